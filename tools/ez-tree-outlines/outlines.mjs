// Draws front-view outlines of trees grown by ez-tree (@dgreenheck/ez-tree, another tree
// generator than Sylva) as held-out targets for `sylva match`: for each preset and seed it
// generates the tree, projects every triangle of its meshes (branches and leaves, world
// matrices applied) orthographically onto the front view (x to the right, y up, looking
// along -Z; z dropped), fills them into a binary mask, crops the mask to its ink plus a
// margin at about 400 pixels tall and writes it as an 8-bit greyscale PNG, black ink (0) on
// white (255), to tests/held-out/ez-tree/<preset>-<seed>.png. It then prints, per preset,
// the IoU of its two seeds' outlines normalised as Sylva's outline term normalises them.
//
// Headless, no browser, no WebGL: ez-tree loads its bark and leaf textures with three.js's
// TextureLoader when it is imported, which needs a DOM (document.createElementNS('img')).
// TextureLoader.prototype.load is replaced, before ez-tree is imported, by one that returns
// an empty THREE.Texture remembering its URL (ez-tree's textures are data: URLs). No DOM
// is stubbed. The leaf textures are PNGs: their alpha is decoded here, and a leaf pixel is
// ink only where the texture's alpha passes the leaf material's alphaTest, as the shader
// would draw it (nearest texel, no mipmaps). With --whole-leaves (or for a leaf material
// without a PNG map) the alpha is not read and each leaf quad counts whole: square blobs
// rather than leaf shapes. Bark textures (JPEGs) are never read. The preset's own seed is
// replaced by each of SEEDS; what lies below the ground (y < 0) is left out.
//
// Usage: node tools/ez-tree-outlines/outlines.mjs [--out DIR] [--presets "Oak Medium,Bush 1"]
//        [--seeds 1,2] [--whole-leaves]   (the IoU is printed for the first two seeds)
// (install first: npm ci --prefix tools/ez-tree-outlines)
import fs from "node:fs";
import path from "node:path";
import zlib from "node:zlib";
import { fileURLToPath } from "node:url";
import * as THREE from "three";

THREE.TextureLoader.prototype.load = function (url) {
  const texture = new THREE.Texture();
  texture.userData.url = url;
  return texture;
};
const { Tree, TreePreset } = await import("@dgreenheck/ez-tree");

const here = path.dirname(fileURLToPath(import.meta.url));
// ez-tree presets that differ: a broad oak, a conifer, a tall narrow aspen and a bush.
const DEFAULT_PRESETS = ["Oak Medium", "Pine Medium", "Aspen Medium", "Bush 2"];
const DEFAULT_SEEDS = [1, 2];
const HEIGHT = 400; // pixels of the picture, ink plus margins
const MARGIN = 8; // white pixels around the ink's box
const SUPERSAMPLE = 4; // samples per pixel each way; a pixel is ink if any sample is
const IOU_ROWS = [64, 256]; // Sylva's default `[match] rows` is 64
// ez-tree's own viewer stands the tree on a ground plane at y = 0, which hides what hangs
// below it (a bush's lowest leaves): only what is above the ground is ink.
const GROUND = 0;

const option = (name) => {
  const at = process.argv.indexOf(name);
  return at > 0 ? process.argv[at + 1] : undefined;
};
const outDir = path.resolve(option("--out") ?? path.resolve(here, "../../tests/held-out/ez-tree"));
const PRESETS = option("--presets")?.split(",") ?? DEFAULT_PRESETS;
const SEEDS = option("--seeds")?.split(",").map(Number) ?? DEFAULT_SEEDS;
// Leaves as whole quads, their texture's alpha not read.
const WHOLE_LEAVES = process.argv.includes("--whole-leaves");

// ---- PNG -----------------------------------------------------------------------------

const CRC_TABLE = new Uint32Array(256).map((_, n) => {
  let c = n;
  for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c >>> 0;
});

function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

function chunk(kind, data) {
  const body = Buffer.concat([Buffer.from(kind, "latin1"), data]);
  const out = Buffer.alloc(body.length + 8);
  out.writeUInt32BE(data.length, 0);
  body.copy(out, 4);
  out.writeUInt32BE(crc32(body), body.length + 4);
  return out;
}

/** An 8-bit greyscale PNG of `mask` (1 = ink): black ink on white. */
function encodePng(mask, width, height) {
  const raw = Buffer.alloc((width + 1) * height);
  for (let y = 0; y < height; y++) {
    raw[y * (width + 1)] = 0; // filter: none
    for (let x = 0; x < width; x++) raw[y * (width + 1) + 1 + x] = mask[y * width + x] ? 0 : 255;
  }
  const header = Buffer.alloc(13);
  header.writeUInt32BE(width, 0);
  header.writeUInt32BE(height, 4);
  header.set([8, 0, 0, 0, 0], 8); // bit depth 8, greyscale, deflate, no filter, no interlace
  return Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    chunk("IHDR", header),
    chunk("IDAT", zlib.deflateSync(raw, { level: 9 })),
    chunk("IEND", Buffer.alloc(0)),
  ]);
}

/** The alpha (0-255) of a non-interlaced 8-bit PNG: greyscale, RGB, palette, with alpha. */
function decodePngAlpha(png) {
  let pos = 8;
  let width, height, type, palAlpha = null;
  const idat = [];
  while (pos < png.length) {
    const length = png.readUInt32BE(pos);
    const kind = png.toString("latin1", pos + 4, pos + 8);
    const data = png.subarray(pos + 8, pos + 8 + length);
    if (kind === "IHDR") {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      type = data[9];
      if (data[8] !== 8 || data[12] !== 0) throw new Error("only 8-bit, non-interlaced PNGs");
    } else if (kind === "tRNS" && type === 3) palAlpha = data;
    else if (kind === "IDAT") idat.push(data);
    pos += length + 12;
  }
  const channels = { 0: 1, 2: 3, 3: 1, 4: 2, 6: 4 }[type];
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const pixels = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? pixels[y * stride + i - channels] : 0;
      const b = y > 0 ? pixels[(y - 1) * stride + i] : 0;
      const c = y > 0 && i >= channels ? pixels[(y - 1) * stride + i - channels] : 0;
      let v = line[i];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      pixels[y * stride + i] = v & 0xff;
    }
  }
  const alpha = new Uint8Array(width * height);
  for (let i = 0; i < width * height; i++) {
    if (type === 3) alpha[i] = palAlpha && pixels[i] < palAlpha.length ? palAlpha[pixels[i]] : 255;
    else if (type === 4 || type === 6) alpha[i] = pixels[i * channels + channels - 1];
    else alpha[i] = 255;
  }
  return { width, height, alpha };
}

// ---- Geometry ------------------------------------------------------------------------

const cutouts = new Map();

/** Which texels of `material`'s map are drawn (alpha passing alphaTest), or null: all. */
function cutout(material) {
  const url = material.map?.userData?.url;
  if (WHOLE_LEAVES || !material.alphaTest || !url?.startsWith("data:image/png;base64,")) return null;
  const key = `${material.alphaTest} ${url}`;
  if (!cutouts.has(key)) {
    const { width, height, alpha } = decodePngAlpha(Buffer.from(url.slice(url.indexOf(",") + 1), "base64"));
    const keep = alpha.map((a) => (a / 255 >= material.alphaTest ? 1 : 0));
    cutouts.set(key, { width, height, keep, flipY: material.map.flipY });
  }
  return cutouts.get(key);
}

/** Every triangle of `tree`'s meshes in the front view: groups of x, y (and u, v) arrays. */
function frontTriangles(tree) {
  tree.updateMatrixWorld(true);
  const groups = [];
  const p = new THREE.Vector3();
  tree.traverse((object) => {
    if (!object.isMesh || !object.visible) return;
    const geometry = object.geometry;
    const position = geometry.attributes.position;
    if (!position || position.count === 0) return;
    const index = geometry.index;
    const count = index ? index.count : position.count;
    const uv = geometry.attributes.uv;
    const mask = uv ? cutout(object.material) : null;
    const xy = new Float64Array(position.count * 2);
    for (let i = 0; i < position.count; i++) {
      p.fromBufferAttribute(position, i).applyMatrix4(object.matrixWorld);
      xy[2 * i] = p.x; // right
      xy[2 * i + 1] = p.y; // up; z is dropped
    }
    const corners = new Uint32Array(count);
    for (let i = 0; i < count; i++) corners[i] = index ? index.getX(i) : i;
    groups.push({ name: object.name || object.material?.name, xy, corners, uv: mask ? uv : null, mask });
  });
  return groups;
}

function bounds(groups) {
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const { xy, corners } of groups)
    for (const c of corners) {
      x0 = Math.min(x0, xy[2 * c]);
      x1 = Math.max(x1, xy[2 * c]);
      y0 = Math.min(y0, xy[2 * c + 1]);
      y1 = Math.max(y1, xy[2 * c + 1]);
    }
  return { x0, y0: Math.max(y0, GROUND), x1, y1 };
}

// ---- Rasterising ---------------------------------------------------------------------

/**
 * Fills every triangle into a mask of `scale` pixels per world unit whose pixel (0, 0) has
 * its top-left corner at world (left, top); a pixel is ink if any of its SUPERSAMPLE^2
 * sample points lies in a triangle (and, on a leaf, on a texel that is drawn) above GROUND.
 */
function rasterise(groups, scale, left, top, width, height) {
  const S = SUPERSAMPLE, k = scale * S, W = width * S, H = height * S;
  const fine = new Uint8Array(W * H);
  const ground = Math.floor((top - GROUND) * k - 0.5); // the last row of samples above it
  for (const { xy, corners, uv, mask } of groups) {
    for (let t = 0; t + 2 < corners.length; t += 3) {
      const a = corners[t], b = corners[t + 1], c = corners[t + 2];
      const ax = (xy[2 * a] - left) * k, ay = (top - xy[2 * a + 1]) * k;
      const bx = (xy[2 * b] - left) * k, by = (top - xy[2 * b + 1]) * k;
      const cx = (xy[2 * c] - left) * k, cy = (top - xy[2 * c + 1]) * k;
      const area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
      if (area === 0) continue; // seen edge-on
      const xs = Math.max(0, Math.floor(Math.min(ax, bx, cx) - 0.5));
      const xe = Math.min(W - 1, Math.ceil(Math.max(ax, bx, cx) - 0.5));
      const ys = Math.max(0, Math.floor(Math.min(ay, by, cy) - 0.5));
      const ye = Math.min(H - 1, ground, Math.ceil(Math.max(ay, by, cy) - 0.5));
      for (let y = ys; y <= ye; y++) {
        const py = y + 0.5;
        for (let x = xs; x <= xe; x++) {
          const px = x + 0.5;
          // Barycentric weights of the sample; all >= 0 inside, whatever the winding.
          const wa = ((bx - px) * (cy - py) - (by - py) * (cx - px)) / area;
          const wb = ((cx - px) * (ay - py) - (cy - py) * (ax - px)) / area;
          const wc = 1 - wa - wb;
          if (wa < 0 || wb < 0 || wc < 0) continue;
          if (mask) {
            const u = wa * uv.getX(a) + wb * uv.getX(b) + wc * uv.getX(c);
            const v = wa * uv.getY(a) + wb * uv.getY(b) + wc * uv.getY(c);
            const col = Math.min(mask.width - 1, Math.max(0, Math.floor(u * mask.width)));
            const row = Math.min(mask.height - 1, Math.max(0, Math.floor((mask.flipY ? 1 - v : v) * mask.height)));
            if (!mask.keep[row * mask.width + col]) continue;
          }
          fine[y * W + x] = 1;
        }
      }
    }
  }
  const out = new Uint8Array(width * height);
  for (let y = 0; y < H; y++)
    for (let x = 0; x < W; x++) if (fine[y * W + x]) out[Math.floor(y / S) * width + Math.floor(x / S)] = 1;
  return out;
}

function inkBox(mask, width, height) {
  let [x0, y0, x1, y1] = [width, height, 0, 0];
  for (let y = 0; y < height; y++)
    for (let x = 0; x < width; x++)
      if (mask[y * width + x]) {
        x0 = Math.min(x0, x);
        x1 = Math.max(x1, x + 1);
        y0 = Math.min(y0, y);
        y1 = Math.max(y1, y + 1);
      }
  return x1 > x0 ? { x0, y0, x1, y1 } : null;
}

/**
 * The outline of `groups`: ink about HEIGHT - 2 MARGIN pixels tall, MARGIN white around it
 * (more above it when the ink falls a row or two short, so the picture is HEIGHT tall).
 */
function outline(groups) {
  const world = bounds(groups);
  const inkRows = HEIGHT - 2 * MARGIN;
  let scale = inkRows / (world.y1 - world.y0);
  let best = null;
  // Leaves cut out by their texture can leave the ink's box smaller than the vertices':
  // the scale is grown until the ink itself is inkRows tall. Pixel phase can make it
  // flip between a row short and a row over: a few tries, the closest (not over) is kept.
  for (let attempt = 0; attempt < 4 && best?.rows !== inkRows; attempt++) {
    // Pixels wide and tall enough for every vertex, a margin and a pixel to spare.
    const left = world.x0 - (MARGIN + 1) / scale, top = world.y1 + (MARGIN + 1) / scale;
    const width = Math.ceil((world.x1 - world.x0) * scale) + 2 * MARGIN + 3;
    const height = Math.ceil((world.y1 - world.y0) * scale) + 2 * MARGIN + 3;
    const mask = rasterise(groups, scale, left, top, width, height);
    const box = inkBox(mask, width, height);
    if (!box) throw new Error("no ink");
    const rows = box.y1 - box.y0;
    const miss = (r) => (r > inkRows ? 2 * (r - inkRows) + 1 : inkRows - r);
    if (!best || miss(rows) < miss(best.rows)) best = { mask, width, box, rows };
    scale *= inkRows / rows;
  }
  const { mask, width, box, rows } = best;
  const w = box.x1 - box.x0 + 2 * MARGIN, h = Math.max(HEIGHT, rows + 2 * MARGIN);
  const cropped = new Uint8Array(w * h);
  for (let y = box.y0; y < box.y1; y++)
    for (let x = box.x0; x < box.x1; x++)
      cropped[(h - MARGIN - (box.y1 - y)) * w + x - box.x0 + MARGIN] = mask[y * width + x];
  return { mask: cropped, width: w, height: h };
}

// ---- Comparing -----------------------------------------------------------------------

/**
 * As Sylva's outline term normalises a target (sylva-fitness, silhouette.rs): crop to the
 * ink's box, scale it to `rows` tall keeping its aspect (a canvas pixel is ink when at
 * least half the picture's pixels under it are), stand it on the bottom row, centred
 * horizontally on a canvas three times as wide as tall.
 */
function normalise({ mask, width, height }, rows) {
  const box = inkBox(mask, width, height);
  const w = box.x1 - box.x0, h = box.y1 - box.y0, cw = rows * 3;
  const out = new Uint8Array(cw * rows);
  const columns = Math.min(cw, Math.max(1, Math.round((w * rows) / h)));
  const left = Math.floor((cw - columns) / 2);
  const under = (c, n, len) => {
    const from = Math.floor((c * len) / n);
    const to = Math.ceil(((c + 1) * len) / n);
    return [from, Math.min(len, Math.max(from + 1, to))];
  };
  for (let cy = 0; cy < rows; cy++) {
    const [py0, py1] = under(cy, rows, h);
    for (let cx = 0; cx < columns; cx++) {
      const [px0, px1] = under(cx, columns, w);
      let ink = 0;
      for (let py = py0; py < py1; py++)
        for (let px = px0; px < px1; px++) ink += mask[(box.y0 + py) * width + box.x0 + px];
      if (2 * ink >= (py1 - py0) * (px1 - px0)) out[cy * cw + left + cx] = 1;
    }
  }
  return out;
}

function iou(a, b) {
  let both = 0, either = 0;
  for (let i = 0; i < a.length; i++) {
    both += a[i] & b[i];
    either += a[i] | b[i];
  }
  return either ? both / either : 0;
}

// ---- Main ----------------------------------------------------------------------------

fs.mkdirSync(outDir, { recursive: true });
for (const preset of PRESETS) {
  if (!TreePreset[preset]) throw new Error(`ez-tree has no preset "${preset}"`);
  const outlines = [];
  for (const seed of SEEDS) {
    const tree = new Tree();
    tree.options.copy(structuredClone(TreePreset[preset]));
    tree.options.seed = seed;
    tree.generate();
    const groups = frontTriangles(tree);
    const picture = outline(groups);
    const file = path.join(outDir, `${preset.toLowerCase().replace(/[^a-z0-9]+/g, "-")}-${seed}.png`);
    fs.writeFileSync(file, encodePng(picture.mask, picture.width, picture.height));
    const ink = picture.mask.reduce((s, v) => s + v, 0) / (picture.width * picture.height);
    const triangles = groups.map((g) => `${g.corners.length / 3} ${g.name}`).join(", ");
    console.log(
      `${path.relative(process.cwd(), file)}: ${picture.width} x ${picture.height}, ink ${(100 * ink).toFixed(1)}%, ` +
        `${triangles} triangles${groups.some((g) => g.mask) ? " (leaves cut out by texture alpha)" : ""}`,
    );
    outlines.push(picture);
  }
  if (outlines.length < 2) continue;
  const ious = IOU_ROWS.map((rows) => `${iou(normalise(outlines[0], rows), normalise(outlines[1], rows)).toFixed(3)} at ${rows} rows`);
  console.log(`${preset}: seed ${SEEDS[0]} vs seed ${SEEDS[1]} IoU ${ious.join(", ")}`);
}
