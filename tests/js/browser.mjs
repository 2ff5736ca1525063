// Headless Chromium (Debian's /usr/bin/chromium) driven by playwright-core,
// with the flags this sandbox needs (no network chatter, software WebGL).
import { existsSync } from 'node:fs';

export const CHROMIUM = process.env.VOXPRESS_CHROMIUM || '/usr/bin/chromium';

/// null when Chromium or playwright-core is missing (the caller skips).
export async function launch() {
  if (!existsSync(CHROMIUM)) return null;
  let chromium;
  try {
    ({ chromium } = await import('playwright-core'));
  } catch {
    return null;
  }
  return chromium.launch({
    executablePath: CHROMIUM,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
           '--disable-background-networking', '--disable-component-update', '--disable-sync',
           '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

/// Opens a report and waits until every mesh is decoded and drawn; returns
/// the page and the milliseconds from navigation to ready.
export async function openReport(browser, file, { width = 1400, height = 900 } = {}) {
  const page = await browser.newPage({ viewport: { width, height } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  // Self-contained: nothing but the file itself (and data: URLs) may be requested.
  page.on('request', (r) => {
    if (!r.url().startsWith('data:') && r.url() !== 'file://' + file) errors.push('request to ' + r.url());
  });
  const t0 = performance.now();
  await page.goto('file://' + file);
  await page.waitForFunction(() => document.body.dataset.ready, null, { timeout: 120000 });
  const ms = performance.now() - t0;
  const state = await page.evaluate(() => document.body.dataset.ready);
  if (state !== 'true') throw new Error(`report failed to load: ${state} ${errors.join('; ')}`);
  return { page, ms, errors };
}
