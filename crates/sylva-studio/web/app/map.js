// Map mode: a variety map (MAP-Elites) of any model. Choose the model and the two descriptors
// the map's axes measure, start, and watch the map fill: each filled cell shows its plant, the
// fittest of its kind found so far. Click a cell to open its plant (branch it into a breeding
// session, export it with wind and levels of detail). Runs go on in the server; the page
// follows them through server-sent events.

import { api, seedValue } from "./api.js";
import { h, clear, field, num, readNumber, fmtNum } from "./dom.js";
import { drawChart } from "./chart.js";
import { follow } from "./follow.js";
import { thumb } from "./thumbs.js";

const RUNNING = "running";
const THUMB = 72;

export default function createMapMode(ctx, root) {
  // ---- the form ------------------------------------------------------------------------------
  const model = h("select", { testid: "map-model" });
  const xName = h("select", { testid: "map-x" });
  const yName = h("select", { testid: "map-y" });
  const xCells = num("map-x-cells", 8, { min: 1, max: 32, step: 1, width: "4em" });
  const yCells = num("map-y-cells", 8, { min: 1, max: 32, step: 1, width: "4em" });
  const generations = num("map-generations", 300, { min: 1, max: 100000, step: 1, width: "6em" });
  const seed = num("map-seed", 1, { min: 0, step: 1, width: "7em" });
  const about = h("p", { class: "hint", testid: "map-about" });
  const startBtn = h("button", { class: "primary", testid: "map-start", onclick: () => start() }, "Start");
  const stopBtn = h("button", { testid: "map-stop", onclick: () => stop() }, "Stop");
  const resumeBtn = h("button", { testid: "map-resume", title: "Go on: twice the generations asked so far", onclick: () => resume() }, "Resume");

  const form = h(
    "div",
    { class: "design-form map-form", testid: "map-form" },
    h("h3", {}, "Map"),
    field("model", model, "the model whose plants fill the map; its example map's fitness scores them"),
    field("across", h("span", {}, xName, " ", xCells), "the descriptor left to right, and its cells"),
    field("up", h("span", {}, yName, " ", yCells), "the descriptor bottom to top, and its cells"),
    about,
    h("h3", {}, "Run"),
    h("div", { class: "weights" }, field("generations", generations, "1 to 100000"), field("seed", seed)),
    h("p", { class: "hint" }, "Each cell keeps the fittest plant of its kind. Click a filled cell to open its plant: branch it into a breeding session, or export it with wind and levels of detail."),
    h("div", { class: "buttons sticky" }, startBtn, stopBtn, resumeBtn),
  );

  // ---- the map and its figures ----------------------------------------------------------------
  const statusEl = h("div", { class: "run-status", testid: "map-status" }, "no map");
  const grid = h("div", { class: "map-grid", testid: "map-grid" });
  const yLabel = h("div", { class: "map-axis map-y-label", testid: "map-y-label" });
  const xLabel = h("div", { class: "map-axis", testid: "map-x-label" });
  const chart = h("canvas", { class: "chart", testid: "map-chart" });
  const right = h("div", { class: "design-right map-right" },
    h("div", { class: "toolbar" }, statusEl),
    h("div", { class: "map-box" }, yLabel, grid, xLabel),
    h("div", { class: "charts" }, chart));
  const workspace = h("div", { class: "workspace design map" }, form, right);
  const formHolder = h("div", { class: "form-holder" });
  root.append(formHolder, workspace);

  let descriptors = [];
  let session = null;
  let view = null; // the map as the server last described it
  let cells = new Map(); // cell -> {plant, fitness, descriptors}
  let rows = new Map(); // generation -> figures
  let es = null;
  let esSession = null;

  async function loadChoices() {
    if (!descriptors.length) descriptors = (await ctx.act(() => api.descriptors())) || [];
    const fill = (select, chosen) => {
      if (select.options.length) return;
      for (const d of descriptors) select.append(h("option", { value: d.name, title: d.about }, d.name));
      select.value = chosen;
    };
    fill(xName, "height_to_width");
    fill(yName, "porosity");
    if (!model.options.length) {
      for (const m of ctx.models) model.append(h("option", { value: m.name }, m.title || m.name));
      model.value = ctx.models.some((m) => m.name === "bintree") ? "bintree" : (ctx.models[0] || {}).name;
    }
    describe();
  }
  function describe() {
    const of = (name) => descriptors.find((d) => d.name === name);
    const x = of(xName.value), y = of(yName.value);
    about.textContent = [x, y].filter(Boolean).map((d) => `${d.name}: ${d.about} (${fmtNum(d.min)} to ${fmtNum(d.max)})`).join(" · ");
  }
  xName.addEventListener("change", describe);
  yName.addEventListener("change", describe);

  function design() {
    return {
      model: model.value,
      x: { name: xName.value, cells: readNumber(xCells, "map.x.cells") },
      y: { name: yName.value, cells: readNumber(yCells, "map.y.cells") },
      generations: readNumber(generations, "map.generations"),
      seed: seedValue(seed.value, "map.seed"),
    };
  }

  function fillForm(d) {
    if (!d) return;
    if (d.model) model.value = d.model;
    if (d.x) {
      xName.value = d.x.name;
      if (d.x.cells) xCells.value = String(d.x.cells);
    }
    if (d.y) {
      yName.value = d.y.name;
      if (d.y.cells) yCells.value = String(d.y.cells);
    }
    if (d.generations) generations.value = String(d.generations);
    if (d.seed !== undefined) seed.value = String(d.seed);
    describe();
  }

  // ---- drawing ---------------------------------------------------------------------------------
  function drawGrid() {
    clear(grid);
    if (!view) return;
    const [x, y] = view.axes;
    const columns = x.cells, rowsN = y ? y.cells : 1;
    // cells of THUMB pixels, narrower (square still) when the map's box is: no side scrolling
    grid.style.gridTemplateColumns = `repeat(${columns}, minmax(0, ${THUMB}px))`;
    // the top row is the highest cells of the second axis
    for (let r = rowsN - 1; r >= 0; r--) {
      for (let c = 0; c < columns; c++) {
        const cell = c * rowsN + r;
        const filled = cells.get(cell);
        const title = filled
          ? `cell ${cell}: plant #${filled.plant}, fitness ${fmtNum(filled.fitness)}, ${(filled.descriptors || []).map((d, i) => `${view.axes[i].name} ${fmtNum(d)}`).join(", ")}`
          : `cell ${cell}: empty`;
        grid.append(
          h("button", {
            class: "map-cell" + (filled ? " filled" : ""),
            testid: "map-cell",
            dataset: { cell: String(cell), plant: filled ? String(filled.plant) : "" },
            title,
            disabled: !filled,
            onclick: () => filled && ctx.openPlant(filled.plant),
          },
          filled ? thumb(api.pngUrl(filled.plant, `${THUMB * 2}x${THUMB * 2}`, "front"), { width: THUMB, height: THUMB, alt: `plant ${filled.plant}` }) : null),
        );
      }
    }
    xLabel.textContent = `${x.name} → (${fmtNum(x.min)} to ${fmtNum(x.max)})`;
    yLabel.textContent = y ? `↑ ${y.name} (${fmtNum(y.min)} to ${fmtNum(y.max)})` : "";
  }

  // the cell index is row-major over the axes, the first slowest: x * y.cells + y
  function updateCell(c) {
    cells.set(c.cell, c);
    const el = grid.querySelector(`[data-cell="${c.cell}"]`);
    if (!el || !view) return drawGrid();
    el.classList.add("filled");
    el.disabled = false;
    el.dataset.plant = String(c.plant);
    el.onclick = () => ctx.openPlant(c.plant);
    clear(el);
    el.append(thumb(api.pngUrl(c.plant, `${THUMB * 2}x${THUMB * 2}`, "front"), { width: THUMB, height: THUMB, alt: `plant ${c.plant}` }));
  }

  function drawChart_() {
    const sorted = [...rows.values()].sort((a, b) => a.generation - b.generation);
    drawChart(chart, [
      { name: "coverage (%)", points: sorted.map((r) => [r.generation, 100 * r.coverage]), color: "#7fd18b", width: 2 },
      { name: "cells filled", points: sorted.map((r) => [r.generation, r.filled]), color: "#e0b85c" },
    ], { title: "the map filling" });
  }

  function setStatus(status, generation, total, error) {
    const filled = cells.size;
    const all = view ? view.axes.reduce((n, a) => n * a.cells, 1) : 0;
    statusEl.dataset.status = status || "";
    statusEl.dataset.generation = String(generation ?? "");
    statusEl.dataset.filled = String(filled);
    statusEl.className = `run-status ${status || ""}`;
    statusEl.textContent = `${status || "–"} · generation ${generation ?? "–"} of ${total ?? "–"} · ${filled} of ${all} cells${error ? ` · ${error}` : ""}`;
    stopBtn.disabled = status !== RUNNING;
    resumeBtn.disabled = !(status === "stopped" || status === "done");
    if (status === "failed" && error) ctx.showError(new Error(`the map failed: ${error}`));
  }

  // ---- the run ---------------------------------------------------------------------------------
  async function render(s) {
    await loadChoices();
    const changed = !session || session.id !== s.id;
    session = s;
    if (changed) {
      cells = new Map();
      rows = new Map();
      view = null;
      drawGrid();
      fillForm(s.state && s.state.design);
    }
    openEvents(s.id);
    const m = await ctx.act(() => api.map(s.id));
    if (!m || !session || session.id !== s.id) return false;
    applyMap(m);
    return true;
  }

  function applyMap(m) {
    view = m;
    cells = new Map(m.cells.map((c) => [c.cell, c]));
    for (const r of m.rows || []) rows.set(r.generation, r);
    drawGrid();
    drawChart_();
    setStatus(m.status, m.generation, m.generations, m.error);
    if (m.status !== RUNNING) closeEvents();
  }

  function openEvents(id) {
    // a stream still open goes on; one closed or reconnecting (the studio was away) starts again
    if (es && esSession === id && es.readyState === EventSource.OPEN) return;
    closeEvents();
    esSession = id;
    es = follow(ctx, api.eventsUrl(id), id, {
      map: (g) => {
        if (!session || session.id !== id || !view) return;
        for (const c of g.cells || []) updateCell(c);
        if (g.filled !== undefined) rows.set(g.generation, g);
        drawChart_();
        setStatus(g.status || RUNNING, g.generation, view.generations, null);
        ctx.refreshPopulation();
      },
      status: async (st) => {
        if (!session || session.id !== id) return;
        if (st.status && st.status !== RUNNING) closeEvents();
        const m = await ctx.act(() => api.map(id));
        if (m && session && session.id === id) applyMap(m);
      },
    }, "map");
  }

  function closeEvents() {
    if (es) es.close();
    es = null;
    esSession = null;
  }

  async function start() {
    const d = await ctx.act(() => design());
    if (!d) return;
    const made = await ctx.act(() => api.createSession({ mode: "map", map: d }));
    if (made) await ctx.sessionCreated(made);
  }

  async function stop() {
    if (!session) return;
    const s = await ctx.act(() => api.mapStop(session.id));
    if (s) await ctx.setSession(s);
  }

  async function resume() {
    if (!session || !view) return;
    const s = await ctx.act(() => api.mapResume(session.id, Math.min(100000, Math.max(view.generations, view.generation) * 2)));
    if (s) {
      await ctx.setSession(s);
      openEvents(s.id);
    }
  }

  return {
    name: "map",
    formHolder,
    workspace,
    alwaysShowWorkspace: true,
    render,
    // the form on the left is the new map's, and Start makes it
    newSessionForm: () => null,
    show() {
      loadChoices();
      drawChart_();
    },
    hide() {},
    reset() {
      closeEvents();
      session = null;
      view = null;
      cells = new Map();
      rows = new Map();
      drawGrid();
      drawChart_();
      setStatus(null, null, null, null);
    },
    onKey() {
      return false;
    },
  };
}
