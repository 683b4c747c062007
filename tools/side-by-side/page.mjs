// The page of tools/side-by-side (render.mjs serves it and drives it in headless chromium):
// loads GLB files with three.js's GLTFLoader, stands them side by side on one ground, each
// scaled about its foot to one height, under one light rig and one camera, renders the row
// (supersampled, or with MSAA when not), checks that every tree drew something and that the
// picture is not blank, draws the labels and hands the PNG back as a data: URL. Everything here is deterministic: fixed sizes, no clock, no
// animation (a file's animations are never played), no random numbers.
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { DRACOLoader } from "three/addons/loaders/DRACOLoader.js";
import { KTX2Loader } from "three/addons/loaders/KTX2Loader.js";
import { MeshoptDecoder } from "three/addons/libs/meshopt_decoder.module.js";

/** The one light rig, ground and sky, for every tree. Colours are sRGB hex numbers. */
export const RIG = {
  sky: 0xc9d3dc, // background, and the fog that melts the far ground into it
  hemisphere: { sky: 0xdce6f2, ground: 0x5c5846, intensity: 1.15 },
  // The sun: from the upper front-left (towards -x, +y, +z), about 45 degrees high.
  sun: { color: 0xfff3e2, intensity: 2.7, direction: [-0.55, 1.0, 0.75], mapSize: { min: 1024, max: 4096 }, radius: 2.5 },
  ground: 0x8a9274, // a muted, neutral grass
  toneMapping: THREE.NeutralToneMapping,
  exposure: 1.0,
};

/**
 * The views. The camera always looks towards -z (the row runs along x) and is pitched down;
 * `iso` turns every tree 45 degrees about its foot instead of moving the camera round the
 * row, so each tree is seen from its front-right as `sylva render --view iso` sees it (eye at
 * +x +z, 30 degrees up), all at the same distance, and the row stays straight in the picture.
 */
const VIEWS = {
  front: { pitch: 3, yaw: 0 },
  iso: { pitch: 30, yaw: -45 },
};
const FOV = 30; // vertical field of view that sets the camera's distance, degrees

const deg = Math.PI / 180;

class FileError extends Error {
  constructor(file, message) {
    super(message);
    this.file = file;
  }
}

/** Calls `visit(point)` for every vertex of `root` in its world space (instances included). */
function forEachVertex(root, visit) {
  const p = new THREE.Vector3(), m = new THREE.Matrix4(), im = new THREE.Matrix4();
  root.updateMatrixWorld(true);
  root.traverse((o) => {
    const position = o.geometry?.attributes?.position;
    if (!position || !(o.isMesh || o.isLine || o.isPoints)) return;
    const instances = o.isInstancedMesh ? o.count : 1;
    for (let k = 0; k < instances; k++) {
      if (o.isInstancedMesh) m.multiplyMatrices(o.matrixWorld, (o.getMatrixAt(k, im), im));
      else m.copy(o.matrixWorld);
      for (let i = 0; i < position.count; i++) visit(p.fromBufferAttribute(position, i).applyMatrix4(m));
    }
  });
}

/** Triangles drawn by `root`'s meshes, each instance counted. */
function triangles(root) {
  let n = 0;
  root.traverse((o) => {
    if (!o.isMesh || !o.geometry) return;
    const g = o.geometry;
    const count = g.index ? g.index.count : (g.attributes.position?.count ?? 0);
    n += Math.floor(count / 3) * (o.isInstancedMesh ? o.count : 1);
  });
  return n;
}

/**
 * Where a file's tree stands and how big it is. Its foot is the file's origin, as Sylva's
 * and ez-tree's trees stand (roots or hanging leaves may reach below y = 0); on an axis the
 * model does not span, the middle of its box across (x, z) and its lowest point up (y).
 * `yaw` turns it about its foot; the extents are in that turned frame, relative to the foot.
 */
function measure(scene, yaw, file) {
  const box = new THREE.Box3();
  let count = 0;
  forEachVertex(scene, (p) => {
    box.expandByPoint(p);
    count++;
  });
  if (count === 0 || box.isEmpty()) throw new FileError(file, "has no geometry to draw");
  const foot = new THREE.Vector3(0, 0, 0);
  if (!(box.min.y <= 0 && box.max.y > 0)) foot.y = box.min.y;
  if (!(box.min.x <= 0 && box.max.x >= 0)) foot.x = (box.min.x + box.max.x) / 2;
  if (!(box.min.z <= 0 && box.max.z >= 0)) foot.z = (box.min.z + box.max.z) / 2;
  const height = box.max.y - foot.y;
  if (!(height > 0) || !Number.isFinite(height)) throw new FileError(file, "has no height above its foot");
  // The extents in the turned frame (three.js's rotation about y: x' = x cos + z sin).
  const c = Math.cos(yaw), s = Math.sin(yaw);
  const turned = new THREE.Box3();
  const q = new THREE.Vector3();
  forEachVertex(scene, (p) => {
    const x = p.x - foot.x, z = p.z - foot.z;
    turned.expandByPoint(q.set(x * c + z * s, p.y - foot.y, -x * s + z * c));
  });
  return { box, foot, height, turned, vertices: count };
}

/** The sRGB 8-bit value of each linear value 0..4095/4095, and the linear value of each byte. */
const TO_LINEAR = Float32Array.from({ length: 256 }, (_, i) => {
  const c = i / 255;
  return c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
});
const TO_SRGB = Uint8ClampedArray.from({ length: 4096 }, (_, i) => {
  const c = i / 4095;
  return Math.round(255 * (c <= 0.0031308 ? c * 12.92 : 1.055 * c ** (1 / 2.4) - 0.055));
});

/**
 * Averages `ss` x `ss` blocks of an RGBA picture read from WebGL (rows bottom-up) in linear
 * light into `out` (an ImageData, rows top-down).
 */
function downsample(src, width, height, ss, out) {
  const W = width * ss;
  const n = ss * ss;
  const d = out.data;
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      let r = 0, g = 0, b = 0;
      for (let j = 0; j < ss; j++) {
        const row = (height - 1 - y) * ss + (ss - 1 - j); // bottom-up rows
        let k = 4 * (row * W + x * ss);
        for (let i = 0; i < ss; i++, k += 4) {
          r += TO_LINEAR[src[k]];
          g += TO_LINEAR[src[k + 1]];
          b += TO_LINEAR[src[k + 2]];
        }
      }
      const o = 4 * (y * width + x);
      d[o] = TO_SRGB[Math.round((r / n) * 4095)];
      d[o + 1] = TO_SRGB[Math.round((g / n) * 4095)];
      d[o + 2] = TO_SRGB[Math.round((b / n) * 4095)];
      d[o + 3] = 255;
    }
  }
}

/**
 * Fits a camera pitched down by `pitch` (radians, looking towards -z) to `points` (x, y, z,
 * flat): the distance at which they fill a FOV-degree view, and a shifted lens (an off-centre
 * frustum) that frames them with room for the labels below, so that the pitch alone sets the
 * perspective. Returns the camera and its distance from the points' centre.
 */
function fitCamera(points, pitch, aspect, labelRoom) {
  const forward = new THREE.Vector3(0, -Math.sin(pitch), -Math.cos(pitch));
  const right = new THREE.Vector3(1, 0, 0);
  const up = new THREE.Vector3().crossVectors(right, forward);
  const n = points.length / 3;
  const centre = new THREE.Vector3();
  for (let i = 0; i < points.length; i += 3) centre.x += points[i], centre.y += points[i + 1], centre.z += points[i + 2];
  centre.divideScalar(n);
  const tanV = Math.tan((FOV / 2) * deg), tanH = tanV * aspect;
  // Fractions of the picture the points may fill: a margin each side, the labels below.
  const [left, rightEdge, bottom, top] = [0.03, 0.97, labelRoom, 0.965];
  const project = (eye) => {
    let [x0, x1, y0, y1] = [Infinity, -Infinity, Infinity, -Infinity];
    for (let i = 0; i < points.length; i += 3) {
      const vx = points[i] - eye.x, vy = points[i + 1] - eye.y, vz = points[i + 2] - eye.z;
      const z = vx * forward.x + vy * forward.y + vz * forward.z;
      const x = (vx * right.x + vy * right.y + vz * right.z) / z;
      const y = (vx * up.x + vy * up.y + vz * up.z) / z;
      if (x < x0) x0 = x;
      if (x > x1) x1 = x;
      if (y < y0) y0 = y;
      if (y > y1) y1 = y;
    }
    return { x0, x1, y0, y1 };
  };
  let radius = 0;
  for (let i = 0; i < points.length; i += 3)
    radius = Math.max(radius, Math.hypot(points[i] - centre.x, points[i + 1] - centre.y, points[i + 2] - centre.z));
  let distance = radius / tanV;
  let eye, b;
  for (let i = 0; i < 60; i++) {
    eye = centre.clone().addScaledVector(forward, -distance);
    b = project(eye);
    const need = Math.max((b.x1 - b.x0) / (2 * tanH * (rightEdge - left)), (b.y1 - b.y0) / (2 * tanV * (top - bottom)));
    if (Math.abs(need - 1) < 1e-6) break;
    distance *= need;
  }
  // The window in tangent units: the points centred across the allowed band; up and down,
  // of the room they leave (a wide row leaves some), 35% below them and 65% above.
  const cx = (b.x0 + b.x1) / 2 - tanH * (left + rightEdge - 1);
  const slack = 2 * tanV * (top - bottom) - (b.y1 - b.y0);
  const cy = b.y0 - 0.35 * slack - tanV * (2 * bottom - 1);
  const camera = new THREE.PerspectiveCamera(FOV, aspect, distance / 200, distance * 400);
  camera.position.copy(eye);
  camera.up.copy(up);
  camera.lookAt(eye.clone().add(forward));
  const near = camera.near;
  camera.projectionMatrix.makePerspective(
    (cx - tanH) * near, (cx + tanH) * near, (cy + tanV) * near, (cy - tanV) * near, near, camera.far,
  );
  camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
  camera.updateMatrixWorld(true);
  return { camera, distance };
}

/** Fits the sun's shadow camera to the trees' boxes and the ground their shadows fall on. */
function fitSun(sun, corners, centre, tallest) {
  const toSun = sun.position.clone().sub(sun.target.position).normalize();
  const points = [];
  for (const p of corners) {
    points.push(p);
    points.push(p.clone().addScaledVector(toSun, -Math.max(p.y, 0) / toSun.y)); // its shadow on y = 0
  }
  let radius = 0;
  for (const p of points) radius = Math.max(radius, p.distanceTo(centre));
  sun.target.position.copy(centre);
  sun.position.copy(centre).addScaledVector(toSun, 2 * radius + 10);
  sun.updateMatrixWorld(true);
  sun.target.updateMatrixWorld(true);
  const view = new THREE.Matrix4().lookAt(sun.position, centre, new THREE.Vector3(0, 1, 0));
  view.setPosition(sun.position).invert();
  const box = new THREE.Box3();
  for (const p of points) box.expandByPoint(p.clone().applyMatrix4(view));
  const pad = 0.02 * Math.max(box.max.x - box.min.x, box.max.y - box.min.y);
  const cam = sun.shadow.camera;
  [cam.left, cam.right, cam.bottom, cam.top] = [box.min.x - pad, box.max.x + pad, box.min.y - pad, box.max.y + pad];
  [cam.near, cam.far] = [Math.max(0.01, -box.max.z - pad), -box.min.z + pad];
  cam.updateProjectionMatrix();
  // The map: a texel of about 1/300 of the tallest tree (4 cm for 12 m trees), 1024 to 4096
  // texels a side. One texel in metres sets the biases.
  const side = Math.max(cam.right - cam.left, cam.top - cam.bottom);
  const size = Math.min(RIG.sun.mapSize.max, Math.max(RIG.sun.mapSize.min, 2 ** Math.ceil(Math.log2(side / (tallest / 300)))));
  sun.shadow.mapSize.set(size, size);
  const texel = side / size;
  sun.shadow.bias = -0.0002;
  sun.shadow.normalBias = 1.5 * texel;
  return texel;
}

/**
 * Renders the row. `config`: { files: [{ url, file, label }], height (0: each file's own),
 * width, pixelHeight, view, supersample }. Returns { png (data: URL), trees: [...],
 * timings } or { error: { file, message } }.
 */
async function render(config) {
  try {
    return await renderRow(config);
  } catch (e) {
    return { error: { file: e.file ?? null, message: e.message ?? String(e) } };
  }
}

async function renderRow({ files, height: wantedHeight, width, pixelHeight, view: viewName, supersample }) {
  const t0 = performance.now();
  const view = VIEWS[viewName];
  if (!view) throw new Error(`no view ${viewName}`);

  // Antialiasing: the canvas is `supersample` times the picture each way (fewer if WebGL
  // cannot draw that big) and averaged down; MSAA only when there is no supersampling.
  const probe = document.createElement("canvas").getContext("webgl2");
  if (!probe) throw new Error("this chromium has no WebGL 2 (it needs --use-angle=swiftshader --enable-unsafe-swiftshader)");
  const maxSize = Math.min(probe.getParameter(probe.MAX_RENDERBUFFER_SIZE), ...probe.getParameter(probe.MAX_VIEWPORT_DIMS));
  probe.getExtension("WEBGL_lose_context")?.loseContext();
  let ss = supersample;
  while (ss > 1 && Math.max(width, pixelHeight) * ss > maxSize) ss--;
  const [W, H] = [width * ss, pixelHeight * ss];
  const canvas = document.createElement("canvas");
  document.body.appendChild(canvas);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: ss === 1, preserveDrawingBuffer: true });
  const gl = renderer.getContext();
  renderer.setPixelRatio(1);
  renderer.setSize(W, H, false);
  if (gl.drawingBufferWidth !== W || gl.drawingBufferHeight !== H)
    throw new Error(`WebGL gave a ${gl.drawingBufferWidth}x${gl.drawingBufferHeight} canvas for ${W}x${H}: ask for a smaller --size or --supersample`);
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  renderer.toneMapping = RIG.toneMapping;
  renderer.toneMappingExposure = RIG.exposure;
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFShadowMap; // with shadow.radius: soft edges

  const loader = new GLTFLoader();
  loader.setDRACOLoader(new DRACOLoader().setDecoderPath("/three/examples/jsm/libs/draco/gltf/"));
  loader.setKTX2Loader(new KTX2Loader().setTranscoderPath("/three/examples/jsm/libs/basis/").detectSupport(renderer));
  loader.setMeshoptDecoder(MeshoptDecoder);

  // ---- Load every file, measure it, stand it at its place --------------------------------
  const yaw = view.yaw * deg;
  const trees = [];
  for (const f of files) {
    let gltf;
    try {
      gltf = await loader.loadAsync(f.url);
    } catch (e) {
      throw new FileError(f.file, `three.js's GLTFLoader could not load it: ${e?.message ?? e}`);
    }
    const scene = gltf.scene ?? gltf.scenes?.[0];
    if (!scene) throw new FileError(f.file, "has no scene");
    // One rig for all: a file's own lights (KHR_lights_punctual) are taken out.
    const lights = [];
    scene.traverse((o) => o.isLight && lights.push(o));
    for (const light of lights) light.removeFromParent();
    const m = measure(scene, yaw, f.file);
    const scale = wantedHeight > 0 ? wantedHeight / m.height : 1;
    // holder: at the tree's place, turned and scaled about the foot; the file's scene moved
    // so that its foot is the holder's origin.
    const holder = new THREE.Group();
    holder.name = f.label;
    holder.rotation.y = yaw;
    holder.scale.setScalar(scale);
    scene.position.sub(m.foot);
    holder.add(scene);
    let masked = false;
    scene.traverse((o) => {
      if (!o.isMesh) return;
      o.castShadow = true;
      o.receiveShadow = true;
      o.frustumCulled = false; // skinned and instanced bounds aside, every tree is in view
      for (const material of Array.isArray(o.material) ? o.material : [o.material]) {
        // Both faces into the shadow map: single-sided leaf cards cast shadows whichever way
        // they face the sun. Alpha-tested (MASK) materials get three.js's depth material with
        // their map and alphaTest, so cut-out leaves cast cut-out shadows.
        material.shadowSide = THREE.DoubleSide;
        if (material.alphaTest > 0) masked = true;
      }
    });
    trees.push({
      ...f,
      holder,
      scale,
      heightBefore: m.height,
      foot: m.foot,
      extent: m.turned.clone().applyMatrix4(new THREE.Matrix4().makeScale(scale, scale, scale)),
      triangles: triangles(scene),
      alphaTested: masked,
      animations: gltf.animations?.length ?? 0,
      lightsRemoved: lights.length,
    });
  }
  const tLoaded = performance.now();

  // ---- The row ----------------------------------------------------------------------------
  const tallest = Math.max(...trees.map((t) => t.extent.max.y));
  const margin = 0.12 * tallest;
  let x = 0;
  for (const [i, t] of trees.entries()) {
    if (i > 0) x += margin - t.extent.min.x;
    t.x = x;
    x += t.extent.max.x;
  }
  const shift = (trees[0].extent.min.x + x) / 2; // centre the row on x = 0
  const zMid = (Math.min(...trees.map((t) => t.extent.min.z)) + Math.max(...trees.map((t) => t.extent.max.z))) / 2;
  const corners = [];
  for (const t of trees) {
    t.x -= shift;
    t.holder.position.set(t.x, 0, -zMid);
    const e = t.extent;
    t.worldBox = new THREE.Box3(
      // Whatever is below the ground (roots, hanging leaves) is hidden by it: not framed.
      new THREE.Vector3(t.x + e.min.x, 0, e.min.z - zMid),
      new THREE.Vector3(t.x + e.max.x, e.max.y, e.max.z - zMid),
    );
    for (const cx of [t.worldBox.min.x, t.worldBox.max.x])
      for (const cy of [t.worldBox.min.y, t.worldBox.max.y])
        for (const cz of [t.worldBox.min.z, t.worldBox.max.z]) corners.push(new THREE.Vector3(cx, cy, cz));
  }
  const rowBox = new THREE.Box3().setFromPoints(corners);
  const rowCentre = rowBox.getCenter(new THREE.Vector3());

  // ---- Scene: sky, ground, the rig ---------------------------------------------------------
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(RIG.sky);
  const labelRoom = 0.11;
  // The camera frames what stands above the ground: every vertex (the boxes would frame the
  // empty corners of a turned tree) and every foot.
  const framed = [];
  for (const t of trees) {
    framed.push(t.holder.position.x, 0, t.holder.position.z);
    forEachVertex(t.holder, (p) => {
      if (p.y >= 0) framed.push(p.x, p.y, p.z);
    });
  }
  const { camera, distance } = fitCamera(Float64Array.from(framed), view.pitch * deg, width / pixelHeight, labelRoom);
  // Fog only far behind the row, where the ground meets the sky: it never touches a tree.
  scene.fog = new THREE.Fog(RIG.sky, distance * 2 + rowBox.max.z - rowBox.min.z, distance * 9);
  const groundRadius = distance * 12;
  const ground = new THREE.Mesh(
    new THREE.CircleGeometry(groundRadius, 256).rotateX(-Math.PI / 2),
    new THREE.MeshStandardMaterial({ color: RIG.ground, roughness: 1, metalness: 0 }),
  );
  ground.receiveShadow = true;
  scene.add(ground);
  const hemisphere = new THREE.HemisphereLight(RIG.hemisphere.sky, RIG.hemisphere.ground, RIG.hemisphere.intensity);
  scene.add(hemisphere);
  const sun = new THREE.DirectionalLight(RIG.sun.color, RIG.sun.intensity);
  sun.position.fromArray(RIG.sun.direction).normalize();
  sun.castShadow = true;
  sun.shadow.radius = RIG.sun.radius;
  scene.add(sun, sun.target);
  const shadowTexel = fitSun(sun, corners, rowCentre, tallest);
  for (const t of trees) scene.add(t.holder);

  // ---- The checks: every tree draws something of its own --------------------------------
  // At a quarter of the canvas (the same programs as the picture), without the ground (so a
  // tree's shadow does not count as drawing it): the sky alone, then the trees against it.
  // Every tree must change the pixels of its box on the screen.
  const project = (p) => {
    const v = p.clone().project(camera);
    return [((v.x + 1) / 2) * W, ((v.y + 1) / 2) * H]; // x right, y up (WebGL's rows)
  };
  const read = (w, h) => {
    const px = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    return px;
  };
  const [cw, ch] = [Math.max(1, Math.floor(W / 4)), Math.max(1, Math.floor(H / 4))];
  renderer.shadowMap.autoUpdate = false; // nothing moves: one shadow map, drawn with the trees
  renderer.setViewport(0, 0, cw, ch);
  ground.visible = false;
  for (const t of trees) t.holder.visible = false;
  renderer.render(scene, camera);
  const sky = read(cw, ch);
  for (const t of trees) t.holder.visible = true;
  renderer.shadowMap.needsUpdate = true;
  renderer.render(scene, camera);
  const alone = read(cw, ch);
  const tChecked = performance.now();
  for (const t of trees) {
    let [x0, x1, y0, y1] = [Infinity, -Infinity, Infinity, -Infinity];
    for (const cx of [t.worldBox.min.x, t.worldBox.max.x])
      for (const cy of [t.worldBox.min.y, t.worldBox.max.y])
        for (const cz of [t.worldBox.min.z, t.worldBox.max.z]) {
          const [px, py] = project(new THREE.Vector3(cx, cy, cz)).map((c) => c / 4);
          [x0, x1, y0, y1] = [Math.min(x0, px), Math.max(x1, px), Math.min(y0, py), Math.max(y1, py)];
        }
    [x0, x1, y0, y1] = [Math.max(0, Math.floor(x0)), Math.min(cw, Math.ceil(x1)), Math.max(0, Math.floor(y0)), Math.min(ch, Math.ceil(y1))];
    let changed = 0;
    for (let y = y0; y < y1; y++)
      for (let x = x0; x < x1; x++) {
        const k = 4 * (y * cw + x);
        if (Math.abs(alone[k] - sky[k]) + Math.abs(alone[k + 1] - sky[k + 1]) + Math.abs(alone[k + 2] - sky[k + 2]) > 24) changed++;
      }
    const area = Math.max(0, x1 - x0) * Math.max(0, y1 - y0);
    t.coverage = area ? changed / area : 0;
    const needed = Math.max(1, Math.min(20, Math.floor(0.01 * area)));
    if (changed < needed)
      throw new FileError(
        t.file,
        `drew nothing visible: ${changed} of the ${area} pixels of its box on the screen (at a quarter of the picture's size) ` +
          `differ from the sky behind it (need ${needed})`,
      );
  }

  // ---- The picture --------------------------------------------------------------------------
  ground.visible = true;
  renderer.setViewport(0, 0, W, H);
  renderer.render(scene, camera);
  const full = read(W, H);
  const tRendered = performance.now();
  // Not blank: the sky, the ground and the trees make many colours.
  const colours = new Set();
  for (let k = 0; k < full.length && colours.size < 16; k += 4 * 101) colours.add((full[k] << 16) | (full[k + 1] << 8) | full[k + 2]);
  if (colours.size < 16) throw new Error(`the WebGL canvas is blank: ${colours.size} colours in the whole picture; is WebGL working?`);

  // ---- The picture: downsampled in linear light, labels drawn in ------------------------
  const out = document.createElement("canvas");
  [out.width, out.height] = [width, pixelHeight];
  const ctx = out.getContext("2d");
  const image = ctx.createImageData(width, pixelHeight);
  downsample(full, width, pixelHeight, ss, image);
  ctx.putImageData(image, 0, 0);

  // Labels: one line under each tree, centred below its foot, on one baseline below the
  // lowest point every tree above the ground reaches on the screen (a crown may reach out in
  // front of its foot).
  const v = new THREE.Vector3();
  const feet = trees.map((t) => {
    const [px, py] = project(t.holder.position);
    let low = py;
    forEachVertex(t.holder, (p) => {
      if (p.y < 0) return;
      v.copy(p).project(camera);
      low = Math.min(low, ((v.y + 1) / 2) * H);
    });
    return [px / ss, pixelHeight - low / ss];
  });
  const font = (size) => `${size}px "DejaVu Sans", "Liberation Sans", Arial, sans-serif`;
  // Each label's box is centred under its tree (kept inside the picture); one that would touch
  // the label before it goes on a second line below. The font shrinks only when two lines are
  // not enough; at 8 px the labels are moved sideways on one line instead, as little as keeps
  // them apart.
  const layout = (size) => {
    ctx.font = font(size);
    const [pad, gap] = [size * 0.45, size * 0.5];
    const boxes = trees.map((t, i) => {
      const w = ctx.measureText(t.label).width + 2 * pad;
      return { left: Math.min(Math.max(feet[i][0] - w / 2, gap), width - gap - w), w, row: 0 };
    });
    const ends = [-Infinity, -Infinity]; // each line's right end so far
    let fits = true;
    for (const b of boxes) {
      b.row = ends.findIndex((end) => end + gap <= b.left);
      if (b.row < 0) fits = false;
      else ends[b.row] = b.left + b.w;
    }
    return { boxes, fits };
  };
  const squeeze = (size) => {
    const { boxes } = layout(size);
    const gap = size * 0.5;
    for (const [i, b] of boxes.entries()) {
      b.row = 0;
      if (i > 0) b.left = Math.max(b.left, boxes[i - 1].left + boxes[i - 1].w + gap);
    }
    for (let i = boxes.length - 1; i >= 0; i--)
      boxes[i].left = Math.min(boxes[i].left, (i + 1 < boxes.length ? boxes[i + 1].left - gap : width - gap) - boxes[i].w);
    return boxes;
  };
  let fontSize = Math.round(Math.max(12, pixelHeight * 0.026));
  let { boxes, fits } = layout(fontSize);
  while (!fits && fontSize > 8) ({ boxes, fits } = layout(--fontSize));
  if (!fits) boxes = squeeze(fontSize);
  ctx.font = font(fontSize);
  const lines = Math.max(...boxes.map((b) => b.row)) + 1;
  const lineHeight = fontSize * 1.5;
  const baseline = Math.min(pixelHeight - fontSize * 0.7 - (lines - 1) * lineHeight, Math.max(...feet.map((f) => f[1])) + fontSize * 1.5);
  ctx.textAlign = "center";
  ctx.textBaseline = "alphabetic";
  for (const [i, t] of trees.entries()) {
    const { left, w, row } = boxes[i];
    const y = baseline + row * lineHeight;
    ctx.fillStyle = "rgba(255, 255, 255, 0.8)";
    ctx.beginPath();
    ctx.roundRect(left, y - fontSize * 1.0, w, fontSize * 1.35, fontSize * 0.3);
    ctx.fill();
    ctx.fillStyle = "#1f2328";
    ctx.fillText(t.label, left + w / 2, y);
  }
  const png = out.toDataURL("image/png");
  const tDone = performance.now();

  const result = {
    png,
    width,
    height: pixelHeight,
    supersample: ss,
    shadowTexel,
    shadowMapSize: sun.shadow.mapSize.x,
    camera: { position: camera.position.toArray(), distance, pitch: view.pitch, yaw: view.yaw, fov: FOV },
    trees: trees.map((t) => ({
      file: t.file,
      label: t.label,
      triangles: t.triangles,
      height_before: t.heightBefore,
      scale: t.scale,
      height_after: t.heightBefore * t.scale,
      alpha_tested: t.alphaTested,
      animations: t.animations,
      lights_removed: t.lightsRemoved,
      x: t.x,
      width: t.worldBox.max.x - t.worldBox.min.x,
      coverage: t.coverage,
    })),
    timings: { load: tLoaded - t0, check: tChecked - tLoaded, render: tRendered - tChecked, picture: tDone - tRendered },
  };
  renderer.dispose();
  return result;
}

window.sideBySide = { render, RIG, VIEWS };
