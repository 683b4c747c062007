// Click-to-paint with heavy plants, measured side by side for two or more studio binaries
// (this one and the version before, say), in turns: A B A B ...
//
//   node crates/sylva-studio/e2e/heavy.mjs [--rounds N] BIN [BIN ...]
//
// Each round, for each binary: a fresh studio on a fresh database, the page opened in Debian's
// chromium on software WebGL (as the browser test does), then, clicking as a person would:
// a new session of the PlantMaker examples; Mutate at Depth 10 on an example, twice; Cross of
// two of the mutants; Add random with nine random PlantMaker plants (what a random start
// grows and draws). Each step's figure is the page's own click-to-paint (`lastPaintMs`: from
// the click to the frame with every plant of the grid drawn, the GPU done), which every
// version of the page reports; the new session's is timed from outside the page. Prints each
// figure's median and range per binary.

import { spawn, spawnSync } from "node:child_process";
import { createRequire } from "node:module";
import { fileURLToPath } from "node:url";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";

const here = path.dirname(fileURLToPath(import.meta.url));
const web = path.resolve(here, "../web");
const args = process.argv.slice(2);
let rounds = 3;
if (args[0] === "--rounds") {
  rounds = Number(args[1]);
  args.splice(0, 2);
}
if (args.length === 0) {
  console.error("usage: node heavy.mjs [--rounds N] BIN [BIN ...]");
  process.exit(2);
}
const { chromium } = createRequire(path.join(web, "package.json"))("playwright-core");

async function startStudio(bin, db) {
  // Versions before the page was built in read three.js from a folder given with --three.
  const help = spawnSync(bin, ["studio", "--help"], { encoding: "utf8" }).stdout || "";
  const three = help.includes("--three") ? ["--three", path.join(web, "node_modules/three")] : [];
  const child = spawn(bin, ["studio", "--port", "0", "--db", db, ...three], { stdio: ["ignore", "pipe", "inherit"] });
  const address = await new Promise((resolve, reject) => {
    let out = "";
    child.stdout.on("data", (d) => {
      out += d;
      const m = out.match(/http:\/\/[^\s/]+/);
      if (m) resolve(m[0]);
    });
    child.on("exit", () => reject(new Error(`${bin} exited: ${out}`)));
  });
  return { child, address };
}

async function measure(bin) {
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "sylva-heavy-"));
  const { child, address } = await startStudio(bin, path.join(tmp, "studio.db"));
  const browser = await chromium.launch({
    executablePath: "/usr/bin/chromium",
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-background-networking", "--disable-gpu", "--no-first-run", "--disable-component-update", "--disable-sync"],
  });
  try {
    const page = await browser.newPage({ viewport: { width: 1440, height: 900 } });
    page.setDefaultTimeout(120_000);
    const byTestId = (id) => page.locator(`[data-testid="${id}"]`);
    await page.goto(address + "/");
    await page.waitForFunction(() => window.sylvaStudio && window.sylvaStudio.ready === true);
    // give the studio a moment to finish starting (the version after makes its textures then)
    await page.waitForTimeout(6000);
    const gridDrawn = async (t0) => {
      await page.waitForFunction(() => {
        const cells = [...document.querySelectorAll('[data-testid^="grid-cell-"]')];
        const filled = cells.filter((c) => c.dataset.plant);
        return filled.length > 0 && filled.every((c) => !c.classList.contains("loading"));
      });
      await page.evaluate(() => window.sylvaStudio.stages.breed.nextPaint());
      return Date.now() - t0;
    };
    const ids = () => page.evaluate(() => [...document.querySelectorAll('[data-testid^="grid-cell-"]')].map((c) => Number(c.dataset.plant) || null));
    const operator = async (id) => (await (await fetch(`${address}/api/plants/${id}`)).json()).operator;
    const newSession = async (start) => {
      const before = await page.evaluate(() => window.sylvaStudio.session()?.id ?? null);
      await byTestId("new-session").click();
      await byTestId("new-model").selectOption("plantmaker");
      await byTestId(start).check();
      const t0 = Date.now();
      await page.locator('#view-breed [data-testid="new-create"]').click();
      await page.waitForFunction((b) => (window.sylvaStudio.session()?.id ?? null) !== b, before);
      return gridDrawn(t0);
    };
    const click = async (action) => {
      const n0 = await page.evaluate(() => window.sylvaStudio.paintCount);
      await action();
      await page.waitForFunction((n) => window.sylvaStudio.paintCount > n, n0);
      return Math.round(await page.evaluate(() => window.sylvaStudio.lastPaintMs));
    };
    const r = {};
    await byTestId("mode-breed").click();
    r.examples = await newSession("new-start-examples");
    r.mutate = [];
    for (let k = 0; k < 2; k++) {
      const grid = await ids();
      let cell = -1;
      for (let i = 0; i < grid.length && cell < 0; i++) if (grid[i] && (await operator(grid[i])) === "example") cell = i;
      await byTestId(`grid-cell-${cell}`).click();
      await byTestId("depth").evaluate((e) => {
        e.value = "10";
        e.dispatchEvent(new Event("input", { bubbles: true }));
      });
      r.mutate.push(await click(() => byTestId("mutate").click()));
    }
    await byTestId("grid-cell-1").click();
    await byTestId("grid-cell-2").click();
    r.cross = await click(() => byTestId("cross").click());
    await byTestId("add-random-count").fill("9");
    r.random = await click(() => byTestId("add-random").click());
    return r;
  } finally {
    await browser.close();
    child.kill("SIGKILL");
    fs.rmSync(tmp, { recursive: true, force: true });
  }
}

const figures = args.map(() => ({ examples: [], mutate: [], cross: [], random: [] }));
for (let round = 0; round < rounds; round++) {
  for (const [i, bin] of args.entries()) {
    const r = await measure(bin);
    console.log(`round ${round + 1}, ${bin}: ${JSON.stringify(r)}`);
    for (const k of Object.keys(figures[i])) figures[i][k].push(...[r[k]].flat());
  }
}
const median = (a) => [...a].sort((x, y) => x - y)[Math.floor((a.length - 1) / 2)];
console.log("");
for (const [i, bin] of args.entries()) {
  const f = figures[i];
  const show = (a) => `${median(a)} ms (${Math.min(...a)} to ${Math.max(...a)})`;
  console.log(`${bin}\n  a session of the examples (from outside): ${show(f.examples)}\n  Mutate at Depth 10:        ${show(f.mutate)}\n  Cross of two mutants:      ${show(f.cross)}\n  nine random plants:        ${show(f.random)}`);
}
