// End-to-end test of `voxpress report` in headless Chromium: the page loads
// every mesh, each panel shows a picture (pixel variance), the toggles change
// the picture, and the stats table shows the JSON the CLI wrote.
// node report_e2e.mjs VOXPRESS_CLI  (exit 0 pass, 1 fail, 77 skipped)
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { PNG } from 'pngjs';
import { launch, openReport } from './browser.mjs';

const cli = process.argv[2];
const browser = await launch();
if (!browser) {
  console.log('SKIPPED: Chromium or playwright-core is not installed (scripts/setup.sh --tests installs both)');
  process.exit(77);
}
const work = mkdtempSync(join(tmpdir(), 'voxpress-report-'));
let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures++;
};

function pixelStats(png) {
  const { data, width, height } = PNG.sync.read(png);
  let sum = 0, sum2 = 0, ink = 0;
  const n = width * height;
  for (let i = 0; i < n; i++) {
    const y = 0.299 * data[4 * i] + 0.587 * data[4 * i + 1] + 0.114 * data[4 * i + 2];
    sum += y, sum2 += y * y;
    if (y < 235) ink++;
  }
  const mean = sum / n;
  return { std: Math.sqrt(Math.max(0, sum2 / n - mean * mean)), ink: ink / n };
}

try {
  const vol = join(work, 'part.nrrd'), html = join(work, 'report.html'), json = join(work, 'report.json');
  execFileSync(cli, ['-q', 'generate', 'cad-part', '--res', '40', '--rotate', 'random:3', '-o', vol]);
  execFileSync(cli, ['-q', 'report', vol, '-o', html, '--methods', 'midpoint,pressing,cesn', '--stats-json', json,
                     '--samples', '20000']);
  const stats = JSON.parse(readFileSync(json, 'utf8'));
  const { page, ms, errors } = await openReport(browser, html);
  console.log(`loaded in ${ms.toFixed(0)} ms`);
  check(errors.length === 0, `no page errors and no requests beyond the file (${errors.join('; ')})`);
  const info = await page.evaluate(() => ({ views: window.voxpressReport.views,
                                            panels: document.querySelectorAll('.panel').length }));
  check(info.views === stats.methods.length && info.panels === stats.methods.length,
        `one view per mesh (${info.views} views, ${info.panels} panels, ${stats.methods.length} in the JSON)`);

  // Every panel shows something: enough non-white pixels and contrast.
  const panels = await page.$$('.panel');
  for (const [i, panel] of panels.entries()) {
    const s = pixelStats(await panel.screenshot());
    check(s.std > 12 && s.ink > 0.03, `panel ${stats.methods[i].name} is not blank (std ${s.std.toFixed(1)}, ` +
                                      `${(100 * s.ink).toFixed(1)} % covered)`);
  }
  // The error heat map and region colours change the picture.
  const stage = await page.$('#stage');
  const before = await stage.screenshot();
  await page.click('#error');
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const heat = await stage.screenshot();
  check(!before.equals(heat), 'the error heat map changes the picture');
  await page.click('#regions');
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const regions = await stage.screenshot();
  check(!regions.equals(heat) && !regions.equals(before), 'region colours change the picture');

  // The stats table shows the JSON.
  const rows = await page.$$eval('#stats tbody tr', (trs) => trs.map((tr) => ({
    method: tr.dataset.method,
    cells: Object.fromEntries([...tr.cells].map((td) => [td.dataset.col, td.textContent])),
  })));
  check(rows.length === stats.methods.length, `one table row per method (${rows.length})`);
  const close = (text, value) => value === undefined ? text === ''
    : Number.isInteger(value) ? text === String(value)
    : Math.abs(parseFloat(text) - value) <= 1e-3 * Math.abs(value) + 1e-12;
  for (const [i, m] of stats.methods.entries()) {
    const row = rows[i];
    if (!row) break;
    const want = { vertices: m.vertices, triangles: m.triangles, iterations: m.iterations, flats: m.flats,
                   seconds: m.seconds, 'samples on the wrong side': m.violations,
                   'RMS error (vox)': m.error?.rms, 'max error (vox)': m.error?.max,
                   'Hausdorff (vox)': m.error?.hausdorff };
    const bad = Object.entries(want).filter(([col, v]) => !close(row.cells[col], v));
    check(row.method === m.name && bad.length === 0,
          `table row ${m.name} matches the JSON` + (bad.length ? ` (differs: ${bad.map(([c]) => c).join(', ')})` : ''));
  }
} catch (e) {
  console.log('FAIL', e.stack || e);
  failures++;
} finally {
  await browser.close();
  rmSync(work, { recursive: true, force: true });
}
process.exit(failures ? 1 : 0);
