// Exports trees grown by ez-tree (@dgreenheck/ez-tree 1.1.0, another tree generator than
// Sylva) as files Sylva reads, to render and inspect them beside Sylva's own plants:
//
//   <name>.glb            the whole tree (branches and leaves) as a glTF 2.0 binary, Y up,
//                         scaled about its foot so that its highest point stands --height
//                         metres above y = 0, with ez-tree's textures embedded as they are;
//   <name>.skeleton.json  the same tree as a Sylva skeleton file (docs/skeleton.md): every
//                         branch section to the next as a segment, every leaf quad an organ;
//   index.json            per tree: preset, seed, triangles, height, scale, counts, bytes.
//
// Headless, no browser, no WebGL: as tools/ez-tree-outlines does, THREE.TextureLoader's
// load is replaced, before ez-tree is imported, by one returning an empty THREE.Texture that
// remembers its URL (ez-tree's textures are data: URLs, whose bytes are embedded here).
//
// The skeleton is captured while ez-tree grows the tree, by wrapping three of the Tree's own
// methods on each instance (nothing of ez-tree is copied or changed):
//   generateBranch(branch)            which branch is being grown, the branches it queues
//                                     (its children) and the leaf quads it adds; a child
//                                     queued before the sections are handed over is its
//                                     terminal branch (deciduous trees grow one from every
//                                     tip), written as a continuation of the parent's axis;
//   generateChildBranches(n, level, sections), generateLeaves(sections)
//                                     the branch's sections ({origin, orientation, radius}),
//                                     which ez-tree keeps in a local variable and hands to
//                                     exactly one of these two.
// Every capture is checked against the mesh ez-tree builds (each section against the ring
// of vertices drawn for it, each leaf quad for its shape), so a version of ez-tree that
// grows differently stops the export with an error rather than writing a wrong skeleton.
//
// Usage: node tools/ez-tree-assets/export.mjs [--out DIR] [--height auto|natural|METRES]
//        [--trees oak-medium,willow,...]
// (install first: npm ci --prefix tools/ez-tree-assets)
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
const root = path.resolve(here, "../..");
const EZ_TREE_VERSION = JSON.parse(
  fs.readFileSync(path.join(here, "node_modules/@dgreenheck/ez-tree/package.json"), "utf8"),
).version;

// ---- The trees ---------------------------------------------------------------------------

// ez-tree has no willow and no maple: these two are its options set by hand (on top of a
// preset), approximations documented in README.md. Every option not named keeps the base
// preset's value.
const WILLOW = {
  base: "Ash Medium",
  options: {
    bark: { type: "willow", tint: 0xd8d0c0, textureScale: { x: 1, y: 4 } },
    branch: {
      levels: 3,
      // Level-1 limbs leave the trunk steeply, and the level 2 and 3 whips hang from them:
      // a pull straight down, which bends thin wood most (ez-tree turns a section towards
      // the force by strength / radius).
      angle: { 1: 40, 2: 30, 3: 20 },
      children: { 0: 7, 1: 6, 2: 4 },
      force: { direction: { x: 0, y: -1, z: 0 }, strength: 0.03 },
      gnarliness: { 0: 0.04, 1: 0.06, 2: 0.03, 3: 0.02 },
      length: { 0: 32, 1: 22, 2: 18, 3: 12 },
      radius: { 0: 2.2, 1: 0.6, 2: 0.45, 3: 0.5 },
      sections: { 0: 10, 1: 10, 2: 10, 3: 8 },
      segments: { 0: 8, 1: 5, 2: 3, 3: 3 },
      start: { 1: 0.45, 2: 0.2, 3: 0.1 },
      taper: { 0: 0.6, 1: 0.6, 2: 0.7, 3: 0.8 },
      twist: { 0: 0, 1: 0, 2: 0, 3: 0 },
    },
    // Ash's leaflets are the narrowest of ez-tree's four leaf pictures (it has no willow
    // leaf); small, many and hanging close along the whips.
    leaves: { type: "ash", billboard: "double", angle: 20, count: 14, start: 0.1, size: 1.8, sizeVariance: 0.3, tint: 0xe6f0c0, alphaTest: 0.5 },
  },
};

const MAPLE = {
  base: "Oak Medium",
  options: {
    bark: { type: "oak", tint: 0xc8c4bc, textureScale: { x: 1, y: 6 } },
    branch: {
      levels: 3,
      // A short trunk splitting low into many wide-angled limbs that turn up again: a broad,
      // rounded dome.
      angle: { 1: 62, 2: 50, 3: 40 },
      children: { 0: 9, 1: 5, 2: 4 },
      force: { direction: { x: 0, y: 1, z: 0 }, strength: 0.012 },
      gnarliness: { 0: 0.02, 1: 0.1, 2: 0.15, 3: 0.09 },
      length: { 0: 26, 1: 20, 2: 11, 3: 6 },
      radius: { 0: 1.6, 1: 0.75, 2: 0.7, 3: 0.9 },
      sections: { 0: 8, 1: 8, 2: 5, 3: 2 },
      segments: { 0: 8, 1: 5, 2: 3, 3: 3 },
      start: { 1: 0.35, 2: 0.2, 3: 0.15 },
      taper: { 0: 0.65, 1: 0.55, 2: 0.65, 3: 0.75 },
      twist: { 0: 0, 1: 0.2, 2: 0, 3: 0 },
    },
    // Oak's lobed leaves are the nearest to a maple's palmate ones.
    leaves: { type: "oak", billboard: "double", angle: 40, count: 16, start: 0.15, size: 2.6, sizeVariance: 0.5, tint: 0xc8e0a0, alphaTest: 0.5 },
  },
};

// name, ez-tree preset (or own options), seed, and whether it is a bush (for --height auto).
const TREES = [
  { name: "oak-medium", preset: "Oak Medium", seed: 1, bush: false },
  { name: "pine-medium", preset: "Pine Medium", seed: 1, bush: false },
  { name: "aspen-medium", preset: "Aspen Medium", seed: 1, bush: false },
  { name: "ash-medium", preset: "Ash Medium", seed: 1, bush: false },
  { name: "bush-1", preset: "Bush 1", seed: 1, bush: true },
  { name: "bush-2", preset: "Bush 2", seed: 1, bush: true },
  { name: "willow", own: WILLOW, seed: 1, bush: false },
  { name: "maple", own: MAPLE, seed: 1, bush: false },
];
const AUTO_HEIGHT = { tree: 12, bush: 2.5 }; // metres, for --height auto

// ---- Options -----------------------------------------------------------------------------

const option = (name) => {
  const at = process.argv.indexOf(name);
  if (at < 0) return undefined;
  const value = process.argv[at + 1];
  if (value === undefined || value.startsWith("--")) usage(`${name} needs a value`);
  return value;
};
function usage(message) {
  console.error(`${message}\nusage: node export.mjs [--out DIR] [--height auto|natural|METRES] [--trees NAME,...]`);
  process.exit(2);
}
for (const arg of process.argv.slice(2))
  if (arg.startsWith("--") && !["--out", "--height", "--trees"].includes(arg)) usage(`unknown option ${arg}`);
const outDir = path.resolve(option("--out") ?? path.join(root, "target/ez-tree-assets"));
const heightOption = option("--height") ?? "auto";
if (!["auto", "natural"].includes(heightOption) && !(Number(heightOption) > 0 && Number.isFinite(Number(heightOption))))
  usage(`--height must be auto, natural or a positive number of metres, got ${heightOption}`);
const only = option("--trees")?.split(",");
for (const name of only ?? []) if (!TREES.some((t) => t.name === name)) usage(`no tree named ${name}`);

// ---- Growing, with the skeleton captured -------------------------------------------------

/** ez-tree's options for `tree` (a fresh TreeOptions with the preset, own options and seed). */
function optionsOf(spec) {
  const base = spec.preset ?? spec.own.base;
  if (!TreePreset[base]) throw new Error(`ez-tree ${EZ_TREE_VERSION} has no preset "${base}"`);
  const tree = new Tree();
  tree.options.copy(structuredClone(TreePreset[base]));
  if (spec.own) tree.options.copy(structuredClone(spec.own.options));
  tree.options.seed = spec.seed;
  return tree;
}

/**
 * Grows `tree`, recording every branch as ez-tree generates it: its Branch, level, parent
 * record, sections and the leaf quads it adds (as a range of quad indices).
 */
function growCaptured(tree) {
  const records = []; // in generation order: parents before children (ez-tree's queue)
  const recordOf = new Map(); // ez-tree's Branch -> its record, set when its parent queues it
  let current = null;
  const capture = (sections) => {
    if (!current) throw new Error("ez-tree handed sections over outside generateBranch");
    if (current.sections) throw new Error("ez-tree handed a branch's sections over twice");
    current.sections = sections.map((s) => ({ origin: s.origin.clone(), radius: s.radius }));
    // What the branch queued before handing its sections over: its terminal branch, if any.
    current.queuedBeforeSections = tree.branchQueue.length;
  };
  const { generateBranch, generateChildBranches, generateLeaves } = tree;
  for (const [name, f] of Object.entries({ generateBranch, generateChildBranches, generateLeaves }))
    if (typeof f !== "function") throw new Error(`ez-tree's Tree has no ${name}()`);
  tree.generateChildBranches = function (count, level, sections) {
    capture(sections);
    return generateChildBranches.call(this, count, level, sections);
  };
  tree.generateLeaves = function (sections) {
    capture(sections);
    return generateLeaves.call(this, sections);
  };
  tree.generateBranch = function (branch) {
    let record = recordOf.get(branch);
    if (!record) {
      if (records.length > 0) throw new Error("ez-tree grew a branch that no branch queued");
      record = { parent: null }; // the trunk, queued by generate()
    }
    Object.assign(record, {
      branch,
      level: branch.level,
      origin: branch.origin.clone(),
      sections: null,
      barkVertex: this.branches.verts.length / 3,
      firstQuad: this.leaves.verts.length / 12,
    });
    const queued = this.branchQueue.length;
    current = record;
    generateBranch.call(this, branch);
    current = null;
    if (!record.sections) throw new Error("ez-tree grew a branch without handing its sections over");
    record.endQuad = this.leaves.verts.length / 12;
    // A deciduous tree queues a branch's terminal branch (the next level, grown from its
    // tip) before its side branches, which generateChildBranches queues.
    const terminals = this.branchQueue.slice(queued, record.queuedBeforeSections);
    if (terminals.length > 1) throw new Error("ez-tree queued more than one terminal branch for a branch");
    for (const child of this.branchQueue.slice(queued))
      recordOf.set(child, { parent: record, terminal: child === terminals[0] });
    records.push(record);
  };
  tree.generate();
  tree.updateMatrixWorld(true);
  checkSections(tree, records);
  checkTerminals(tree, records);
  return records;
}

/**
 * A terminal branch grows from its parent's tip: the next level, starting at the parent's
 * last section with its radius, and with as many sections and segments around as its parent.
 * Only deciduous trees grow them, one from every branch below the last level.
 */
function checkTerminals(tree, records) {
  const deciduous = tree.options.type === "deciduous";
  const levels = tree.options.branch.levels;
  const terminalOf = new Map();
  for (const r of records) if (r.terminal) terminalOf.set(r.parent, r);
  for (const r of records) {
    const wanted = deciduous && r.level < levels;
    if (wanted !== terminalOf.has(r)) throw new Error("a branch without the terminal branch ez-tree 1.1.0 grows, or with one it does not");
    if (!r.terminal) continue;
    const p = r.parent, tip = p.sections[p.sections.length - 1];
    if (
      r.level !== p.level + 1 ||
      !r.origin.equals(tip.origin) ||
      r.sections[0].radius !== tip.radius ||
      r.branch.sectionCount !== p.branch.sectionCount ||
      r.branch.segmentCount !== p.branch.segmentCount
    )
      throw new Error("a terminal branch that does not grow from its parent's tip as ez-tree 1.1.0 grows it");
  }
}

/** Each captured section is the centre and radius of the ring of vertices drawn for it. */
function checkSections(tree, records) {
  const verts = tree.branches.verts;
  const ring = new THREE.Vector3(), centre = new THREE.Vector3(), p = new THREE.Vector3();
  for (const r of records) {
    const { sectionCount, segmentCount } = r.branch;
    if (r.sections.length !== sectionCount + 1) throw new Error("a branch's sections do not match its section count");
    r.sections.forEach((s, i) => {
      centre.set(0, 0, 0);
      const first = r.barkVertex + i * (segmentCount + 1);
      for (let j = 0; j < segmentCount; j++) centre.add(ring.fromArray(verts, 3 * (first + j)));
      centre.divideScalar(segmentCount);
      const radius = p.fromArray(verts, 3 * first).distanceTo(centre);
      const tolerance = 1e-6 * Math.max(1, s.origin.length());
      if (centre.distanceTo(s.origin) > tolerance || Math.abs(radius - s.radius) > tolerance)
        throw new Error("a captured section is not where ez-tree drew its ring of vertices");
    });
  }
}

/** The segment of `record` (index into its sections) that `point` lies on, or nearest to. */
function segmentAt(record, point) {
  let best = 0, bestDistance = Infinity;
  const closest = new THREE.Vector3();
  for (let i = 0; i + 1 < record.sections.length; i++) {
    const line = new THREE.Line3(record.sections[i].origin, record.sections[i + 1].origin);
    line.closestPointToPoint(point, true, closest);
    const d = closest.distanceTo(point);
    // A point where two segments meet belongs to the first: a branch at a section's end
    // grows from the segment that ends there.
    if (d < bestDistance - 1e-9 * (1 + point.length())) [best, bestDistance] = [i, d];
  }
  if (bestDistance > 1e-4 * (1 + point.length())) throw new Error("a branch or leaf does not start on its parent");
  return best;
}

// ---- Textures ----------------------------------------------------------------------------

/** The bytes and MIME type of a data: URL. */
function dataUrl(url) {
  const m = /^data:(image\/(?:png|jpeg));base64,(.*)$/s.exec(url ?? "");
  if (!m) throw new Error(`not a PNG or JPEG data: URL: ${String(url).slice(0, 40)}`);
  return { mimeType: m[1], bytes: Buffer.from(m[2], "base64") };
}

/** RGBA of a non-interlaced 8-bit PNG (greyscale, RGB, palette, with or without alpha). */
function decodePng(png) {
  let pos = 8, width, height, type, palette = null, transparency = null;
  const idat = [];
  while (pos < png.length) {
    const length = png.readUInt32BE(pos);
    const kind = png.toString("latin1", pos + 4, pos + 8);
    const data = png.subarray(pos + 8, pos + 8 + length);
    if (kind === "IHDR") {
      [width, height, type] = [data.readUInt32BE(0), data.readUInt32BE(4), data[9]];
      if (data[8] !== 8 || data[12] !== 0) throw new Error("only 8-bit non-interlaced PNGs are read");
    } else if (kind === "PLTE") palette = data;
    else if (kind === "tRNS") transparency = data;
    else if (kind === "IDAT") idat.push(data);
    pos += length + 12;
  }
  const channels = { 0: 1, 2: 3, 3: 1, 4: 2, 6: 4 }[type];
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const px = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? px[y * stride + i - channels] : 0;
      const b = y > 0 ? px[(y - 1) * stride + i] : 0;
      const c = y > 0 && i >= channels ? px[(y - 1) * stride + i - channels] : 0;
      let predicted = 0;
      if (filter === 1) predicted = a;
      else if (filter === 2) predicted = b;
      else if (filter === 3) predicted = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        predicted = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      px[y * stride + i] = (raw[y * (stride + 1) + 1 + i] + predicted) & 0xff;
    }
  }
  const rgba = new Uint8Array(width * height * 4);
  for (let i = 0; i < width * height; i++) {
    let r, g, b, a = 255;
    if (type === 3) {
      const k = px[i];
      [r, g, b] = [palette[3 * k], palette[3 * k + 1], palette[3 * k + 2]];
      if (transparency && k < transparency.length) a = transparency[k];
    } else if (type === 0 || type === 4) {
      r = g = b = px[i * channels];
      if (type === 4) a = px[i * channels + 1];
    } else {
      [r, g, b] = [px[i * channels], px[i * channels + 1], px[i * channels + 2]];
      if (type === 6) a = px[i * channels + 3];
    }
    rgba.set([r, g, b, a], 4 * i);
  }
  return { width, height, rgba };
}

const srgbToLinear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);

/**
 * How much of a leaf quad its picture fills: the texels whose alpha passes `cutoff`, as a
 * fraction of the quad (area) and their extent along the quad's length (from its base, the
 * picture's bottom row as ez-tree maps it) and across its width; and their mean colour.
 */
function leafPicture(png, cutoff) {
  const { width, height, rgba } = decodePng(png);
  let count = 0, row0 = height, row1 = -1, col0 = width, col1 = -1;
  const sum = [0, 0, 0];
  for (let y = 0; y < height; y++)
    for (let x = 0; x < width; x++) {
      const i = 4 * (y * width + x);
      if (rgba[i + 3] / 255 < cutoff) continue;
      count++;
      [row0, row1, col0, col1] = [Math.min(row0, y), Math.max(row1, y), Math.min(col0, x), Math.max(col1, x)];
      for (let k = 0; k < 3; k++) sum[k] += srgbToLinear(rgba[i + k] / 255);
    }
  const round = (x) => Number(x.toFixed(4));
  return {
    texels: [width, height],
    alpha_cutoff: cutoff,
    fill_area: round(count / (width * height)),
    // In the quad's own units (0 to 1): along its length from the base, across from its left.
    fill_along: [round((height - 1 - row1) / height), round((height - row0) / height)],
    fill_across: [round(col0 / width), round((col1 + 1) / width)],
    fill_length: round((row1 - row0 + 1) / height),
    fill_width: round((col1 - col0 + 1) / width),
    mean_color_linear: sum.map((s) => round(s / count)),
  };
}

// glTF's sampler constants for three.js's.
const WRAP = { [THREE.RepeatWrapping]: 10497, [THREE.ClampToEdgeWrapping]: 33071, [THREE.MirroredRepeatWrapping]: 33648 };
const FILTER = {
  [THREE.NearestFilter]: 9728,
  [THREE.LinearFilter]: 9729,
  [THREE.NearestMipmapNearestFilter]: 9984,
  [THREE.LinearMipmapNearestFilter]: 9985,
  [THREE.NearestMipmapLinearFilter]: 9986,
  [THREE.LinearMipmapLinearFilter]: 9987,
};

// ---- GLB ---------------------------------------------------------------------------------

/** A glTF 2.0 binary: one JSON chunk, one BIN chunk. */
class Glb {
  constructor() {
    this.json = {
      asset: { version: "2.0", generator: `Sylva tools/ez-tree-assets (ez-tree ${EZ_TREE_VERSION}, three.js 0.${THREE.REVISION}.x)` },
      scene: 0,
      scenes: [],
      nodes: [],
      meshes: [],
      materials: [],
      textures: [],
      samplers: [],
      images: [],
      accessors: [],
      bufferViews: [],
      buffers: [],
    };
    this.chunks = [];
    this.length = 0;
    this.images = new Map(); // data: URL -> image index
    this.imageBytes = 0;
  }

  view(bytes, target) {
    const view = { buffer: 0, byteOffset: this.length, byteLength: bytes.length };
    if (target) view.target = target;
    this.chunks.push(bytes);
    this.length += bytes.length;
    const pad = (4 - (this.length % 4)) % 4;
    if (pad) {
      this.chunks.push(Buffer.alloc(pad));
      this.length += pad;
    }
    return this.json.bufferViews.push(view) - 1;
  }

  accessor(array, type, target, extra = {}) {
    const bytes = Buffer.from(array.buffer, array.byteOffset, array.byteLength);
    const componentType = { Float32Array: 5126, Uint16Array: 5123, Uint32Array: 5125 }[array.constructor.name];
    const width = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[type];
    const accessor = { bufferView: this.view(bytes, target), componentType, count: array.length / width, type, ...extra };
    return this.json.accessors.push(accessor) - 1;
  }

  image(url, name) {
    if (!this.images.has(url)) {
      const { mimeType, bytes } = dataUrl(url);
      this.imageBytes += bytes.length;
      this.images.set(url, this.json.images.push({ name, mimeType, bufferView: this.view(bytes) }) - 1);
    }
    return this.images.get(url);
  }

  texture(map, name) {
    const sampler = {
      magFilter: FILTER[map.magFilter],
      minFilter: FILTER[map.minFilter],
      wrapS: WRAP[map.wrapS],
      wrapT: WRAP[map.wrapT],
    };
    if (Object.values(sampler).includes(undefined)) throw new Error(`texture ${name}: a filter or wrap glTF has no name for`);
    let s = this.json.samplers.findIndex((x) => JSON.stringify(x) === JSON.stringify(sampler));
    if (s < 0) s = this.json.samplers.push(sampler) - 1;
    return this.json.textures.push({ sampler: s, source: this.image(map.userData.url, name) }) - 1;
  }

  bytes() {
    this.json.buffers = [{ byteLength: this.length }];
    for (const key of Object.keys(this.json)) if (Array.isArray(this.json[key]) && this.json[key].length === 0) delete this.json[key];
    let json = Buffer.from(JSON.stringify(this.json), "utf8");
    json = Buffer.concat([json, Buffer.alloc((4 - (json.length % 4)) % 4, 0x20)]);
    const bin = Buffer.concat(this.chunks);
    const header = Buffer.alloc(12);
    header.writeUInt32LE(0x46546c67, 0); // "glTF"
    header.writeUInt32LE(2, 4);
    header.writeUInt32LE(12 + 8 + json.length + 8 + bin.length, 8);
    const chunkHeader = (length, kind) => {
      const h = Buffer.alloc(8);
      h.writeUInt32LE(length, 0);
      h.writeUInt32LE(kind, 4);
      return h;
    };
    return Buffer.concat([header, chunkHeader(json.length, 0x4e4f534a), json, chunkHeader(bin.length, 0x004e4942), bin]);
  }
}

/**
 * A material's colour as glTF wants it, linear RGB: ez-tree gives its tints as sRGB hex
 * numbers, which three.js converts to its linear working space when the Color is made.
 */
function linearFactor(color) {
  const linear = {};
  color.getRGB(linear, THREE.LinearSRGBColorSpace);
  return [linear.r, linear.g, linear.b];
}

/**
 * A mesh's world-space triangles: positions scaled about the foot, normals, texture
 * coordinates (after `uvTransform`, ez-tree's repeat) and, with `tangents`, a tangent space
 * for a normal map. Texture coordinates are returned as three.js samples them (v = 0 at the
 * picture's bottom row, ez-tree's textures having flipY), turned into glTF's (v = 0 at the
 * top row) by the caller.
 */
function meshData(mesh, scale, uvTransform, tangents) {
  const g = mesh.geometry;
  const position = g.attributes.position, normal = g.attributes.normal, uv = g.attributes.uv;
  const n = position.count;
  // ez-tree's own index buffers are Uint16: more than 65536 vertices would wrap in ez-tree.
  if (n > 65536) throw new Error(`${mesh.name}: ${n} vertices, more than ez-tree's 16-bit indices hold`);
  const normalMatrix = new THREE.Matrix3().getNormalMatrix(mesh.matrixWorld);
  const positions = new Float64Array(3 * n), normals = new Float64Array(3 * n), uvs = new Float64Array(2 * n);
  const p = new THREE.Vector3(), q = new THREE.Vector3(), t = new THREE.Vector2();
  for (let i = 0; i < n; i++) {
    p.fromBufferAttribute(position, i).applyMatrix4(mesh.matrixWorld).multiplyScalar(scale);
    positions.set([p.x, p.y, p.z], 3 * i);
    q.fromBufferAttribute(normal, i).applyMatrix3(normalMatrix).normalize();
    normals.set([q.x, q.y, q.z], 3 * i);
    t.fromBufferAttribute(uv, i);
    if (uvTransform) t.applyMatrix3(uvTransform);
    uvs.set([t.x, t.y], 2 * i);
  }
  const index = Array.from(g.index.array);
  for (const i of index) if (i >= n) throw new Error(`${mesh.name}: an index past its vertices`);
  const data = { positions, normals, uvs, index };
  return tangents ? withTangents(data) : data;
}

/**
 * Per-vertex tangents (glTF's TANGENT: xyz along +u, w the handedness, the bitangent
 * cross(normal, tangent) * w pointing up the picture). ez-tree maps its bark with v running
 * 0, 1, 0, 1 ... from ring to ring, a mirror image on every other section, which three.js
 * shades per pixel; here a vertex whose triangles disagree on the handedness is split in
 * two, one per handedness, as MikkTSpace splits mirrored seams, so each section keeps its
 * own tangent space.
 */
function withTangents({ positions, normals, uvs, index }) {
  const v3 = (a, i) => new THREE.Vector3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
  const triangles = [];
  for (let k = 0; k < index.length; k += 3) {
    const [a, b, c] = index.slice(k, k + 3);
    const e1 = v3(positions, b).sub(v3(positions, a)), e2 = v3(positions, c).sub(v3(positions, a));
    const du1 = uvs[2 * b] - uvs[2 * a], dv1 = uvs[2 * b + 1] - uvs[2 * a + 1];
    const du2 = uvs[2 * c] - uvs[2 * a], dv2 = uvs[2 * c + 1] - uvs[2 * a + 1];
    const det = du1 * dv2 - du2 * dv1;
    let sdir = null, tdir = null, sign = 0;
    if (det !== 0 && Number.isFinite(1 / det)) {
      sdir = e1.clone().multiplyScalar(dv2).addScaledVector(e2, -dv1).divideScalar(det); // along +u
      tdir = e2.clone().multiplyScalar(du1).addScaledVector(e1, -du2).divideScalar(det); // along +v
      const face = e1.clone().cross(e2);
      const s = face.clone().cross(sdir).dot(tdir);
      sign = s < 0 ? -1 : s > 0 ? 1 : 0;
    }
    triangles.push({ corners: [a, b, c], sdir, sign });
  }
  // Each vertex's handedness: that of its first triangle with one; a later triangle of the
  // other handedness gets a copy of the vertex.
  const first = new Map();
  for (const { corners, sign } of triangles) for (const v of corners) if (sign && !first.has(v)) first.set(v, sign);
  const out = { positions: [], normals: [], uvs: [], index: [], tangents: [] };
  const slot = new Map(); // "vertex sign" -> new index
  const accumulated = [];
  const vertex = (v, sign) => {
    const key = `${v} ${sign || first.get(v) || 1}`;
    if (!slot.has(key)) {
      slot.set(key, out.positions.length / 3);
      out.positions.push(...positions.slice(3 * v, 3 * v + 3));
      out.normals.push(...normals.slice(3 * v, 3 * v + 3));
      out.uvs.push(uvs[2 * v], uvs[2 * v + 1]);
      accumulated.push({ t: new THREE.Vector3(), sign: sign || first.get(v) || 1 });
    }
    return slot.get(key);
  };
  for (const { corners, sdir, sign } of triangles)
    for (const v of corners) {
      const i = vertex(v, sign);
      if (sdir) accumulated[i].t.add(sdir);
      out.index.push(i);
    }
  accumulated.forEach(({ t, sign }, i) => {
    const nrm = v3(out.normals, i);
    t.addScaledVector(nrm, -nrm.dot(t)); // Gram-Schmidt: perpendicular to the normal
    if (t.lengthSq() < 1e-20) {
      // No triangle with a usable picture gradient: any direction across the normal.
      t.set(1, 0, 0).addScaledVector(nrm, -nrm.x);
      if (t.lengthSq() < 1e-6) t.set(0, 0, 1).addScaledVector(nrm, -nrm.z);
    }
    t.normalize();
    out.tangents.push(t.x, t.y, t.z, sign);
  });
  return out;
}

/** The GLB of `tree`, scaled by `scale`, and the bytes of its embedded images. */
function treeGlb(tree, scale, name, extras) {
  const glb = new Glb();
  const primitives = [];
  const bark = tree.branchesMesh.material, leaves = tree.leavesMesh.material;

  // Bark: its colour picture and normal map repeat as ez-tree repeats them (textureScale),
  // baked into the texture coordinates (both maps share one transform in ez-tree).
  let barkUv = null;
  if (bark.map) {
    bark.map.updateMatrix();
    barkUv = bark.map.matrix.clone();
    if (bark.normalMap) {
      bark.normalMap.updateMatrix();
      if (!bark.normalMap.matrix.equals(barkUv)) throw new Error("bark maps with different repeats");
    }
  }
  const barkMaterial = {
    name: "bark",
    pbrMetallicRoughness: { baseColorFactor: [...linearFactor(bark.color), 1], metallicFactor: 0, roughnessFactor: 1 },
  };
  if (bark.map) barkMaterial.pbrMetallicRoughness.baseColorTexture = { index: glb.texture(bark.map, `${tree.options.bark.type}_bark_color`) };
  if (bark.normalMap) barkMaterial.normalTexture = { index: glb.texture(bark.normalMap, `${tree.options.bark.type}_bark_normal`) };
  if (bark.side === THREE.DoubleSide) barkMaterial.doubleSided = true;

  const leafUv = leaves.map ? (leaves.map.updateMatrix(), leaves.map.matrix.clone()) : null;
  const leafMaterial = {
    name: "leaf",
    pbrMetallicRoughness: { baseColorFactor: [...linearFactor(leaves.color), 1], metallicFactor: 0, roughnessFactor: 1 },
    alphaMode: "MASK",
    alphaCutoff: leaves.alphaTest,
    doubleSided: leaves.side === THREE.DoubleSide,
  };
  if (leaves.map) leafMaterial.pbrMetallicRoughness.baseColorTexture = { index: glb.texture(leaves.map, `${tree.options.leaves.type}_leaves_color`) };

  for (const [mesh, material, uvTransform] of [
    [tree.branchesMesh, barkMaterial, barkUv],
    [tree.leavesMesh, leafMaterial, leafUv],
  ]) {
    if (mesh.geometry.attributes.position.count === 0) continue;
    const data = meshData(mesh, scale, uvTransform, material.normalTexture !== undefined);
    const positions = new Float32Array(data.positions);
    const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < positions.length; i++) {
      min[i % 3] = Math.min(min[i % 3], positions[i]);
      max[i % 3] = Math.max(max[i % 3], positions[i]);
    }
    // glTF's v = 0 is the picture's top row, three.js's (flipY) its bottom row.
    const uvs = new Float32Array(data.uvs).map((x, i) => (i % 2 ? 1 - x : x));
    const count = positions.length / 3;
    const attributes = {
      POSITION: glb.accessor(positions, "VEC3", 34962, { min, max }),
      NORMAL: glb.accessor(new Float32Array(data.normals), "VEC3", 34962),
      TEXCOORD_0: glb.accessor(uvs, "VEC2", 34962),
    };
    if (data.tangents) attributes.TANGENT = glb.accessor(new Float32Array(data.tangents), "VEC4", 34962);
    primitives.push({
      attributes,
      indices: glb.accessor(count <= 65535 ? new Uint16Array(data.index) : new Uint32Array(data.index), "SCALAR", 34963),
      material: glb.json.materials.push(material) - 1,
    });
  }
  glb.json.meshes.push({ name, primitives });
  glb.json.nodes.push({ name, mesh: 0, extras });
  glb.json.scenes.push({ nodes: [0] });
  return { bytes: glb.bytes(), imageBytes: glb.imageBytes, json: glb.json };
}

// ---- Skeleton ----------------------------------------------------------------------------

/** A number as Sylva writes a 32-bit float: the shortest decimal that reads back to it. */
function f32(x) {
  const f = Math.fround(x);
  if (!Number.isFinite(f)) throw new Error(`a number that is not finite: ${x}`);
  if (f === 0) return "0.0";
  for (let digits = 1; digits <= 9; digits++) {
    const n = Number(f.toPrecision(digits));
    if (Math.fround(n) === f) {
      const s = String(n);
      return /[.e]/.test(s) ? s : `${s}.0`;
    }
  }
  throw new Error("unreachable");
}
const vec = (v) => `[${v.map(f32).join(",")}]`;

/** JSON with every object's keys sorted (Sylva writes genomes canonically). */
function canonical(value) {
  if (Array.isArray(value)) return `[${value.map(canonical).join(",")}]`;
  if (value && typeof value === "object")
    return `{${Object.keys(value).sort().map((k) => `${JSON.stringify(k)}:${canonical(value[k])}`).join(",")}}`;
  return JSON.stringify(value);
}

/** The segments and organs of a captured tree, in metres after `scale`. */
function skeletonOf(tree, records, scale) {
  const segments = [];
  for (const r of records) {
    const n = r.sections.length - 1;
    if (n < 1) throw new Error("a branch of one section has no segment");
    r.firstSegment = segments.length;
    // A terminal branch continues its parent's axis from its last segment (Sylva's
    // continuation: not lateral, the same order); any other branch leaves its parent part-way
    // along a segment, as a lateral one order higher.
    const parent = !r.parent
      ? null
      : r.terminal
        ? r.parent.firstSegment + r.parent.sections.length - 2
        : r.parent.firstSegment + segmentAt(r.parent, r.origin);
    r.order = !r.parent ? 0 : r.terminal ? r.parent.order : r.parent.order + 1;
    for (let i = 0; i < n; i++) {
      const [a, b] = [r.sections[i], r.sections[i + 1]];
      segments.push({
        start: a.origin.clone().multiplyScalar(scale).toArray(),
        end: b.origin.clone().multiplyScalar(scale).toArray(),
        start_radius: a.radius * scale,
        end_radius: b.radius * scale,
        order: r.order,
        parent: i === 0 ? parent : r.firstSegment + i - 1,
        lateral: i === 0 && r.parent !== null && !r.terminal,
      });
    }
  }

  // Leaves: every quad ez-tree drew, read from its mesh. A quad's corners are, in order,
  // tip-left, base-left, base-right, tip-right; its triangles (0 1 2) and (0 2 3).
  const position = tree.leavesMesh.geometry.attributes.position;
  const index = tree.leavesMesh.geometry.index.array;
  const organs = [];
  const c = [0, 1, 2, 3].map(() => new THREE.Vector3());
  const x = new THREE.Vector3(), y = new THREE.Vector3(), z = new THREE.Vector3();
  const basis = new THREE.Matrix4(), q = new THREE.Quaternion();
  for (const r of records)
    for (let quad = r.firstQuad; quad < r.endQuad; quad++) {
      const expected = [0, 1, 2, 0, 2, 3].map((k) => 4 * quad + k);
      if (expected.some((v, k) => index[6 * quad + k] !== v)) throw new Error("a leaf quad is not drawn as ez-tree 1.1.0 draws it");
      c.forEach((v, k) => v.fromBufferAttribute(position, 4 * quad + k).applyMatrix4(tree.leavesMesh.matrixWorld));
      const base = c[1].clone().add(c[2]).multiplyScalar(0.5);
      x.subVectors(c[2], c[1]);
      y.subVectors(c[0], c[1]);
      const width = x.length(), length = y.length();
      x.normalize();
      y.normalize();
      z.crossVectors(x, y);
      // The quad is a rectangle: its far side parallel to its base, its sides at right angles.
      const far = c[3].clone().sub(c[0]);
      if (Math.abs(x.dot(y)) > 1e-3 || far.distanceTo(x.clone().multiplyScalar(width)) > 1e-3 * (1 + width))
        throw new Error("a leaf quad is not a rectangle");
      q.setFromRotationMatrix(basis.makeBasis(x, y, z)).normalize();
      organs.push({
        position: base.multiplyScalar(scale).toArray(),
        orientation: q.toArray(),
        axis: y.toArray(),
        normal: z.toArray(),
        length: length * scale,
        width: width * scale,
        parent: r.firstSegment + segmentAt(r, c[1].clone().add(c[2]).multiplyScalar(0.5)),
      });
    }
  if (organs.length * 4 !== position.count) throw new Error("leaf quads that no branch made");
  return { segments, organs };
}

/** A leaf's length over its quad's: ez-tree's leaf pictures are sprigs of many leaves. */
const LEAF_OF_CARD = 0.1;

function skeletonJson({ seed, genome, materials, segments, organs }) {
  const lines = [
    "{",
    '  "format": 1,',
    '  "kind": "sylva-skeleton",',
    `  "sylva_version": ${JSON.stringify(SYLVA_VERSION)},`,
    '  "origin": {',
    '    "model": "ez-tree",',
    '    "genome_hash": "0000000000000000",',
    `    "seed": ${seed},`,
    `    "genome": ${canonical(genome)}`,
    "  },",
    '  "taper": null,',
    '  "roots": false,',
  ];
  const list = (name, items, last) => {
    if (items.length === 0) return lines.push(`  "${name}": []${last ? "" : ","}`);
    lines.push(`  "${name}": [`);
    items.forEach((item, i) => lines.push(`    ${item}${i + 1 < items.length ? "," : ""}`));
    lines.push(`  ]${last ? "" : ","}`);
  };
  list(
    "materials",
    materials.map(
      (m) =>
        `{"name":${JSON.stringify(m.name)},"kind":"${m.kind}","color":${vec(m.color)},"texture":null` +
        (m.fill === undefined ? "" : `,"fill":${m.fill},"leaf_of_card":${m.leaf_of_card}`) +
        "}",
    ),
  );
  list(
    "segments",
    segments.map(
      (s) =>
        `{"start":${vec(s.start)},"end":${vec(s.end)},"start_radius":${f32(s.start_radius)},"end_radius":${f32(s.end_radius)},` +
        `"order":${s.order},"parent":${s.parent},"lateral":${s.lateral},"material":0,"kind":"bark","woody":true}`,
    ),
  );
  list(
    "organs",
    organs.map(
      (o) =>
        `{"kind":"leaf","position":${vec(o.position)},"orientation":${vec(o.orientation)},"axis":${vec(o.axis)},` +
        `"normal":${vec(o.normal)},"length":${f32(o.length)},"width":${f32(o.width)},"parent":${o.parent},"material":1}`,
    ),
    true,
  );
  lines.push("}");
  return lines.join("\n") + "\n";
}

// The Sylva version whose skeleton format the files follow (the workspace's version).
const SYLVA_VERSION = (() => {
  try {
    const toml = fs.readFileSync(path.join(root, "Cargo.toml"), "utf8");
    return /\[workspace\.package\][^[]*?\nversion\s*=\s*"([^"]+)"/.exec(toml)?.[1] ?? "0.1.0";
  } catch {
    return "0.1.0";
  }
})();

// ---- Main --------------------------------------------------------------------------------

/** Writes `bytes` to `file` through a temporary name, so a file is whole or absent. */
function writeWhole(file, bytes) {
  fs.writeFileSync(`${file}.tmp`, bytes);
  fs.renameSync(`${file}.tmp`, file);
}

const leafPictures = new Map();
const index = [];
fs.mkdirSync(outDir, { recursive: true });
for (const spec of TREES) {
  if (only && !only.includes(spec.name)) continue;
  const tree = optionsOf(spec);
  const records = growCaptured(tree);

  // Height: the highest vertex of either mesh above the foot (the trunk's base, at the origin).
  let top = -Infinity;
  const p = new THREE.Vector3();
  for (const mesh of [tree.branchesMesh, tree.leavesMesh]) {
    const position = mesh.geometry.attributes.position;
    for (let i = 0; i < position.count; i++) top = Math.max(top, p.fromBufferAttribute(position, i).applyMatrix4(mesh.matrixWorld).y);
  }
  const height = heightOption === "auto" ? AUTO_HEIGHT[spec.bush ? "bush" : "tree"] : heightOption === "natural" ? top : Number(heightOption);
  const scale = height / top;

  const leaves = tree.leavesMesh.material;
  const leafUrl = leaves.map?.userData.url;
  const pictureKey = `${leaves.alphaTest} ${leafUrl}`;
  if (leafUrl && !leafPictures.has(pictureKey)) leafPictures.set(pictureKey, leafPicture(dataUrl(leafUrl).bytes, leaves.alphaTest));
  const genome = {
    preset: spec.preset ?? null,
    ...(spec.own ? { approximation: spec.name, based_on: spec.own.base } : {}),
    ez_tree: EZ_TREE_VERSION,
    options: structuredClone(tree.options),
    natural_height: top,
    height,
    scale,
    leaf_picture: { type: tree.options.leaves.type, ...(leafPictures.get(pictureKey) ?? {}) },
  };

  const extras = { generator: "ez-tree", genome, seed: spec.seed, height, scale };
  const glb = treeGlb(tree, scale, spec.name, extras);
  const { segments, organs } = skeletonOf(tree, records, scale);
  const materials = [
    { name: "bark", kind: "bark", color: linearFactor(tree.branchesMesh.material.color) },
    {
      name: "leaf",
      kind: "leaf",
      color: linearFactor(leaves.color),
      // The share of a quad the leaf picture covers, measured from its alpha; one leaf of
      // the sprig is about a tenth of the quad's length (ez-tree's pictures, by eye).
      fill: genome.leaf_picture.fill_area,
      leaf_of_card: LEAF_OF_CARD,
    },
  ];
  writeWhole(path.join(outDir, `${spec.name}.glb`), glb.bytes);
  writeWhole(
    path.join(outDir, `${spec.name}.skeleton.json`),
    skeletonJson({ seed: spec.seed, genome, materials, segments, organs }),
  );
  const entry = {
    name: spec.name,
    preset: spec.preset ?? null,
    ...(spec.own ? { approximation: spec.name, based_on: spec.own.base } : {}),
    seed: spec.seed,
    triangles: tree.triangleCount,
    natural_height: top,
    height,
    scale,
    segments: segments.length,
    terminals: records.filter((r) => r.terminal).length,
    organs: organs.length,
    texture_bytes: glb.imageBytes,
    leaf_picture: genome.leaf_picture,
    textures: glb.json.images.map((im) => ({ name: im.name, mime_type: im.mimeType, bytes: glb.json.bufferViews[im.bufferView].byteLength })),
    glb_bytes: glb.bytes.length,
  };
  index.push(entry);
  console.log(
    `${spec.name}: ${entry.triangles} triangles, ${top.toFixed(2)} units tall -> ${height} m (scale ${scale.toFixed(5)}), ` +
      `${segments.length} segments (${entry.terminals} terminal branches as continuations), ${organs.length} leaf quads, ` +
      `${entry.texture_bytes} texture bytes`,
  );
}
writeWhole(path.join(outDir, "index.json"), JSON.stringify(index, null, 2) + "\n");
console.log(`wrote ${index.length} trees to ${path.relative(process.cwd(), outDir) || "."}`);
