// Renders GLB trees side by side under one light rig, ground and camera, each scaled about
// its foot to the same height, so that Sylva's plants and other generators' (ez-tree's) can
// be compared by eye. three.js (this tool's pinned copy) draws them in Debian's chromium,
// headless with software WebGL (SwiftShader), driven by playwright-core; the page (page.html,
// page.mjs) is served from this folder by a small HTTP server on 127.0.0.1 (a random port):
// no request leaves the machine.
//
// Usage: node tools/side-by-side/render.mjs --out OUT.png [--height 12] [--size 1600x900]
//        [--view front|iso] [--labels "Sylva oak,ez-tree oak"] [--supersample 2]
//        A.glb B.glb [C.glb ...]
// (install first: npm ci --prefix tools/side-by-side; chromium: apt-get install -y chromium)
//
// Prints one JSON line per file on stdout (triangles, texture bytes, height before scaling,
// whether it has MASK materials, ...), and what it did and how long it took on stderr.
// Exit codes: 0 done; 2 a bad command line, a missing file or one that is not a GLB (the file
// named); 1 a file three.js cannot load or draws nothing of (named), a blank canvas, no
// chromium, or any other failure.
import fs from "node:fs";
import http from "node:http";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { createRequire } from "node:module";

const here = path.dirname(fileURLToPath(import.meta.url));
const CHROMIUM = "/usr/bin/chromium";
const T0 = performance.now();
const seconds = (t) => ((t ?? performance.now()) - T0) / 1000;

class Exit extends Error {
  constructor(code, message) {
    super(message);
    this.code = code;
  }
}

// ---- The command line ---------------------------------------------------------------------

const USAGE =
  "usage: node tools/side-by-side/render.mjs --out OUT.png [--height METRES] [--size WxH] " +
  '[--view front|iso] [--labels "A,B,..."] [--supersample N] A.glb [B.glb ...]';

function parseArgs(argv) {
  const o = { out: null, height: 12, size: [1600, 900], view: "front", labels: null, supersample: 2, files: [] };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const value = () => {
      const v = argv[++i];
      if (v === undefined) throw new Exit(2, `${a} needs a value\n${USAGE}`);
      return v;
    };
    if (a === "--out") o.out = value();
    else if (a === "--height") {
      const v = value();
      o.height = Number(v);
      if (v.trim() === "" || !Number.isFinite(o.height) || o.height < 0 || o.height > 10000)
        throw new Exit(2, `--height must be a number of metres from 0 (each file's own size) to 10000, got ${v}`);
    } else if (a === "--size") {
      const v = value();
      const m = /^(\d+)x(\d+)$/.exec(v);
      if (!m) throw new Exit(2, `--size must be WIDTHxHEIGHT, like 1600x900, got ${v}`);
      o.size = [Number(m[1]), Number(m[2])];
      if (o.size.some((n) => n < 64 || n > 8192)) throw new Exit(2, `--size: each side from 64 to 8192 pixels, got ${v}`);
    } else if (a === "--view") {
      o.view = value();
      if (!["front", "iso"].includes(o.view)) throw new Exit(2, `--view must be front or iso, got ${o.view}`);
    } else if (a === "--labels") o.labels = value().split(",").map((s) => s.trim());
    else if (a === "--supersample") {
      const v = value();
      o.supersample = Number(v);
      if (![1, 2, 3, 4].includes(o.supersample)) throw new Exit(2, `--supersample must be 1, 2, 3 or 4, got ${v}`);
    } else if (a === "--help" || a === "-h") {
      console.log(USAGE);
      process.exit(0);
    } else if (a.startsWith("--")) throw new Exit(2, `unknown option ${a}\n${USAGE}`);
    else o.files.push(a);
  }
  if (!o.out) throw new Exit(2, `--out OUT.png is required\n${USAGE}`);
  if (!o.out.toLowerCase().endsWith(".png")) throw new Exit(2, `--out must name a .png file, got ${o.out}`);
  if (o.files.length === 0) throw new Exit(2, `no GLB files given\n${USAGE}`);
  if (o.labels && o.labels.length !== o.files.length)
    throw new Exit(2, `--labels has ${o.labels.length} labels for ${o.files.length} files`);
  return o;
}

// ---- The files ------------------------------------------------------------------------------

/**
 * Reads and checks a GLB: the 12-byte header (magic "glTF", version 2, its length), a JSON
 * chunk first that parses as glTF 2.0. Returns its bytes and JSON, or throws Exit 2.
 */
function readGlb(file) {
  let stat;
  try {
    stat = fs.statSync(file);
  } catch {
    throw new Exit(2, `${file}: no such file`);
  }
  if (!stat.isFile()) throw new Exit(2, `${file}: not a file`);
  let bytes;
  try {
    bytes = fs.readFileSync(file);
  } catch (e) {
    throw new Exit(2, `${file}: cannot be read (${e.code ?? e.message})`);
  }
  const bad = (why) => new Exit(2, `${file}: not a GLB (glTF 2.0 binary) file: ${why}`);
  if (bytes.length < 20) throw bad(`only ${bytes.length} bytes`);
  if (bytes.readUInt32LE(0) !== 0x46546c67) throw bad('no "glTF" magic at its start');
  if (bytes.readUInt32LE(4) !== 2) throw bad(`container version ${bytes.readUInt32LE(4)}, not 2`);
  if (bytes.readUInt32LE(8) > bytes.length) throw bad(`the header says ${bytes.readUInt32LE(8)} bytes, the file has ${bytes.length}`);
  const jsonLength = bytes.readUInt32LE(12);
  if (bytes.readUInt32LE(16) !== 0x4e4f534a) throw bad("its first chunk is not JSON");
  if (20 + jsonLength > bytes.length) throw bad("its JSON chunk runs past the end");
  let json;
  try {
    json = JSON.parse(bytes.toString("utf8", 20, 20 + jsonLength));
  } catch (e) {
    throw bad(`its JSON does not parse (${e.message})`);
  }
  if (typeof json !== "object" || json === null || !String(json.asset?.version ?? "").startsWith("2."))
    throw bad("its JSON has no asset.version 2.x");
  return { bytes, json };
}

/** Bytes of the file's images: buffer views, data: URIs, or files beside it. */
function textureBytes(file, json) {
  let total = 0;
  for (const image of json.images ?? []) {
    if (image.bufferView !== undefined) total += json.bufferViews?.[image.bufferView]?.byteLength ?? 0;
    else if (typeof image.uri === "string") {
      const m = /^data:[^,]*?(;base64)?,(.*)$/s.exec(image.uri);
      if (m) total += m[1] ? Buffer.from(m[2], "base64").length : decodeURIComponent(m[2]).length;
      else {
        try {
          total += fs.statSync(path.resolve(path.dirname(file), decodeURIComponent(image.uri))).size;
        } catch {
          // a missing image: the loader says so
        }
      }
    }
  }
  return total;
}

// ---- The server -----------------------------------------------------------------------------

const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".json": "application/json",
  ".wasm": "application/wasm",
  ".glb": "model/gltf-binary",
  ".gltf": "model/gltf+json",
  ".bin": "application/octet-stream",
  ".png": "image/png",
  ".jpg": "image/jpeg",
  ".jpeg": "image/jpeg",
  ".webp": "image/webp",
  ".ktx2": "image/ktx2",
};

/** `rel` (URL-decoded) inside `dir`, or null if it would leave it. */
function inside(dir, rel) {
  const p = path.resolve(dir, "." + path.posix.normalize("/" + rel));
  return p === dir || p.startsWith(dir + path.sep) ? p : null;
}

/**
 * Serves the page, three.js (its build and examples/jsm only) and, under /files/N/, the
 * N-th input file (as /files/N/its-name) and any file beside it its JSON names by URI.
 */
function startServer(inputs) {
  const three = path.join(here, "node_modules/three");
  const server = http.createServer((req, res) => {
    let file = null, body = null;
    const url = new URL(req.url, "http://127.0.0.1");
    let rel;
    try {
      rel = decodeURIComponent(url.pathname);
    } catch {
      rel = "";
    }
    if (rel === "/" || rel === "/page.html") file = path.join(here, "page.html");
    else if (rel === "/page.mjs") file = path.join(here, "page.mjs");
    else if (rel.startsWith("/three/build/") || rel.startsWith("/three/examples/jsm/")) file = inside(three, rel.slice("/three/".length));
    else {
      const m = /^\/files\/(\d+)\/(.+)$/.exec(rel);
      const input = m && inputs[Number(m[1])];
      if (input && m[2] === path.basename(input.file)) body = input.bytes;
      else if (input) file = inside(path.dirname(path.resolve(input.file)), m[2]);
    }
    const type = TYPES[path.extname(file ?? rel).toLowerCase()] ?? "application/octet-stream";
    if (body) {
      res.writeHead(200, { "content-type": type, "content-length": body.length, "cache-control": "no-store" });
      return res.end(body);
    }
    if (file) {
      fs.readFile(file, (err, data) => {
        if (err) {
          res.writeHead(404, { "content-type": "text/plain" });
          res.end(`not found: ${rel}`);
        } else {
          res.writeHead(200, { "content-type": type, "content-length": data.length, "cache-control": "no-store" });
          res.end(data);
        }
      });
      return;
    }
    res.writeHead(404, { "content-type": "text/plain" });
    res.end(`not found: ${rel}`);
  });
  return new Promise((resolve, reject) => {
    server.once("error", reject);
    server.listen(0, "127.0.0.1", () => resolve(server));
  });
}

// ---- Main -------------------------------------------------------------------------------------

async function main() {
  const o = parseArgs(process.argv.slice(2));
  const inputs = o.files.map((file, i) => {
    const { bytes, json } = readGlb(file);
    return {
      file,
      bytes,
      label: o.labels?.[i] || path.basename(file).replace(/\.glb$/i, ""),
      textureBytes: textureBytes(file, json),
      mask: (json.materials ?? []).some((m) => m.alphaMode === "MASK"),
      materials: (json.materials ?? []).map((m) => ({
        name: m.name ?? null,
        alphaMode: m.alphaMode ?? "OPAQUE",
        doubleSided: m.doubleSided === true,
      })),
    };
  });

  if (!fs.existsSync(path.join(here, "node_modules/three/build/three.module.js")))
    throw new Exit(1, "three.js is not installed: run `npm ci --prefix tools/side-by-side`");
  let chromium;
  try {
    ({ chromium } = createRequire(path.join(here, "package.json"))("playwright-core"));
  } catch (e) {
    throw new Exit(1, `cannot load playwright-core (${e.message}): run \`npm ci --prefix tools/side-by-side\``);
  }
  if (!fs.existsSync(CHROMIUM)) throw new Exit(1, `no ${CHROMIUM}: install Debian's chromium (apt-get install -y chromium)`);

  const server = await startServer(inputs);
  const base = `http://127.0.0.1:${server.address().port}`;
  let browser = null;
  try {
    const tLaunch = performance.now();
    browser = await chromium.launch({
      executablePath: CHROMIUM,
      headless: true,
      args: [
        "--no-sandbox",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--disable-background-networking",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-component-update",
        "--disable-sync",
      ],
    });
    const page = await browser.newPage({ viewport: { width: 640, height: 480 }, deviceScaleFactor: 1 });
    page.setDefaultTimeout(300_000);
    const problems = [];
    page.on("pageerror", (e) => problems.push(`script error: ${e.message}`));
    page.on("console", (m) => {
      if (m.type() === "error") problems.push(`console: ${m.text()}`);
    });
    // Nothing may leave the machine.
    const offsite = [];
    await page.route(/.*/, (route) => {
      const u = new URL(route.request().url());
      if (u.hostname === "127.0.0.1") return route.continue();
      offsite.push(u.href);
      return route.abort();
    });
    await page.goto(`${base}/`);
    try {
      await page.waitForFunction(() => window.sideBySide !== undefined, null, { timeout: 60_000 });
    } catch {
      throw new Exit(1, `the page did not start: ${problems.join("; ") || "no sideBySide after 60 s"}`);
    }
    const tReady = performance.now();
    const result = await page.evaluate((config) => window.sideBySide.render(config), {
      files: inputs.map((input, i) => ({
        url: `/files/${i}/${encodeURIComponent(path.basename(input.file))}`,
        file: input.file,
        label: input.label,
      })),
      height: o.height,
      width: o.size[0],
      pixelHeight: o.size[1],
      view: o.view,
      supersample: o.supersample,
    });
    if (result.error) {
      const why = result.error.file ? `${result.error.file}: ${result.error.message}` : result.error.message;
      const more = problems.length ? ` (${problems.join("; ")})` : "";
      throw new Exit(1, why + more);
    }
    if (offsite.length) console.error(`blocked requests off the machine: ${offsite.join(", ")}`);

    const png = Buffer.from(result.png.replace(/^data:image\/png;base64,/, ""), "base64");
    fs.mkdirSync(path.dirname(path.resolve(o.out)), { recursive: true });
    const tmp = `${o.out}.tmp`;
    fs.writeFileSync(tmp, png);
    fs.renameSync(tmp, o.out);

    for (const [i, t] of result.trees.entries()) {
      const input = inputs[i];
      console.log(
        JSON.stringify({
          file: input.file,
          label: input.label,
          triangles: t.triangles,
          texture_bytes: input.textureBytes,
          height: Number(t.height_before.toPrecision(6)),
          mask: input.mask,
          scale: Number(t.scale.toPrecision(6)),
          animations: t.animations,
          materials: input.materials,
        }),
      );
    }
    const ms = (x) => `${(x / 1000).toFixed(2)} s`;
    console.error(
      `wrote ${o.out}: ${result.width}x${result.height}, ${result.trees.length} ${result.trees.length === 1 ? "tree" : "trees"}, view ${o.view}, ` +
        `${result.supersample > 1 ? `${result.supersample}x${result.supersample} supersampled` : "MSAA"}, in ${seconds().toFixed(2)} s ` +
        `(chromium ${ms(tReady - tLaunch)}, load ${ms(result.timings.load)}, checks ${ms(result.timings.check)}, ` +
        `render ${ms(result.timings.render)}, picture ${ms(result.timings.picture)})`,
    );
  } finally {
    if (browser) await browser.close().catch(() => {});
    server.close();
  }
}

main().then(
  () => process.exit(0),
  (e) => {
    console.error(e instanceof Exit ? e.message : `side-by-side: ${e?.stack ?? e}`);
    process.exit(e instanceof Exit ? e.code : 1);
  },
);
