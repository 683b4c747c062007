// Design mode: Poncin's designer (§4). Set the target surface and the density grid's favoured
// and forbidden cells, choose the weights, start an evolution of automata trees and watch the
// best of each generation grow, with its fitness terms as a table (Table 2's columns) and as
// curves. Runs go on in the server; the page follows them through server-sent events.

import { api, seedValue } from "./api.js";
import { Stage, loadPlant, THREE } from "./viewer.js";
import { TransformControls } from "three/addons/controls/TransformControls.js";
import { h, clear, field, num, readNumber, fmtNum } from "./dom.js";
import { drawChart } from "./chart.js";
import { stats as probes } from "./stats.js";
import { isLost, suspect } from "./connection.js";

const UNIT = 0.1; // metres per paper unit
const SHAPES = {
  sphere: [["center", "vec"], ["radius", "num"]],
  ellipsoid: [["center", "vec"], ["radii", "vec"]],
  box: [["center", "vec"], ["size", "vec"]],
  cylinder: [["base", "vec"], ["radius", "num"], ["height", "num"]],
  cone: [["base", "vec"], ["radius", "num"], ["height", "num"]],
};
const DEFAULTS = {
  center: [0, 200, 0],
  radii: [150, 120, 150],
  size: [300, 300, 300],
  base: [0, 50, 0],
  radius: 150,
  height: 300,
};
const WEIGHTS = [
  ["pos", 5, "F_pos: endpoints on the surface"],
  ["num", 50, "F_num: number of endpoints"],
  ["dist", 200, "F_dist: endpoints spread out"],
  ["thick", 0, "F_thick: branch thickness"],
  ["angle", 0, "F_angle: branching angles"],
  ["grid", 10, "F_grid: leaves in favoured cells, none in forbidden ones"],
];
const RUNNING = "running";
// The most generations a design run has (the studio's limit).
const MAX_GENERATIONS = 1000;

export default function createDesignMode(ctx, root) {
  // ---- the form ------------------------------------------------------------------------------
  const shape = h("select", { testid: "design-shape" });
  for (const s of Object.keys(SHAPES)) shape.append(h("option", { value: s }, s));
  const values = structuredClone(DEFAULTS);
  const shapeFields = h("div", { class: "shape-fields" });
  const weightInputs = Object.fromEntries(
    WEIGHTS.map(([k, v]) => [k, num(`design-weight-${k}`, v, { min: 0, width: "5em" })]),
  );
  const numTarget = num("design-num-target", 30, { min: 1, step: 1, width: "5em" });
  const population = num("design-population", 200, { min: 10, max: 20000, step: 1, width: "6em" });
  const generations = num("design-generations", 30, { min: 1, max: 1000, step: 1, width: "5em" });
  const seed = num("design-seed", 1, { min: 0, step: 1, width: "7em" });

  const gridEnabled = h("input", { type: "checkbox", testid: "design-grid-enabled" });
  const gridMin = vecInputs("design-grid-min", [-200, 0, -200]);
  const gridMax = vecInputs("design-grid-max", [200, 400, 200]);
  const divisions = vecInputs("design-divisions", [5, 5, 5], { min: 1, max: 16, step: 1 });
  const gridTarget = num("design-grid-target", 15, { min: 0, step: 1, width: "5em" });
  const painter = h("div", { class: "painter", testid: "design-painter" });
  const cells = new Map(); // "i,j,k" -> 1 | -1

  const startBtn = h("button", { class: "primary", testid: "design-start", onclick: () => start() }, "Start");
  const updateBtn = h("button", { testid: "design-update", title: "Send this design to the open session's run", onclick: () => update() }, "Apply to this run");
  const stopBtn = h("button", { testid: "design-stop", onclick: () => stop() }, "Stop");
  const resumeBtn = h("button", { testid: "design-resume", title: "Go on: a stopped run to its generations, a finished one to twice as many", onclick: () => resume() }, "Resume");
  const frameBtn = h("button", { testid: "design-frame", onclick: () => view && view.frame() }, "Frame");
  // The move gizmo sits at the target's centre, where the trees grow: shown only while the
  // person moves the target (and before a run shows a tree).
  const moveBtn = h("button", { testid: "design-move", "aria-pressed": "false", title: "Show the arrows that move the target", onclick: () => setMoving(!moving) }, "Move target");
  let moving = true;

  const form = h(
    "div",
    { class: "design-form", testid: "design-form" },
    h("h3", {}, "Target surface"),
    field("Shape", shape),
    shapeFields,
    h("p", { class: "hint" }, "Paper units (0.1 m). Move target shows arrows in the view to drag it by."),
    h("h3", {}, "Weights"),
    h("div", { class: "weights" }, WEIGHTS.map(([k, , t]) => field(k, weightInputs[k], t))),
    h("h3", {}, "Run"),
    h("div", { class: "weights" },
      field("endpoints (N)", numTarget, "num_target: the number of branch endpoints aimed at"),
      field("population", population, "10 to 20000"),
      field("generations", generations, "1 to 1000"),
      field("seed", seed)),
    h("h3", {}, h("label", {}, gridEnabled, " Density grid")),
    h("div", { class: "grid-fields" },
      field("min", gridMin.el), field("max", gridMax.el), field("divisions", divisions.el),
      field("leaves per favoured cell", gridTarget),
      h("div", { class: "buttons" },
        h("button", { testid: "design-grid-all", onclick: () => fillCells(1) }, "All favoured"),
        h("button", { testid: "design-grid-top", title: "Forbid the top layer (Poncin's object above the tree)", onclick: () => forbidTop() }, "Forbid top layer"),
        h("button", { testid: "design-grid-clear", onclick: () => fillCells(0) }, "Clear")),
      h("p", { class: "hint" }, "Click a cell: neutral → favoured → forbidden. Layers from the top down; x across, z down."),
      painter),
    h("div", { class: "buttons sticky" }, startBtn, updateBtn, stopBtn, resumeBtn),
  );

  // ---- the view and the progress --------------------------------------------------------------
  const canvas = h("canvas", { class: "stage-canvas", testid: "design-canvas" });
  const viewEl = h("div", { class: "view-el" });
  const wrap = h("div", { class: "view-wrap design-view" }, canvas, viewEl);
  const statusEl = h("div", { class: "run-status", testid: "design-status" }, "no run");
  const table = h("table", { class: "progress", testid: "design-table" });
  // a table of many figures a generation: it scrolls sideways where the view is narrow
  const tableBox = h("div", { class: "table-box", dataset: { scroll: "x" } }, table);
  const chart = h("canvas", { class: "chart", testid: "design-chart" });
  const termsChart = h("canvas", { class: "chart", testid: "design-terms-chart" });
  const right = h("div", { class: "design-right" },
    h("div", { class: "toolbar" }, statusEl, frameBtn, moveBtn), wrap,
    h("div", { class: "charts" }, chart, termsChart), tableBox);
  const workspace = h("div", { class: "workspace design" }, form, right);
  const formHolder = h("div", { class: "form-holder" });
  root.append(formHolder, workspace);

  let stage = null;
  let view = null;
  let tc = null;
  let targetGroup = null;
  let gridGroup = null;
  let session = null;
  let run = null;
  let rows = new Map();
  let terms = [];
  let es = null;
  let esSession = null;
  let framed = false;
  let framedBox = null;
  let wantPlant = null;
  let shownPlant = null;
  let pumping = false;

  function vecInputs(prefix, v, opts = {}) {
    const inputs = ["x", "y", "z"].map((a, i) =>
      num(`${prefix}-${a}`, v[i], { width: "5.2em", step: opts.step ?? "any", min: opts.min, max: opts.max }),
    );
    return { el: h("span", { class: "vec" }, inputs), inputs };
  }

  function buildShapeFields() {
    clear(shapeFields);
    for (const [name, kind] of SHAPES[shape.value]) {
      if (kind === "vec") {
        const vi = vecInputs(`design-${name}`, values[name]);
        vi.inputs.forEach((inp, i) =>
          inp.addEventListener("input", () => {
            const n = Number(inp.value);
            if (Number.isFinite(n)) values[name][i] = n;
            drawTarget();
          }),
        );
        shapeFields.append(field(name, vi.el));
      } else {
        const inp = num(`design-${name}`, values[name], { width: "6em" });
        inp.addEventListener("input", () => {
          const n = Number(inp.value);
          if (Number.isFinite(n)) values[name] = n;
          drawTarget();
        });
        shapeFields.append(field(name, inp));
      }
    }
  }
  shape.addEventListener("change", () => {
    buildShapeFields();
    drawTarget();
  });

  function target() {
    const t = { shape: shape.value };
    for (const [name] of SHAPES[shape.value]) {
      const v = values[name];
      t[name] = Array.isArray(v) ? [...v] : v;
    }
    return t;
  }

  function readVec(vi, name) {
    return vi.inputs.map((inp, i) => readNumber(inp, `${name}[${i}]`));
  }

  function design() {
    const weights = {};
    for (const [k] of WEIGHTS) weights[k] = readNumber(weightInputs[k], `weights.${k}`);
    const d = {
      target: target(),
      weights,
      num_target: readNumber(numTarget, "num_target"),
      population: readNumber(population, "population"),
      generations: readNumber(generations, "generations"),
      seed: seedValue(seed.value),
    };
    if (gridEnabled.checked) {
      const div = readVec(divisions, "grid.divisions");
      d.grid = {
        min: readVec(gridMin, "grid.min"),
        max: readVec(gridMax, "grid.max"),
        divisions: div,
        cells: [...cells.entries()]
          .map(([k, w]) => ({ cell: k.split(",").map(Number), weight: w }))
          .filter(({ cell }) => cell.every((c, i) => c < div[i])),
        target: readNumber(gridTarget, "grid.target"),
      };
    }
    return d;
  }

  function fillForm(design) {
    if (!design || typeof design !== "object") return;
    // the studio echoes the request with nulls for what was left to its defaults
    const d = Object.fromEntries(Object.entries(design).filter(([, v]) => v !== null && v !== undefined));
    const t = d.target;
    if (t && SHAPES[t.shape]) {
      shape.value = t.shape;
      for (const [name] of SHAPES[t.shape]) if (t[name] !== undefined) values[name] = structuredClone(t[name]);
      buildShapeFields();
    }
    if (d.weights) for (const [k] of WEIGHTS) if (d.weights[k] !== undefined && d.weights[k] !== null) weightInputs[k].value = d.weights[k];
    if (typeof d.num_target === "number") numTarget.value = d.num_target;
    if (d.population !== undefined) population.value = d.population;
    if (d.generations !== undefined) generations.value = d.generations;
    if (d.seed !== undefined) seed.value = String(d.seed);
    gridEnabled.checked = !!d.grid;
    if (d.grid) {
      const g = d.grid;
      if (g.min) gridMin.inputs.forEach((inp, i) => (inp.value = g.min[i]));
      if (g.max) gridMax.inputs.forEach((inp, i) => (inp.value = g.max[i]));
      if (g.divisions) divisions.inputs.forEach((inp, i) => (inp.value = g.divisions[i]));
      if (g.target !== undefined) gridTarget.value = g.target;
      cells.clear();
      for (const c of g.cells || []) cells.set(c.cell.join(","), c.weight > 0 ? 1 : -1);
    }
    buildPainter();
    drawTarget();
  }

  // ---- the grid painter ------------------------------------------------------------------------
  function dims() {
    return divisions.inputs.map((inp) => Math.max(1, Math.min(16, Math.round(Number(inp.value)) || 1)));
  }

  function buildPainter() {
    clear(painter);
    painter.classList.toggle("disabled", !gridEnabled.checked);
    const [nx, ny, nz] = dims();
    const lo = gridMin.inputs.map((i) => Number(i.value));
    const hi = gridMax.inputs.map((i) => Number(i.value));
    for (let j = ny - 1; j >= 0; j--) {
      const y0 = lo[1] + ((hi[1] - lo[1]) * j) / ny;
      const y1 = lo[1] + ((hi[1] - lo[1]) * (j + 1)) / ny;
      const layer = h("div", { class: "layer", style: { gridTemplateColumns: `repeat(${nx}, 1fr)` } });
      for (let k = 0; k < nz; k++) {
        for (let i = 0; i < nx; i++) {
          const key = `${i},${j},${k}`;
          const w = cells.get(key) || 0;
          const b = h("button", {
            class: "pcell " + (w > 0 ? "fav" : w < 0 ? "forb" : ""),
            testid: `paint-${i}-${j}-${k}`,
            title: `cell [${i}, ${j}, ${k}]`,
            dataset: { weight: String(w) },
            onclick: () => {
              const now = cells.get(key) || 0;
              const next = now === 0 ? 1 : now === 1 ? -1 : 0;
              if (next === 0) cells.delete(key);
              else cells.set(key, next);
              if (next !== 0) gridEnabled.checked = true;
              b.className = "pcell " + (next > 0 ? "fav" : next < 0 ? "forb" : "");
              b.dataset.weight = String(next);
              painter.classList.toggle("disabled", !gridEnabled.checked);
              drawTarget();
            },
          });
          layer.append(b);
        }
      }
      painter.append(h("div", { class: "layer-box" }, h("div", { class: "layer-title" }, `layer ${j} · y ${fmtNum(y0)}–${fmtNum(y1)}`), layer));
    }
  }

  function fillCells(w) {
    const [nx, ny, nz] = dims();
    cells.clear();
    if (w !== 0) {
      gridEnabled.checked = true;
      for (let i = 0; i < nx; i++) for (let j = 0; j < ny; j++) for (let k = 0; k < nz; k++) cells.set(`${i},${j},${k}`, w);
    }
    buildPainter();
    drawTarget();
  }

  function forbidTop() {
    const [nx, ny, nz] = dims();
    gridEnabled.checked = true;
    for (let i = 0; i < nx; i++) for (let k = 0; k < nz; k++) cells.set(`${i},${ny - 1},${k}`, -1);
    buildPainter();
    drawTarget();
  }

  for (const vi of [divisions, gridMin, gridMax]) {
    for (const inp of vi.inputs) inp.addEventListener("change", () => (buildPainter(), drawTarget()));
  }
  gridEnabled.addEventListener("change", () => (buildPainter(), drawTarget()));

  // ---- the 3D view -----------------------------------------------------------------------------
  function ensureStage() {
    if (stage) return;
    stage = new Stage(canvas);
    view = stage.addView(viewEl, { detail: true });
    probes.stages.design = stage;
    targetGroup = new THREE.Group();
    gridGroup = new THREE.Group();
    view.helpers.add(targetGroup, gridGroup);
    tc = new TransformControls(view.camera, viewEl);
    tc.setMode("translate");
    tc.setSize(0.8);
    tc.translationSnap = 0.5; // metres: 5 paper units
    view.scene.add(tc.getHelper());
    tc.attach(targetGroup);
    tc.addEventListener("change", () => stage.requestRender());
    tc.addEventListener("dragging-changed", (e) => (view.controls.enabled = !e.value));
    tc.addEventListener("objectChange", () => {
      const key = shape.value === "cylinder" || shape.value === "cone" ? "base" : "center";
      const p = targetGroup.position;
      values[key] = [p.x, p.y, p.z].map((v) => Math.round((v / UNIT) * 100) / 100);
      for (const [i, a] of ["x", "y", "z"].entries()) {
        const inp = shapeFields.querySelector(`[data-testid="design-${key}-${a}"]`);
        if (inp) inp.value = values[key][i];
      }
    });
    new ResizeObserver(() => drawCharts()).observe(chart);
    setMoving(moving);
    drawTarget();
    view.frame();
  }

  function setMoving(on) {
    moving = on;
    moveBtn.setAttribute("aria-pressed", String(on));
    moveBtn.classList.toggle("on", on);
    if (!tc) return;
    tc.enabled = on;
    tc.getHelper().visible = on;
    stage.requestRender();
  }

  function drawTarget() {
    if (!stage) return;
    for (const c of [...targetGroup.children]) {
      targetGroup.remove(c);
      disposeTree(c);
    }
    const t = target();
    const line = new THREE.LineBasicMaterial({ color: 0x8fb8ff, transparent: true, opacity: 0.6, depthWrite: false });
    const fill = new THREE.MeshBasicMaterial({ color: 0x8fb8ff, transparent: true, opacity: 0.06, depthWrite: false, side: THREE.DoubleSide });
    let origin;
    if (t.shape === "sphere" || t.shape === "ellipsoid") {
      origin = t.center;
      const r = t.shape === "sphere" ? [t.radius, t.radius, t.radius] : t.radii;
      const s = r.map((v) => Math.max(Math.abs(v) * UNIT, 1e-3));
      targetGroup.add(ellipsoidWire(s, line));
      const m = new THREE.Mesh(new THREE.SphereGeometry(1, 32, 16), fill);
      m.scale.set(...s);
      targetGroup.add(m);
    } else if (t.shape === "box") {
      origin = t.center;
      const s = t.size.map((v) => Math.max(Math.abs(v) * UNIT, 1e-3));
      const g = new THREE.BoxGeometry(...s);
      targetGroup.add(new THREE.LineSegments(new THREE.EdgesGeometry(g), line), new THREE.Mesh(g, fill));
    } else {
      origin = t.base;
      const r = Math.max(Math.abs(t.radius) * UNIT, 1e-3);
      const height = t.height * UNIT || 1e-3;
      const top = t.shape === "cylinder" ? r : 0;
      const g = new THREE.CylinderGeometry(top, r, Math.abs(height), 32, 1, false);
      g.translate(0, Math.abs(height) / 2, 0);
      if (height < 0) g.scale(1, -1, 1);
      targetGroup.add(new THREE.LineSegments(new THREE.EdgesGeometry(g, 10), line), new THREE.Mesh(g, fill));
      targetGroup.add(new THREE.LineSegments(verticals(top, r, height), line));
    }
    if (!tc || !tc.dragging) targetGroup.position.set(origin[0] * UNIT, origin[1] * UNIT, origin[2] * UNIT);
    drawGrid();
    stage.requestRender();
  }

  function drawGrid() {
    for (const c of [...gridGroup.children]) {
      gridGroup.remove(c);
      disposeTree(c);
    }
    if (!gridEnabled.checked) return;
    const lo = gridMin.inputs.map((i) => Number(i.value) * UNIT);
    const hi = gridMax.inputs.map((i) => Number(i.value) * UNIT);
    if (![...lo, ...hi].every(Number.isFinite)) return;
    const [nx, ny, nz] = dims();
    const outer = new THREE.Box3(new THREE.Vector3(...lo), new THREE.Vector3(...hi));
    const bh = new THREE.Box3Helper(outer, 0x59606b);
    bh.userData.frame = true;
    gridGroup.add(bh);
    const step = [(hi[0] - lo[0]) / nx, (hi[1] - lo[1]) / ny, (hi[2] - lo[2]) / nz];
    const fav = new THREE.LineBasicMaterial({ color: 0x7fd18b, transparent: true, opacity: 0.28 });
    const forb = new THREE.LineBasicMaterial({ color: 0xe05a4f, transparent: true, opacity: 0.9 });
    const forbFill = new THREE.MeshBasicMaterial({ color: 0xe05a4f, transparent: true, opacity: 0.12, depthWrite: false });
    const unit = new THREE.BoxGeometry(1, 1, 1);
    const edges = new THREE.EdgesGeometry(unit);
    for (const [key, w] of cells) {
      const [i, j, k] = key.split(",").map(Number);
      if (i >= nx || j >= ny || k >= nz) continue;
      const c = new THREE.Vector3(lo[0] + (i + 0.5) * step[0], lo[1] + (j + 0.5) * step[1], lo[2] + (k + 0.5) * step[2]);
      const s = new THREE.Vector3(step[0] * 0.96, step[1] * 0.96, step[2] * 0.96);
      const e = new THREE.LineSegments(edges, w > 0 ? fav : forb);
      e.position.copy(c);
      e.scale.copy(s);
      gridGroup.add(e);
      if (w < 0) {
        const m = new THREE.Mesh(unit, forbFill);
        m.position.copy(c);
        m.scale.copy(s);
        gridGroup.add(m);
      }
    }
  }

  // ---- the run ---------------------------------------------------------------------------------
  async function render(s) {
    const changed = !session || session.id !== s.id;
    session = s;
    ensureStage();
    if (changed) {
      rows = new Map();
      terms = [];
      framed = false;
      framedBox = null;
      shownPlant = null;
      wantPlant = null;
      view.setContent(null, { frame: false });
      const saved = (s.state && s.state.design) || loadSavedDesign(s.id);
      if (saved) fillForm(saved);
    }
    // follow the events first so nothing falls between the table and the stream
    openEvents(s.id);
    const r = await ctx.act(() => api.run(s.id));
    if (!r || !session || session.id !== s.id) return false;
    applyRun(r);
    if (!changed) return true;
    if (r.design && typeof r.design === "object") fillForm(r.design);
    else if (r.config && typeof r.config === "object") fillForm(r.config);
    return true;
  }

  function applyRun(r) {
    run = r;
    if (Array.isArray(r.terms)) terms = r.terms;
    for (const row of r.rows || []) rows.set(row.generation, row);
    setStatus(r.status, r.generation, r.generations, r.error);
    drawTable();
    drawCharts();
    const last = lastRow();
    if (last && last.plant !== undefined && last.plant !== null) showBest(last.plant);
    if (r.status !== RUNNING) closeEvents();
  }

  function setStatus(status, generation, total, error) {
    statusEl.dataset.status = status || "";
    statusEl.dataset.generation = String(generation ?? "");
    statusEl.className = `run-status ${status || ""}`;
    statusEl.textContent = `${status || "–"} · generation ${generation ?? "–"} of ${total ?? "–"}${error ? ` · ${error}` : ""}`;
    stopBtn.disabled = status !== RUNNING;
    // as Match and Map: a finished run goes on too (to twice its generations, at most 1000)
    resumeBtn.disabled = !(status === "stopped" || (status === "done" && (generation ?? 0) < MAX_GENERATIONS));
    updateBtn.disabled = !session;
    if (status === "failed" && error) ctx.showError(new Error(`the run failed: ${error}`));
  }

  function lastRow() {
    let best = null;
    for (const r of rows.values()) if (!best || r.generation > best.generation) best = r;
    return best;
  }

  function openEvents(id) {
    // a stream still open goes on; one closed or reconnecting (the studio was away) starts again
    if (es && esSession === id && es.readyState === EventSource.OPEN) return;
    closeEvents();
    esSession = id;
    // EventSource sends the cookie (set by the studio when the page was opened with a token)
    es = new EventSource(api.eventsUrl(id));
    const onGeneration = (e) => {
      let g;
      try {
        g = JSON.parse(e.data);
      } catch {
        ctx.showError(new Error(`a generation event that is not JSON: ${String(e.data).slice(0, 120)}`));
        return;
      }
      if (!session || session.id !== id) return;
      if (Array.isArray(g.terms) && g.terms.length) terms = g.terms;
      rows.set(g.generation, g);
      setStatus(g.status || RUNNING, g.generation, run?.generations, null);
      drawTable();
      drawCharts();
      if (g.plant !== undefined && g.plant !== null) showBest(g.plant);
      ctx.refreshPopulation();
    };
    const onStatus = async (e) => {
      let st = {};
      try {
        st = JSON.parse(e.data);
      } catch {
        st = { status: String(e.data) };
      }
      if (!session || session.id !== id) return;
      if (st.status && st.status !== RUNNING) closeEvents();
      const r = await ctx.act(() => api.run(id));
      if (r && session && session.id === id) applyRun(r);
    };
    es.addEventListener("generation", onGeneration);
    es.addEventListener("status", onStatus);
    es.addEventListener("message", (e) => {
      // a stream without event names: tell the kinds apart by their fields
      try {
        const d = JSON.parse(e.data);
        if (d && d.generation !== undefined && d.best !== undefined) onGeneration(e);
        else onStatus(e);
      } catch {
        /* keep-alive text */
      }
    });
    const mine = es;
    es.addEventListener("error", async () => {
      // a dropped stream may be a studio that is gone: the page follows again when it is back
      await suspect();
      if (es === mine && mine.readyState === EventSource.CLOSED && !isLost()) {
        ctx.showError(new Error(`lost the progress stream of session #${id}; reload to follow the run again`));
      }
    });
  }

  function closeEvents() {
    if (es) es.close();
    es = null;
    esSession = null;
  }

  async function showBest(id) {
    wantPlant = id;
    if (pumping) return;
    pumping = true;
    try {
      while (wantPlant !== shownPlant) {
        const pid = wantPlant;
        let object;
        try {
          object = await loadPlant(pid, viewEl);
        } catch (err) {
          ctx.showError(err, `plant #${pid}`);
          shownPlant = pid;
          break;
        }
        if (!session) break;
        // frame again when the new best outgrows what is in view (runs grow their trees)
        const box = new THREE.Box3().setFromObject(object);
        const outgrows = framedBox && !box.isEmpty() && !framedBox.containsBox(box);
        // the first tree of a run: out of its way
        if (shownPlant === null && moving) setMoving(false);
        view.setContent(object, { frame: !framed || outgrows, plantId: pid });
        if (!framed || outgrows) {
          framedBox = new THREE.Box3().setFromObject(view.content);
          for (const h of view.helpers.children) framedBox.expandByObject(h);
          framedBox.expandByScalar(framedBox.getSize(new THREE.Vector3()).length() * 0.02);
        }
        framed = true;
        shownPlant = pid;
        viewEl.dataset.plant = String(pid);
      }
    } finally {
      pumping = false;
    }
  }

  function drawTable() {
    clear(table);
    const head = h("tr", {}, h("th", {}, "gen"), h("th", {}, "best"), h("th", {}, "mean"), terms.map((t) => h("th", {}, t)), h("th", {}, "plant"));
    const sorted = [...rows.values()].sort((a, b) => a.generation - b.generation);
    const body = sorted.map((r) =>
      h("tr", { dataset: { generation: String(r.generation) } },
        h("td", {}, String(r.generation)),
        h("td", {}, fmtNum(r.best)),
        h("td", {}, fmtNum(r.mean)),
        terms.map((_, i) => h("td", {}, fmtNum((r.best_terms || [])[i]))),
        h("td", {}, r.plant !== undefined && r.plant !== null
          ? h("a", { href: "#", onclick: (e) => { e.preventDefault(); ctx.openPlant(r.plant); } }, `#${r.plant}`)
          : "–"),
      ),
    );
    table.append(h("thead", {}, head), h("tbody", {}, body));
    tableBox.scrollTop = tableBox.scrollHeight;
  }

  function drawCharts() {
    const sorted = [...rows.values()].sort((a, b) => a.generation - b.generation);
    drawChart(chart, [
      { name: "best", points: sorted.map((r) => [r.generation, r.best]), color: "#7fd18b", width: 2 },
      { name: "mean", points: sorted.map((r) => [r.generation, r.mean]), color: "#e0b85c" },
    ], { title: "fitness: best and mean", log: "auto" });
    drawChart(termsChart, terms.map((t, i) => ({ name: t, points: sorted.map((r) => [r.generation, (r.best_terms || [])[i]]) })),
      { title: "the best tree's terms", log: "auto" });
  }

  async function start() {
    const made = await ctx.act(() => api.createSession({ mode: "design", design: design() }));
    if (made) {
      saveDesign(made.id, design());
      await ctx.sessionCreated(made);
    }
  }

  async function update() {
    if (!session) return;
    const d = await ctx.act(() => design());
    if (!d) return;
    const s = await ctx.act(() => api.design(session.id, d));
    if (s) {
      saveDesign(session.id, d);
      rows = new Map();
      closeEvents();
      await ctx.setSession(s);
    }
  }

  async function stop() {
    if (!session) return;
    const s = await ctx.act(() => api.stop(session.id));
    if (s) await ctx.setSession(s);
  }

  async function resume() {
    if (!session) return;
    // a stopped run goes on to the generations it was asked; a finished one to twice as many
    const more = run && run.status === "done"
      ? Math.min(MAX_GENERATIONS, Math.max(run.generations, run.generation) * 2)
      : undefined;
    const s = await ctx.act(() => api.resume(session.id, more));
    if (s) await ctx.setSession(s);
  }

  // Design has no separate form: the form on the left is the new session's, and Start makes it.
  function newSessionForm() {
    return null;
  }

  buildShapeFields();
  buildPainter();

  return {
    name: "design",
    formHolder,
    workspace,
    alwaysShowWorkspace: true,
    render,
    newSessionForm,
    show() {
      ensureStage();
      stage.requestRender();
      drawCharts();
    },
    hide() {},
    reset() {
      closeEvents();
      session = null;
      run = null;
      rows = new Map();
      terms = [];
      setStatus(null, null, null, null);
      drawTable();
      drawCharts();
      if (view) view.setContent(null, { frame: false });
    },
    onKey() {
      return false;
    },
  };
}

function saveDesign(id, d) {
  try {
    localStorage.setItem(`sylva-design-${id}`, JSON.stringify(d));
  } catch {
    /* storage full or disabled: the form simply stays as it is */
  }
}

function loadSavedDesign(id) {
  try {
    const t = localStorage.getItem(`sylva-design-${id}`);
    return t ? JSON.parse(t) : null;
  } catch {
    return null;
  }
}

function ellipsoidWire([rx, ry, rz], material) {
  const pts = [];
  const N = 64;
  for (let m = 0; m < 12; m++) {
    const phi = (m / 12) * Math.PI * 2;
    for (let i = 0; i < N; i++) {
      const a = (i / N) * Math.PI, b = ((i + 1) / N) * Math.PI;
      pts.push(
        new THREE.Vector3(Math.sin(a) * Math.cos(phi) * rx, Math.cos(a) * ry, Math.sin(a) * Math.sin(phi) * rz),
        new THREE.Vector3(Math.sin(b) * Math.cos(phi) * rx, Math.cos(b) * ry, Math.sin(b) * Math.sin(phi) * rz),
      );
    }
  }
  for (let p = 1; p < 8; p++) {
    const th = (p / 8) * Math.PI;
    const y = Math.cos(th) * ry, s = Math.sin(th);
    for (let i = 0; i < N; i++) {
      const a = (i / N) * Math.PI * 2, b = ((i + 1) / N) * Math.PI * 2;
      pts.push(new THREE.Vector3(Math.cos(a) * s * rx, y, Math.sin(a) * s * rz), new THREE.Vector3(Math.cos(b) * s * rx, y, Math.sin(b) * s * rz));
    }
  }
  return new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(pts), material);
}

function verticals(top, r, height) {
  const pts = [];
  for (let i = 0; i < 8; i++) {
    const a = (i / 8) * Math.PI * 2;
    pts.push(new THREE.Vector3(Math.cos(a) * r, 0, Math.sin(a) * r), new THREE.Vector3(Math.cos(a) * top, height, Math.sin(a) * top));
  }
  return new THREE.BufferGeometry().setFromPoints(pts);
}

function disposeTree(o) {
  o.traverse((c) => {
    if (c.geometry) c.geometry.dispose();
  });
}
