// 3D views. A Stage is one WebGLRenderer on one canvas; it draws any number of Views, each the
// rectangle of an ordinary element (three.js's "multiple elements" pattern: a scissor and a
// viewport per element), so the nine plants of the Breed grid share one WebGL context.
// Nothing renders in a loop: a stage draws when asked (a plant arrived, a control moved, the
// page resized) and then tells whoever waits for the paint.

import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { getBytes } from "./api.js";

export { THREE };

export const BACKGROUND = new THREE.Color(0x1d2024);
const VIEW_BACKGROUND = new THREE.Color(0x272b31);

/**
 * Whether WebGL runs in software (SwiftShader, llvmpipe): then the views are drawn without
 * multisampling, which costs four times the fill there. Asked once, on a throwaway context.
 */
export const softwareRenderer = (() => {
  try {
    const gl = document.createElement("canvas").getContext("webgl2");
    if (!gl) return false;
    const info = gl.getExtension("WEBGL_debug_renderer_info");
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    gl.getExtension("WEBGL_lose_context")?.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  } catch {
    return false;
  }
})();

/**
 * One renderer on one canvas, drawing every view whose element is on screen. The drawing
 * buffer is preserved, so a change to one view (a plant arrived, the mouse orbits it) redraws
 * that view alone; a resize or a moved element redraws them all.
 */
export class Stage {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({
      canvas,
      antialias: !softwareRenderer,
      alpha: false,
      preserveDrawingBuffer: true,
      powerPreference: "high-performance",
    });
    this.renderer.outputColorSpace = THREE.SRGBColorSpace;
    this.renderer.toneMapping = THREE.NoToneMapping;
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.autoClear = false;
    this.views = [];
    this.frame = 0;
    this.waiters = [];
    this.renders = 0;
    this.lastRenderMs = 0;
    this.dirty = new Set();
    this.allDirty = true;
    this.lost = false;
    canvas.addEventListener("webglcontextlost", (e) => {
      e.preventDefault();
      this.lost = true;
    });
    canvas.addEventListener("webglcontextrestored", () => {
      this.lost = false;
      this.requestRender();
    });
    new ResizeObserver(() => this.requestRender()).observe(canvas);
  }

  /** A view drawn in `element`'s rectangle (which must lie over this stage's canvas). */
  addView(element, options) {
    const view = new View(this, element, options);
    this.views.push(view);
    this.requestRender();
    return view;
  }

  removeView(view) {
    this.views = this.views.filter((v) => v !== view);
    view.dispose();
    this.requestRender();
  }

  /** Draws `view` (or every view) at the next animation frame, however often it is asked. */
  requestRender(view) {
    if (view) this.dirty.add(view);
    else this.allDirty = true;
    this.schedule();
  }

  schedule() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.render();
    });
  }

  /**
   * Resolves once what is asked to be drawn now has been drawn and the GPU has finished it
   * (a fence, polled without blocking), so the pixels can be on screen.
   */
  nextPaint() {
    return new Promise((resolve) => {
      this.waiters.push(resolve);
      this.schedule();
    });
  }

  /** Draws the views that changed (all of them after a resize) now. */
  render() {
    if (this.lost) return;
    const started = performance.now();
    const canvas = this.canvas;
    const width = canvas.clientWidth;
    const height = canvas.clientHeight;
    if (width === 0 || height === 0) {
      this.flushWaiters();
      return;
    }
    const r = this.renderer;
    const size = r.getSize(new THREE.Vector2());
    if (size.x !== width || size.y !== height) {
      r.setSize(width, height, false);
      this.allDirty = true;
    }
    const box = canvas.getBoundingClientRect();
    const rects = new Map();
    for (const view of this.views) {
      const rect = view.element.getBoundingClientRect();
      const key = `${rect.left - box.left},${rect.top - box.top},${rect.width},${rect.height}`;
      if (key !== view.lastRect) {
        view.lastRect = key;
        this.allDirty = true;
      }
      rects.set(view, rect);
    }
    const all = this.allDirty;
    const todo = all ? this.views : this.views.filter((v) => this.dirty.has(v));
    this.allDirty = false;
    this.dirty.clear();
    if (all) {
      r.setScissorTest(false);
      r.setClearColor(BACKGROUND, 1);
      r.clear();
    }
    r.setScissorTest(true);
    for (const view of todo) {
      const rect = rects.get(view);
      if (rect.width < 1 || rect.height < 1) continue;
      if (rect.bottom < box.top || rect.top > box.bottom) continue;
      if (rect.right < box.left || rect.left > box.right) continue;
      const left = rect.left - box.left;
      const bottom = box.bottom - rect.bottom;
      r.setViewport(left, bottom, rect.width, rect.height);
      r.setScissor(left, bottom, rect.width, rect.height);
      view.camera.aspect = rect.width / rect.height;
      view.camera.updateProjectionMatrix();
      r.setClearColor(view.background, 1);
      r.clear();
      r.render(view.scene, view.camera);
    }
    r.setScissorTest(false);
    this.renders += 1;
    this.lastRenderMs = performance.now() - started;
    this.flushWaiters();
  }

  flushWaiters() {
    const waiters = this.waiters;
    this.waiters = [];
    if (waiters.length === 0) return;
    gpuDone(this.renderer.getContext()).then(() => {
      for (const w of waiters) w();
    });
  }

  /**
   * For tests: draws now (without the ground discs) and reads the pixels back in the same task
   * (the drawing buffer is still there), returning how many differ from the backgrounds, in
   * all and per view.
   */
  probe() {
    // the ground discs are left out so that only plants (and guides) count
    const grounds = this.views.map((v) => v.ground).filter((g) => g && g.visible);
    for (const g of grounds) g.visible = false;
    this.allDirty = true;
    this.render();
    const gl = this.renderer.getContext();
    const w = gl.drawingBufferWidth;
    const h = gl.drawingBufferHeight;
    const pixels = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    for (const g of grounds) g.visible = true;
    this.requestRender();
    const backgrounds = [BACKGROUND, VIEW_BACKGROUND, ...this.views.map((v) => v.background)].map(
      (c) => {
        const s = c.clone().convertLinearToSRGB();
        return [s.r * 255, s.g * 255, s.b * 255];
      },
    );
    let other = 0;
    const colors = new Set();
    const mask = new Uint8Array(w * h);
    for (let i = 0, j = 0; i < pixels.length; i += 4, j++) {
      const p = [pixels[i], pixels[i + 1], pixels[i + 2]];
      const isBg = backgrounds.some(
        (b) => Math.abs(b[0] - p[0]) + Math.abs(b[1] - p[1]) + Math.abs(b[2] - p[2]) <= 6,
      );
      if (!isBg) {
        other += 1;
        mask[j] = 1;
        if (colors.size < 4096) colors.add((p[0] << 16) | (p[1] << 8) | p[2]);
      }
    }
    // the share of each view's rectangle that is not background (rows are bottom-up)
    const box = this.canvas.getBoundingClientRect();
    const pr = w / Math.max(box.width, 1);
    const views = this.views.map((view) => {
      const r = view.element.getBoundingClientRect();
      const x0 = Math.max(0, Math.floor((r.left - box.left) * pr));
      const x1 = Math.min(w, Math.floor((r.right - box.left) * pr));
      const y0 = Math.max(0, Math.floor((box.bottom - r.bottom) * pr));
      const y1 = Math.min(h, Math.floor((box.bottom - r.top) * pr));
      let n = 0;
      for (let y = y0; y < y1; y++) for (let x = x0; x < x1; x++) n += mask[y * w + x];
      const area = Math.max((x1 - x0) * (y1 - y0), 1);
      return { nonBackground: n, fraction: n / area, plant: view.plantId };
    });
    return { width: w, height: h, nonBackground: other, fraction: other / (w * h), colors: colors.size, views };
  }
}

/** Resolves when the GPU has done every command issued so far (WebGL2 fence, polled). */
function gpuDone(gl) {
  if (!gl.fenceSync) return Promise.resolve();
  const sync = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
  if (!sync) return Promise.resolve();
  gl.flush();
  const started = performance.now();
  return new Promise((resolve) => {
    const poll = () => {
      const status = gl.getSyncParameter(sync, gl.SYNC_STATUS);
      if (status === gl.SIGNALED || gl.isContextLost() || performance.now() - started > 120000) {
        gl.deleteSync(sync);
        resolve();
      } else setTimeout(poll, 4);
    };
    poll();
  });
}

const ISO = new THREE.Vector3(1, 0.55, 1.35).normalize();

/** A scene, a camera and orbit controls drawn in one element's rectangle. */
export class View {
  constructor(stage, element, { ground = true, background = VIEW_BACKGROUND } = {}) {
    this.stage = stage;
    this.element = element;
    this.background = background;
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
    this.camera.position.set(4, 3, 6);
    this.content = new THREE.Group();
    this.helpers = new THREE.Group();
    this.scene.add(this.content, this.helpers);

    const hemi = new THREE.HemisphereLight(0xe8f0ff, 0x4a3f33, 1.6);
    const sun = new THREE.DirectionalLight(0xfff4e0, 2.2);
    sun.position.set(3, 6, 2);
    const fill = new THREE.DirectionalLight(0xc8d8ff, 0.5);
    fill.position.set(-4, 2, -3);
    this.scene.add(hemi, sun, fill);

    if (ground) {
      this.ground = new THREE.Mesh(
        new THREE.CircleGeometry(1, 72),
        // translucent, so that what hangs below the ground still shows, dimmed
        new THREE.MeshStandardMaterial({
          color: 0x3f4339,
          roughness: 1,
          metalness: 0,
          transparent: true,
          opacity: 0.7,
          depthWrite: false,
        }),
      );
      this.ground.rotation.x = -Math.PI / 2;
      this.ground.renderOrder = -1;
      this.scene.add(this.ground);
    }

    this.controls = new OrbitControls(this.camera, element);
    this.controls.enableDamping = false;
    this.controls.zoomToCursor = false;
    this.onChange = () => stage.requestRender(this);
    this.controls.addEventListener("change", this.onChange);
    this.plantId = null;
  }

  /** Replaces the content with `object` (or nothing) and frames it unless `frame` is false. */
  setContent(object, { frame = true, plantId = null } = {}) {
    for (const child of [...this.content.children]) this.content.remove(child);
    if (this.plantId !== null) release(this.plantId);
    this.plantId = plantId;
    if (object) this.content.add(object);
    if (this.ground) this.ground.visible = !!object;
    if (frame) this.frame();
    this.stage.requestRender(this);
  }

  /**
   * Points the camera at the content and helpers, seen from the front-right and a little
   * above, as close as keeps every corner of their bounding box in view.
   */
  frame() {
    const box = new THREE.Box3();
    box.expandByObject(this.content);
    for (const h of this.helpers.children) if (h.userData.frame !== false) box.expandByObject(h);
    if (box.isEmpty()) box.set(new THREE.Vector3(-1, 0, -1), new THREE.Vector3(1, 2, 1));
    const size = box.getSize(new THREE.Vector3());
    const radius = Math.max(size.length() / 2, 0.05);
    if (this.ground) {
      const r = Math.max(size.x, size.z) * 0.62 + radius * 0.08;
      this.ground.scale.setScalar(Math.max(r, 0.1));
      const center = box.getCenter(new THREE.Vector3());
      // plants grow from the origin: the ground is at y = 0 (or under a plant set higher)
      this.ground.position.set(center.x, Math.max(0, box.min.y) - radius * 0.002, center.z);
    }
    const rect = this.element.getBoundingClientRect();
    const aspect = rect.width > 0 && rect.height > 0 ? rect.width / rect.height : 1;
    const tanV = Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2);
    const tanH = tanV * aspect;
    // camera axes for a view along -ISO
    const forward = ISO.clone().negate();
    const right = new THREE.Vector3().crossVectors(forward, new THREE.Vector3(0, 1, 0)).normalize();
    const up = new THREE.Vector3().crossVectors(right, forward).normalize();
    // aim at the middle of the box's extent across the view, then back off until it all fits
    const corners = [];
    for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) corners.push(new THREE.Vector3(x, y, z));
    const along = (v) => corners.map((c) => c.dot(v));
    const span = (v) => {
      const d = along(v);
      return [Math.min(...d), Math.max(...d)];
    };
    const [r0, r1] = span(right);
    const [u0, u1] = span(up);
    const center = right.clone().multiplyScalar((r0 + r1) / 2)
      .add(up.clone().multiplyScalar((u0 + u1) / 2))
      .add(forward.clone().multiplyScalar(along(forward).reduce((a, b) => a + b, 0) / 8));
    let distance = 0;
    for (const c of corners) {
      const d = c.clone().sub(center);
      const depth = d.dot(forward); // ahead of the aim point
      distance = Math.max(distance,
        Math.abs(d.dot(right)) / tanH - depth,
        Math.abs(d.dot(up)) / tanV - depth);
    }
    distance = Math.max(distance * 1.06, radius * 0.2);
    this.controls.target.copy(center);
    this.camera.position.copy(center).addScaledVector(ISO, distance);
    this.camera.near = Math.max(distance / 1000, 0.001);
    this.camera.far = distance * 20 + radius * 4;
    this.camera.updateProjectionMatrix();
    this.controls.minDistance = radius * 0.02;
    this.controls.maxDistance = distance * 10;
    this.controls.update();
    this.stage.requestRender(this);
  }

  /** Draws this view again at the next frame. */
  redraw() {
    this.stage.requestRender(this);
  }

  dispose() {
    this.controls.removeEventListener("change", this.onChange);
    this.controls.dispose();
    if (this.plantId !== null) release(this.plantId);
  }
}

// ---------------------------------------------------------------------------------------------
// GLB loading. Plants never change once archived, so each plant's scene is parsed once and
// handed out as clones (sharing geometry and materials).

const loader = new GLTFLoader();
const cache = new Map(); // id -> Promise<THREE.Object3D>
const inUse = new Map(); // id -> count of views showing it
const CACHE_LIMIT = 18; // random PlantMaker plants are 10 to 40 MB of mesh each
/** Per plant: bytes, fetch and parse times (for the test's report). */
export const timings = [];

/** Parses GLB bytes into a scene graph. */
export async function parseGlb(bytes) {
  const gltf = await loader.parseAsync(bytes, "");
  const scene = gltf.scene;
  return scene;
}

/** Fetches and parses any GLB (not cached; for gardens, which change). */
export async function loadGlb(url) {
  const bytes = await getBytes(url, { cache: "no-store" });
  return parseGlb(bytes);
}

/** A clone of plant `id`'s grown scene (roots left out), fetched and parsed once. */
export async function loadPlant(id) {
  let p = cache.get(id);
  if (p) {
    cache.delete(id);
    cache.set(id, p);
  } else {
    p = (async () => {
      const t0 = performance.now();
      const bytes = await getBytes(`/api/plants/${encodeURIComponent(id)}/plant.glb`);
      const t1 = performance.now();
      const scene = await parseGlb(bytes);
      timings.push({ plant: id, bytes: bytes.byteLength, fetchMs: t1 - t0, parseMs: performance.now() - t1 });
      if (timings.length > 200) timings.shift();
      return scene;
    })();
    p.catch(() => cache.delete(id));
    cache.set(id, p);
    evict();
  }
  const scene = await p;
  inUse.set(id, (inUse.get(id) || 0) + 1);
  return scene.clone(true);
}

function release(id) {
  const n = (inUse.get(id) || 0) - 1;
  if (n <= 0) inUse.delete(id);
  else inUse.set(id, n);
}

function evict() {
  for (const [id, p] of cache) {
    if (cache.size <= CACHE_LIMIT) break;
    if (inUse.has(id)) continue;
    cache.delete(id);
    p.then(disposeObject, () => {});
  }
}

/** Frees the GPU resources of an object's meshes. */
export function disposeObject(object) {
  object.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    const materials = Array.isArray(o.material) ? o.material : o.material ? [o.material] : [];
    for (const m of materials) {
      for (const v of Object.values(m)) if (v && v.isTexture) v.dispose();
      m.dispose();
    }
  });
}
