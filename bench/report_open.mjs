// node bench/report_open.mjs [RES] — the report of a rotated CAD-like part at
// RES^3 (default 256): time to write it, its size per million triangles, and
// the time from navigation until every mesh is decoded and drawn in headless
// Chromium (software WebGL). Prints figures; asserts nothing.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launch, openReport } from '../tests/js/browser.mjs';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const cli = join(root, 'build/bin/voxpress');
const res = process.argv[2] || '256';
const work = mkdtempSync(join(tmpdir(), 'voxpress-bench-report-'));
try {
  const vol = join(work, 'part.nrrd'), html = join(work, 'report.html'), json = join(work, 'report.json');
  execFileSync(cli, ['-q', 'generate', 'cad-part', '--res', res, '--rotate', 'random:7', '-o', vol]);
  const t0 = performance.now();
  execFileSync(cli, ['-q', 'report', vol, '-o', html, '--methods', 'midpoint,pressing', '--stats-json', json]);
  const writeMs = performance.now() - t0;
  const stats = JSON.parse(readFileSync(json, 'utf8'));
  const triangles = stats.methods.reduce((a, m) => a + m.triangles, 0);
  const bytes = statSync(html).size;
  console.log(`cad-part ${res}^3: ${stats.methods.length} views, ${triangles} triangles, ` +
              `report ${(bytes / 1e6).toFixed(1)} MB = ${(bytes / 1e6 / (triangles / 1e6)).toFixed(2)} MB per million ` +
              `triangles, written in ${(writeMs / 1000).toFixed(2)} s (all methods and errors included)`);
  const browser = await launch();
  if (!browser) {
    console.log('Chromium or playwright-core missing: open time not measured');
  } else {
    for (let run = 1; run <= 5; run++) {
      const { page, ms } = await openReport(browser, html);
      const t = await page.evaluate(() => window.voxpressReport.ms);
      console.log(`open + decode + first frame, run ${run}: ${ms.toFixed(0)} ms (page: parse and scripts ` +
                  `${(t.sinceStart - t.decode - t.firstFrame).toFixed(0)} ms, decode ${t.decode.toFixed(0)} ms, ` +
                  `first frame ${t.firstFrame.toFixed(0)} ms)`);
      await page.close();
    }
    await browser.close();
  }
} finally {
  rmSync(work, { recursive: true, force: true });
}
