// 3D views. A Stage is one WebGLRenderer on one canvas; it draws any number of Views, each the
// rectangle of an ordinary element (three.js's "multiple elements" pattern: a scissor and a
// viewport per element), so the nine plants of the Breed grid share one WebGL context.
// Nothing renders in a loop: a stage draws when asked (a plant arrived, a control moved, the
// page resized, a turntable turned) and then tells whoever waits for the paint.
//
// The look follows Sylva's own renderer (the sylva-render crate): a pale sky, a soft
// checkered ground that fades out at its rim, a hemisphere light, a warm sun from the upper
// front-left and a cool fill from the right, the plant filling its view. The sun casts soft
// shadows in detail views (garden, family, design); grid cells have a contact shadow.

import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { getBytes } from "./api.js";

export { THREE };

/** The canvas between views. */
export const BACKGROUND = new THREE.Color(0x1d2024);
/** A view's flat colour where it has no sky: in the probe pass, which counts what differs. */
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
 * Texture anisotropy (clamped to what the GPU has), for bark, leaves and ground seen at a
 * slant; software WebGL filters every extra sample on the CPU, so there plain trilinear
 * mipmaps do.
 */
const ANISOTROPY = softwareRenderer ? 1 : 4;

/** A texture drawn once on a small canvas by `draw(context, width, height)`. */
function canvasTexture(width, height, draw, colorSpace = THREE.NoColorSpace) {
  const canvas = document.createElement("canvas");
  canvas.width = width;
  canvas.height = height;
  draw(canvas.getContext("2d"), width, height);
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = colorSpace;
  return texture;
}

// Sylva's renderer draws a flat sky of sRGB (221, 232, 242); the views grade it from a
// clearer blue overhead to that pale tone and near white at the horizon. sRGB textures are
// not tone mapped, so the sky keeps these exact colours. Shared by every view.
const SKY = canvasTexture(1, 256, (g, w, h) => {
  const grad = g.createLinearGradient(0, 0, 0, h);
  grad.addColorStop(0, "#a7c6e5");
  grad.addColorStop(0.6, "#dde8f2");
  grad.addColorStop(1, "#f3f6f9");
  g.fillStyle = grad;
  g.fillRect(0, 0, w, h);
}, THREE.SRGBColorSpace);
SKY.generateMipmaps = false;
SKY.minFilter = THREE.LinearFilter;

// The ground: the renderer's two checker tones, squares of a round size in metres (so the
// ground doubles as a scale), in a disc that fades out from GROUND_SOLID of its radius to the
// rim.
/** Where the ground starts to fade, as a share of its radius. */
const GROUND_SOLID = 0.7;
const CHECKER = canvasTexture(64, 64, (g) => {
  g.fillStyle = "rgb(196, 201, 171)";
  g.fillRect(0, 0, 64, 64);
  g.fillStyle = "rgb(184, 191, 159)";
  g.fillRect(0, 0, 32, 32);
  g.fillRect(32, 32, 32, 32);
}, THREE.SRGBColorSpace);
CHECKER.wrapS = CHECKER.wrapT = THREE.RepeatWrapping;
CHECKER.anisotropy = ANISOTROPY;

/** A disc for an alphaMap: `alpha(d)`, 0 to 1, at distance d from the centre (1 at the rim). */
function radialAlpha(size, alpha) {
  return canvasTexture(size, size, (g) => {
    const image = g.createImageData(size, size);
    for (let y = 0; y < size; y++) {
      for (let x = 0; x < size; x++) {
        const d = Math.min(Math.hypot(((x + 0.5) / size) * 2 - 1, ((y + 0.5) / size) * 2 - 1), 1);
        const a = 255 * alpha(d);
        image.data.set([a, a, a, 255], (y * size + x) * 4);
      }
    }
    g.putImageData(image, 0, 0);
  });
}
const GROUND_FADE = radialAlpha(128, (d) => 1 - THREE.MathUtils.smoothstep(d, GROUND_SOLID, 1));
/** A grid cell's contact shadow: a soft dark blob. */
const CONTACT_SHADOW = radialAlpha(64, (d) => (1 - d * d) ** 2);

// Lights as in Sylva's renderer (its linear colours, times π: three.js divides diffuse light
// by π where the renderer does not), so a plant's colours come out as in its pictures.
const linear = (r, g, b) => new THREE.Color().setRGB(r, g, b, THREE.LinearSRGBColorSpace);
const SKY_LIGHT = linear(0.72, 0.84, 1.0);
const BOUNCE_LIGHT = linear(0.48, 0.4, 0.3);
const AMBIENT_INTENSITY = 0.425 * Math.PI;
const SUN_LIGHT = linear(1.0, 0.95, 0.85);
const SUN_INTENSITY = 1.05 * Math.PI;
const FILL_LIGHT = linear(0.73, 0.82, 1.0);
const FILL_INTENSITY = 0.255 * Math.PI;
const SUN_ELEVATION = THREE.MathUtils.degToRad(50);
/** Shadow map side in texels: soft shadows need few, and software WebGL pays for each. */
const SHADOW_MAP = 1024;

/** One full turn of the turntable, in seconds. */
const TURNTABLE_SECONDS = 24;

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
    const r = this.renderer;
    r.outputColorSpace = THREE.SRGBColorSpace;
    // Khronos' neutral tone mapping leaves colours as they are up to about 0.8 and rolls off
    // only the highlights (leaves facing the sun), so greens stay the renderer's greens; side
    // by side with its pictures, ACES lightens and yellows them and AgX greys them.
    r.toneMapping = THREE.NeutralToneMapping;
    r.shadowMap.enabled = true;
    r.shadowMap.type = THREE.PCFShadowMap; // soft through each sun's shadow.radius
    r.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    r.autoClear = false;
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
      for (const view of this.views) view.sun.shadow.needsUpdate = true;
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
      const shown = rect.width >= 1 && rect.height >= 1 &&
        rect.bottom >= box.top && rect.top <= box.bottom &&
        rect.right >= box.left && rect.left <= box.right;
      if (shown) rects.set(view, rect);
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
      if (!rect) continue;
      const left = rect.left - box.left;
      const bottom = box.bottom - rect.bottom;
      r.setViewport(left, bottom, rect.width, rect.height);
      r.setScissor(left, bottom, rect.width, rect.height);
      view.camera.aspect = rect.width / rect.height;
      view.camera.updateProjectionMatrix();
      if (view.scene.background) {
        r.clearDepth(); // the sky covers every pixel
      } else {
        r.setClearColor(view.background, 1);
        r.clear();
      }
      r.render(view.scene, view.camera);
    }
    r.setScissorTest(false);
    this.renders += 1;
    this.lastRenderMs = performance.now() - started;
    // turntables turn only while their view is on screen: a hidden one asks for no frames
    for (const view of this.views) view.turn(rects.has(view), started);
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
   * For tests: draws now, without the sky and the ground discs, on flat backgrounds, and
   * reads the pixels back in the same task (the drawing buffer is still there), returning how
   * many differ from the backgrounds, in all and per view: plants (and guides) alone count.
   */
  probe() {
    const saved = this.views.map((v) => ({ view: v, sky: v.scene.background, ground: v.ground?.visible }));
    for (const { view } of saved) {
      view.scene.background = null;
      if (view.ground) view.ground.visible = false;
    }
    this.allDirty = true;
    this.render();
    const gl = this.renderer.getContext();
    const w = gl.drawingBufferWidth;
    const h = gl.drawingBufferHeight;
    const pixels = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    for (const { view, sky, ground } of saved) {
      view.scene.background = sky;
      if (view.ground) view.ground.visible = ground;
    }
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

/** From the target towards the camera: front-right, 22° above the horizon (lower than the
 * renderer's 30°, so a tall plant fills more of a wide cell). */
const ISO = new THREE.Vector3().setFromSphericalCoords(1, THREE.MathUtils.degToRad(90 - 22), THREE.MathUtils.degToRad(36.5));
const UP = new THREE.Vector3(0, 1, 0);
/** The share of the view's height (or width) the framed content spans. */
const FILL = 0.92;

/**
 * A scene, a camera and orbit controls drawn in one element's rectangle. A `detail` view has
 * its stage to itself (a garden, a family member, a design): its sun casts soft shadows, and
 * a button in it turns the turntable on. Grid cells (the default) have a soft contact shadow
 * under the plant instead: each new plant would redraw its cell's shadow map, and software
 * WebGL pays for every shadowed pixel of nine views.
 */
export class View {
  constructor(stage, element, { ground = true, background = VIEW_BACKGROUND, detail = false } = {}) {
    this.stage = stage;
    this.element = element;
    this.background = background;
    this.scene = new THREE.Scene();
    this.scene.background = SKY;
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
    this.camera.position.set(4, 3, 6);
    this.content = new THREE.Group();
    this.helpers = new THREE.Group();
    this.scene.add(this.content, this.helpers);

    this.scene.add(new THREE.HemisphereLight(SKY_LIGHT, BOUNCE_LIGHT, AMBIENT_INTENSITY));
    // The sun is placed (and its shadow camera fitted) when content arrives, from the
    // camera's side; it then stays put, so orbiting needs no new shadow map.
    this.sun = new THREE.DirectionalLight(SUN_LIGHT, SUN_INTENSITY);
    this.sun.castShadow = detail;
    const shadow = this.sun.shadow;
    shadow.mapSize.set(SHADOW_MAP, SHADOW_MAP);
    shadow.radius = 3; // texels the PCF taps spread over: a soft edge
    shadow.autoUpdate = false;
    shadow.needsUpdate = true;
    this.fill = new THREE.DirectionalLight(FILL_LIGHT, FILL_INTENSITY);
    this.scene.add(this.sun, this.sun.target, this.fill, this.fill.target);

    if (ground) {
      const map = CHECKER.clone(); // shares the image; its repeat is this view's
      this.ground = new THREE.Mesh(
        new THREE.CircleGeometry(1, 96),
        new THREE.MeshLambertMaterial({
          map,
          alphaMap: GROUND_FADE,
          transparent: true,
          // a little translucent, so that what hangs below the ground still shows, dimmed
          opacity: 0.9,
          depthWrite: false,
        }),
      );
      this.ground.rotation.x = -Math.PI / 2;
      this.ground.renderOrder = -1;
      this.ground.receiveShadow = true;
      this.ground.visible = false;
      this.scene.add(this.ground);
      if (!detail) {
        this.contactShadow = new THREE.Mesh(
          new THREE.CircleGeometry(1, 48),
          new THREE.MeshBasicMaterial({ color: 0x000000, alphaMap: CONTACT_SHADOW, transparent: true, opacity: 0.3, depthWrite: false }),
        );
        this.contactShadow.position.z = 1e-3; // in the ground's frame: just above it
        this.contactShadow.renderOrder = -0.5;
        this.ground.add(this.contactShadow);
      }
    }

    this.controls = new OrbitControls(this.camera, element);
    this.controls.enableDamping = false;
    this.controls.zoomToCursor = false;
    this.controls.autoRotateSpeed = 60 / TURNTABLE_SECONDS;
    this.onChange = () => stage.requestRender(this);
    this.controls.addEventListener("change", this.onChange);
    this.plantId = null;
    this.cacheKey = null;
    this.turntable = false;
    this.lastTurn = null;
    if (detail) this.addTurntableToggle();
  }

  /** Replaces the content with `object` (or nothing) and frames it unless `frame` is false. */
  setContent(object, { frame = true, plantId = null } = {}) {
    for (const child of [...this.content.children]) this.content.remove(child);
    if (this.cacheKey !== null) release(this.cacheKey);
    this.cacheKey = object?.userData?.cacheKey ?? null;
    this.plantId = plantId;
    if (object) {
      object.traverse((o) => {
        if (o.isMesh) o.castShadow = o.receiveShadow = this.sun.castShadow;
      });
      this.content.add(object);
    }
    if (this.ground) this.ground.visible = !!object;
    this.placeGround();
    if (frame) this.frame();
    else this.placeSun();
    this.stage.requestRender(this);
  }

  /**
   * The content's box (what casts shadows), and the place and radius of the ground under it
   * and the framed helpers (a garden's rings, a design's target): null when there is no
   * content.
   */
  groundUnder() {
    const casters = new THREE.Box3().setFromObject(this.content);
    if (casters.isEmpty()) return null;
    const box = casters.clone();
    for (const h of this.helpers.children) if (h.userData.frame !== false) box.expandByObject(h);
    const size = box.getSize(new THREE.Vector3());
    const center = box.getCenter(new THREE.Vector3());
    // as Sylva's renderer: 1.2 times the wider horizontal extent across, and at least 0.6
    // times the height, so a lone stem still stands on something; at y = 0, where plants
    // grow from (or under a plant set higher)
    const radius = Math.max(0.6 * Math.max(size.x, size.z), 0.3 * size.y, 1e-3);
    return { casters, center, radius, y: Math.max(0, casters.min.y) };
  }

  /** Sizes the ground disc to the content and the framed helpers. */
  placeGround() {
    const under = this.groundUnder();
    if (!this.ground || !under) return;
    const { casters, center, radius, y } = under;
    this.ground.scale.setScalar(radius);
    this.ground.position.set(center.x, y - radius * 1e-3, center.z);
    if (this.contactShadow) {
      // under the plant's foot (plants grow from the origin), its radius 0.3 of the crown's width
      const size = casters.getSize(new THREE.Vector3());
      const foot = casters.min.x <= 0 && casters.max.x >= 0 && casters.min.z <= 0 && casters.max.z >= 0
        ? new THREE.Vector3(0, 0, 0) : center;
      this.contactShadow.scale.setScalar(Math.max(0.3 * Math.max(size.x, size.z), 0.05 * size.y) / radius);
      this.contactShadow.position.x = (foot.x - center.x) / radius;
      this.contactShadow.position.y = -(foot.z - center.z) / radius;
    }
    const square = niceStep(radius / 4);
    const map = this.ground.material.map;
    // the disc's uv runs 0..1 across its diameter; squares line up with the world's metres
    map.repeat.setScalar(radius / square);
    map.offset.set((center.x - radius) / (2 * square), (-center.z - radius) / (2 * square));
  }

  /**
   * Places the sun above the upper front-left of the picture (the renderer's key light, 50°
   * up) and the fill on the right, and fits the sun's shadow camera (if it casts shadows) to
   * what casts (the content) and what receives (the ground).
   */
  placeSun() {
    const under = this.groundUnder();
    if (!under) return;
    const { casters, center, radius, y: groundY } = under;
    const toward = new THREE.Vector3().subVectors(this.camera.position, this.controls.target).setY(0);
    if (toward.lengthSq() < 1e-12) toward.set(ISO.x, 0, ISO.z);
    toward.normalize();
    const right = new THREE.Vector3().crossVectors(UP, toward).normalize();
    const toSun = right.clone().multiplyScalar(-0.55).addScaledVector(toward, 0.6).normalize()
      .multiplyScalar(Math.cos(SUN_ELEVATION)).addScaledVector(UP, Math.sin(SUN_ELEVATION));
    const toFill = right.clone().multiplyScalar(0.85).addScaledVector(UP, 0.25).addScaledVector(toward, 0.45).normalize();
    // Seen from the sun, a shadow on the ground lies within the casters' outline, so the
    // shadow camera spans that across; along its axis it reaches the ground's rim too, so
    // that the long shadow of a tall plant is not cut off.
    const corners = boxCorners(casters);
    const rim = [];
    for (let i = 0; i < 16; i++) {
      const a = (i / 16) * Math.PI * 2;
      rim.push(new THREE.Vector3(center.x + Math.cos(a) * radius, groundY, center.z + Math.sin(a) * radius));
    }
    const reach = [...corners, ...rim].reduce((m, p) => Math.max(m, p.distanceTo(center)), 0);
    this.sun.position.copy(center).addScaledVector(toSun, reach * 2);
    this.sun.target.position.copy(center);
    this.fill.position.copy(center).addScaledVector(toFill, reach * 2);
    this.fill.target.position.copy(center);
    if (!this.sun.castShadow) return;
    // the shadow camera looks from the sun at the centre, x = up × toward-sun as three.js does
    const sx = new THREE.Vector3().crossVectors(UP, toSun).normalize();
    const sy = new THREE.Vector3().crossVectors(toSun, sx);
    let [x0, x1, y0, y1, z0, z1] = [Infinity, -Infinity, Infinity, -Infinity, Infinity, -Infinity];
    const d = new THREE.Vector3();
    for (const p of corners) {
      d.subVectors(p, this.sun.position);
      x0 = Math.min(x0, d.dot(sx));
      x1 = Math.max(x1, d.dot(sx));
      y0 = Math.min(y0, d.dot(sy));
      y1 = Math.max(y1, d.dot(sy));
    }
    for (const p of [...corners, ...rim]) {
      const depth = -d.subVectors(p, this.sun.position).dot(toSun);
      z0 = Math.min(z0, depth);
      z1 = Math.max(z1, depth);
    }
    const shadow = this.sun.shadow;
    const pad = reach * 0.02;
    Object.assign(shadow.camera, { left: x0 - pad, right: x1 + pad, bottom: y0 - pad, top: y1 + pad, near: Math.max(z0 - pad, 1e-4), far: z1 + pad });
    shadow.camera.updateProjectionMatrix();
    // thin leaves shade themselves: push the lookup off the surface by about a texel
    shadow.normalBias = (Math.max(x1 - x0, y1 - y0) / SHADOW_MAP) * 1.5;
    shadow.bias = -0.0005;
    shadow.needsUpdate = true;
  }

  /**
   * Points the camera at the content and helpers, seen from the front-right and a little
   * above, as close as keeps every point of them inside the middle FILL of the view (with the
   * ground's solid part, so the plant stands on something).
   */
  frame() {
    const rect = this.element.getBoundingClientRect();
    const aspect = rect.width > 0 && rect.height > 0 ? rect.width / rect.height : 1;
    const tanV = Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2) * FILL;
    const tanH = tanV * aspect;
    // camera axes for a view along -ISO
    const forward = ISO.clone().negate();
    const right = new THREE.Vector3().crossVectors(forward, UP).normalize();
    const up = new THREE.Vector3().crossVectors(right, forward).normalize();
    const points = this.framePoints(right, up, forward, Math.max(tanH, tanV));
    if (points.length === 0) {
      const empty = new THREE.Box3(new THREE.Vector3(-1, 0, -1), new THREE.Vector3(1, 2, 1));
      points.push(...boxCorners(empty));
    }
    const bounds = new THREE.Box3().setFromPoints(points);
    const radius = Math.max(bounds.getSize(new THREE.Vector3()).length() / 2, 0.05);
    // Start aimed at the middle of the points' extent across the view, then (perspective
    // makes near points look bigger) recentre on where they fall in the picture, a few times.
    let [r0, r1, u0, u1] = [Infinity, -Infinity, Infinity, -Infinity];
    for (const p of points) {
      const x = p.dot(right);
      const y = p.dot(up);
      r0 = Math.min(r0, x);
      r1 = Math.max(r1, x);
      u0 = Math.min(u0, y);
      u1 = Math.max(u1, y);
    }
    const aim = right.clone().multiplyScalar((r0 + r1) / 2)
      .addScaledVector(up, (u0 + u1) / 2)
      .addScaledVector(forward, bounds.getCenter(new THREE.Vector3()).dot(forward));
    const d = new THREE.Vector3();
    // the least distance from `aim` that keeps every point in view
    const fitDistance = () => {
      let distance = 0;
      for (const p of points) {
        d.subVectors(p, aim);
        const depth = d.dot(forward);
        distance = Math.max(distance, Math.abs(d.dot(right)) / tanH - depth, Math.abs(d.dot(up)) / tanV - depth);
      }
      return distance;
    };
    let distance = fitDistance();
    for (let i = 0; i < 4; i++) {
      let [x0, x1, y0, y1] = [Infinity, -Infinity, Infinity, -Infinity];
      for (const p of points) {
        d.subVectors(p, aim);
        const z = Math.max(distance + d.dot(forward), 1e-9);
        const x = d.dot(right) / z;
        const y = d.dot(up) / z;
        x0 = Math.min(x0, x);
        x1 = Math.max(x1, x);
        y0 = Math.min(y0, y);
        y1 = Math.max(y1, y);
      }
      aim.addScaledVector(right, ((x0 + x1) / 2) * distance).addScaledVector(up, ((y0 + y1) / 2) * distance);
      distance = fitDistance();
    }
    distance = Math.max(distance, radius * 0.2);
    this.controls.target.copy(aim);
    this.camera.position.copy(aim).addScaledVector(ISO, distance);
    this.camera.near = Math.max(distance / 1000, 0.001);
    this.camera.far = distance * 20 + radius * 4;
    this.camera.updateProjectionMatrix();
    this.controls.minDistance = radius * 0.02;
    this.controls.maxDistance = distance * 10;
    this.controls.update();
    this.placeSun();
    this.stage.requestRender(this);
  }

  /**
   * The points that decide the framing: of the content's and helpers' vertices, those
   * farthest out in the picture, and the rim of the ground's solid part. Seen from a distance
   * D, a point d (from the aim) lies at x = d·right / (D + d·forward) across the picture; the
   * point with the largest x is the one farthest along right − x·forward. So the extremes
   * along ±right and ±up, each tilted back by a few slopes up to `slope`, the widest the
   * view shows, are all the frame needs (one pass over every vertex, however many).
   */
  framePoints(right, up, forward, slope) {
    const tilts = [0, 1 / 3, 2 / 3, 1].map((t) => t * slope);
    const n = tilts.length * 4;
    const scores = new Float64Array(n).fill(-Infinity);
    const where = new Float64Array(n * 3);
    this.scene.updateMatrixWorld(true);
    const objects = [];
    this.content.traverse((o) => objects.push(o));
    for (const h of this.helpers.children) if (h.userData.frame !== false) h.traverse((o) => objects.push(o));
    const world = new THREE.Matrix4();
    const instance = new THREE.Matrix4();
    const v = new THREE.Vector3();
    for (const o of objects) {
      const position = o.geometry?.attributes?.position;
      if (!position || !o.visible) continue;
      for (let k = 0; k < (o.isInstancedMesh ? o.count : 1); k++) {
        world.copy(o.matrixWorld);
        if (o.isInstancedMesh) world.multiply(o.getMatrixAt(k, instance));
        // a vertex's place across (a), up (b) and along (c) the view, straight from its
        // local coordinates: one affine map per object, not a matrix product per vertex
        const e = world.elements;
        const row = (axis) => [0, 1, 2, 3].map((j) => axis.x * e[4 * j] + axis.y * e[4 * j + 1] + axis.z * e[4 * j + 2]);
        const [ra, rb, rc] = [row(right), row(up), row(forward)];
        const plain = !position.isInterleavedBufferAttribute && !position.normalized;
        const array = position.array;
        for (let i = 0; i < position.count; i++) {
          const x = plain ? array[3 * i] : position.getX(i);
          const y = plain ? array[3 * i + 1] : position.getY(i);
          const z = plain ? array[3 * i + 2] : position.getZ(i);
          const a = ra[0] * x + ra[1] * y + ra[2] * z + ra[3];
          const b = rb[0] * x + rb[1] * y + rb[2] * z + rb[3];
          const c = rc[0] * x + rc[1] * y + rc[2] * z + rc[3];
          for (let t = 0; t < tilts.length; t++) {
            const back = tilts[t] * c;
            const candidates = 4 * t;
            for (let q = 0; q < 4; q++) {
              const score = (q === 0 ? a : q === 1 ? -a : q === 2 ? b : -b) - back;
              if (score > scores[candidates + q]) {
                scores[candidates + q] = score;
                v.set(x, y, z).applyMatrix4(world).toArray(where, 3 * (candidates + q));
              }
            }
          }
        }
      }
    }
    const points = [];
    for (let j = 0; j < n; j++) {
      if (scores[j] > -Infinity) points.push(new THREE.Vector3(where[3 * j], where[3 * j + 1], where[3 * j + 2]));
    }
    if (this.ground?.visible) {
      const g = this.ground;
      for (let i = 0; i < 24; i++) {
        const a = (i / 24) * Math.PI * 2;
        points.push(new THREE.Vector3(
          g.position.x + Math.cos(a) * g.scale.x * GROUND_SOLID,
          g.position.y,
          g.position.z + Math.sin(a) * g.scale.x * GROUND_SOLID,
        ));
      }
    }
    return points;
  }

  /** Turns the view slowly about its target (orbit controls' auto-rotation), or stops it. */
  setTurntable(on) {
    this.turntable = on;
    this.controls.autoRotate = on;
    this.lastTurn = null;
    if (this.turntableButton) {
      this.turntableButton.setAttribute("aria-pressed", String(on));
      this.turntableButton.classList.toggle("on", on);
    }
    this.stage.requestRender(this);
  }

  /** Called by the stage after each draw: a turning view on screen asks for its next frame. */
  turn(onScreen, now) {
    if (!this.turntable || !onScreen) {
      this.lastTurn = null;
      return;
    }
    // seconds since the last turn, capped so that a slow frame or a pause does not jump
    const seconds = this.lastTurn === null ? 0 : Math.min((now - this.lastTurn) / 1000, 0.1);
    this.lastTurn = now;
    this.controls.update(seconds);
    this.stage.requestRender(this);
  }

  /** A button in the view's corner that turns the turntable on and off. */
  addTurntableToggle() {
    const button = document.createElement("button");
    button.className = "turntable-toggle";
    button.dataset.testid = "turntable";
    button.type = "button";
    button.title = "Turntable: turn the view slowly about the plant";
    button.setAttribute("aria-pressed", "false");
    button.textContent = "⟳ Turntable";
    // the element under the button orbits and picks on pointer events: keep them to the button
    for (const type of ["pointerdown", "pointerup", "wheel", "dblclick"]) {
      button.addEventListener(type, (e) => e.stopPropagation());
    }
    button.addEventListener("click", (e) => {
      e.stopPropagation();
      this.setTurntable(!this.turntable);
    });
    this.element.append(button);
    this.turntableButton = button;
  }

  /** Draws this view again at the next frame. */
  redraw() {
    this.stage.requestRender(this);
  }

  dispose() {
    this.turntable = false;
    this.turntableButton?.remove();
    this.controls.removeEventListener("change", this.onChange);
    this.controls.dispose();
    if (this.cacheKey !== null) release(this.cacheKey);
    this.sun.shadow.dispose();
    if (this.ground) {
      this.ground.geometry.dispose();
      this.ground.material.map.dispose(); // this view's clone; the image stays for the others
      this.ground.material.dispose();
    }
    if (this.contactShadow) {
      this.contactShadow.geometry.dispose();
      this.contactShadow.material.dispose();
    }
  }
}

/** The eight corners of a box. */
function boxCorners(box) {
  const corners = [];
  for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) corners.push(new THREE.Vector3(x, y, z));
  return corners;
}

/** The nearest 1, 2 or 5 times a power of ten at or below `x` (the ground's square, metres). */
function niceStep(x) {
  if (!(Number.isFinite(x) && x > 0)) return 1;
  const p = 10 ** Math.floor(Math.log10(x));
  const m = x / p;
  return p * (m >= 5 ? 5 : m >= 2 ? 2 : 1);
}

// ---------------------------------------------------------------------------------------------
// GLB loading. Plants never change once archived, so each plant's scene is parsed once per
// preview size and handed out as clones (sharing geometry and materials). A view loads the
// preview its size needs (`preview.glb?px=N`: a level of the plant's own chain of levels of
// detail), never the plant in full, which is for exports.

const loader = new GLTFLoader();
const cache = new Map(); // "id@px" -> Promise<THREE.Object3D>
const inUse = new Map(); // "id@px" -> count of views showing it
const CACHE_LIMIT = 36; // previews are at most a few MB each
/** Per plant: bytes, fetch and parse times (for the test's report). */
export const timings = [];

/**
 * Parses GLB bytes into a scene graph. The loader keeps the exports' textures (bark and leaf
 * grey-scale images in sRGB, times the material colour and the vertex colours); they are seen
 * at a slant, so they get some anisotropic filtering.
 */
export async function parseGlb(bytes) {
  const gltf = await loader.parseAsync(bytes, "");
  gltf.scene.traverse((o) => {
    for (const m of Array.isArray(o.material) ? o.material : o.material ? [o.material] : []) {
      for (const v of Object.values(m)) if (v && v.isTexture) v.anisotropy = ANISOTROPY;
    }
  });
  return gltf.scene;
}

/** Fetches and parses any GLB (not cached; for gardens, which change). */
export async function loadGlb(url) {
  const bytes = await getBytes(url, { cache: "no-store" });
  return parseGlb(bytes);
}

/**
 * The preview size for a view shown in `element`: its longest side in device pixels, rounded
 * up to a power of two from 128 to 2048 (the studio's own size classes, so views of about the
 * same size share one preview).
 */
function previewPixels(element) {
  const rect = element ? element.getBoundingClientRect() : null;
  const side = rect ? Math.max(rect.width, rect.height) * (window.devicePixelRatio || 1) : 320;
  return 2 ** Math.ceil(Math.log2(Math.min(Math.max(side, 128), 2048)));
}

/**
 * A clone of plant `id`'s grown scene (roots left out) at the detail a view in `element`
 * needs, fetched and parsed once.
 */
export async function loadPlant(id, element) {
  const px = previewPixels(element);
  const key = `${id}@${px}`;
  let p = cache.get(key);
  if (p) {
    cache.delete(key);
    cache.set(key, p);
  } else {
    p = (async () => {
      const t0 = performance.now();
      const bytes = await getBytes(`/api/plants/${encodeURIComponent(id)}/preview.glb?px=${px}`);
      const t1 = performance.now();
      const scene = await parseGlb(bytes);
      timings.push({ plant: id, px, bytes: bytes.byteLength, fetchMs: t1 - t0, parseMs: performance.now() - t1 });
      if (timings.length > 200) timings.shift();
      return scene;
    })();
    p.catch(() => cache.delete(key));
    cache.set(key, p);
    evict();
  }
  const scene = await p;
  inUse.set(key, (inUse.get(key) || 0) + 1);
  const clone = scene.clone(true);
  clone.userData.cacheKey = key;
  return clone;
}

function release(key) {
  const n = (inUse.get(key) || 0) - 1;
  if (n <= 0) inUse.delete(key);
  else inUse.set(key, n);
}

function evict() {
  for (const [key, p] of cache) {
    if (cache.size <= CACHE_LIMIT) break;
    if (inUse.has(key)) continue;
    cache.delete(key);
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
