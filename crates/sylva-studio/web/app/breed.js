// Breed mode: PlantMaker's main window (Sipper et al., §2). Nine plants in a 3×3 grid, most
// dominant first, drawn by one renderer; pick two or more to Cross (with a dominance each) or
// one to Mutate (with a Depth), add random plants, examples or genome files.

import { api, seedValue } from "./api.js";
import { Stage, loadPlant } from "./viewer.js";
import { h, clear, field, num, readNumber } from "./dom.js";
import { stats } from "./stats.js";

const CELLS = 9;
const MAX_UPLOAD = 1024 * 1024;
/** The largest dominance the studio takes (its cross refuses more). */
const MAX_DOMINANCE = 1e6;

export default function createBreedMode(ctx, root) {
  const status = h("span", { class: "hint", testid: "breed-status" });
  const level = h(
    "select",
    { testid: "level", title: "Crossover level (Sipper et al., Figure 9)" },
    h("option", { value: "low" }, "low"),
    h("option", { value: "medium", selected: true }, "medium"),
    h("option", { value: "high" }, "high"),
  );
  level.value = "medium";
  const depthOut = h("output", { testid: "depth-value" }, "2");
  const depth = h("input", {
    type: "range",
    min: 1,
    max: 10,
    step: 1,
    value: "2",
    testid: "depth",
    title: "Depth: mutation probability 0.05·d per variable",
    oninput: () => (depthOut.textContent = depth.value),
  });
  const children = h("input", {
    type: "number",
    min: 1,
    max: 9,
    placeholder: "auto",
    testid: "children",
    style: { width: "4.5em" },
    title: "Offspring per step (empty: 9 − parents for a cross, 8 for a mutation)",
  });
  const crossBtn = h("button", { testid: "cross", class: "primary", onclick: () => cross() }, "Cross");
  const mutateBtn = h("button", { testid: "mutate", class: "primary", onclick: () => mutate() }, "Mutate");
  const addRandomN = num("add-random-count", 1, { min: 1, max: 9, width: "3.5em" });
  const addRandomBtn = h("button", { testid: "add-random", onclick: () => addRandom() }, "Add random");
  const exampleSelect = h("select", { testid: "example-select" });
  const addExamplesBtn = h("button", { testid: "add-examples", onclick: () => addExamples() }, "Add examples");
  const upload = h("input", {
    type: "file",
    multiple: true,
    testid: "upload",
    accept: ".json,.toml,.txt,.packed,.genome",
    onchange: () => uploadFiles(),
  });

  const controls = h(
    "div",
    { class: "toolbar" },
    h("div", { class: "group" }, field("Level", level), crossBtn),
    h("div", { class: "group" }, field("Depth", h("span", { class: "range" }, depth, depthOut)), mutateBtn),
    h("div", { class: "group" }, field("Children", children)),
    h("div", { class: "group" }, addRandomN, addRandomBtn),
    h("div", { class: "group" }, exampleSelect, addExamplesBtn),
    h("div", { class: "group" }, h("label", { class: "upload button" }, "Upload genomes…", upload)),
    status,
  );

  const canvas = h("canvas", { class: "stage-canvas", testid: "grid-canvas" });
  const gridEl = h("div", { class: "grid", testid: "grid" });
  const gridWrap = h("div", { class: "grid-wrap" }, canvas, gridEl);
  const workspace = h("div", { class: "workspace breed" }, controls, gridWrap);
  const formHolder = h("div", { class: "form-holder" });
  root.append(formHolder, workspace);

  let stage = null;
  const cells = [];
  let selected = []; // plant ids in the order they were picked
  const dominance = new Map(); // plant id -> input element value
  let renderToken = 0;
  let session = null;

  function ensureStage() {
    if (stage) return;
    stage = new Stage(canvas);
    for (let i = 0; i < CELLS; i++) {
      const label = h("div", { class: "cell-label" });
      const dom = h("input", {
        type: "number",
        min: 0,
        max: MAX_DOMINANCE,
        step: "any",
        value: "1",
        testid: `dominance-${i}`,
        class: "dominance",
        title: "Dominance of this parent: the more dominant, the more genes it gives",
      });
      const info = h("button", { class: "cell-info", testid: `cell-info-${i}`, title: "Show this plant's genome" }, "i");
      const domError = h("span", { class: "dom-error", testid: `dominance-error-${i}`, role: "alert", hidden: true });
      const el = h("div", { class: "cell", testid: `grid-cell-${i}`, dataset: { index: String(i) } }, label,
        h("div", { class: "cell-tools" }, domError, h("label", { class: "dom-label" }, "dominance ", dom), info));
      for (const c of [dom, info, domError]) {
        c.addEventListener("pointerdown", (e) => e.stopPropagation());
        c.addEventListener("pointerup", (e) => e.stopPropagation());
        c.addEventListener("wheel", (e) => e.stopPropagation());
      }
      dom.addEventListener("input", () => {
        if (cell.plant !== null) dominance.set(cell.plant, dom.value);
        showDominanceError(cell, "");
      });
      info.addEventListener("click", () => {
        if (cell.plant !== null) ctx.openPlant(cell.plant);
      });
      gridEl.append(el);
      const view = stage.addView(el);
      const cell = { el, label, dom, domError, view, plant: null };
      cells.push(cell);
      let down = null;
      el.addEventListener("pointerdown", (e) => {
        down = { x: e.clientX, y: e.clientY, t: performance.now(), button: e.button };
      });
      el.addEventListener("pointerup", (e) => {
        if (!down || down.button !== 0) return;
        const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
        down = null;
        if (moved < 5) toggle(cell, e);
      });
      el.addEventListener("dblclick", () => {
        if (cell.plant !== null) ctx.openPlant(cell.plant);
      });
    }
    stats.stages.breed = stage;
  }

  function toggle(cell, event) {
    if (cell.plant === null) return;
    const id = cell.plant;
    const i = selected.indexOf(id);
    if (i >= 0) selected.splice(i, 1);
    else selected.push(id);
    applySelection();
    stats.lastSelectMs = event ? performance.now() - event.timeStamp : 0;
  }

  function applySelection() {
    for (const cell of cells) {
      const on = cell.plant !== null && selected.includes(cell.plant);
      cell.el.classList.toggle("selected", on);
      if (on) cell.dom.value = dominance.get(cell.plant) ?? "1";
    }
    const n = selected.length;
    crossBtn.disabled = n < 2;
    mutateBtn.disabled = n !== 1;
    status.textContent = n === 0 ? "click plants to pick them" : `${n} picked`;
  }

  function fillExamples() {
    clear(exampleSelect);
    const model = session?.model;
    const list = (ctx.examples || []).filter((e) => !model || e.model === model);
    exampleSelect.append(h("option", { value: "*" }, `all ${model || ""} examples (${list.length})`));
    for (const e of list) exampleSelect.append(h("option", { value: e.name }, e.name));
    exampleSelect.disabled = addExamplesBtn.disabled = list.length === 0;
  }

  /**
   * Shows the session's grid; resolves once all of its plants are drawn. New plants are
   * loaded side by side and put in their cells together, so that the stage draws once rather
   * than once per arrival while the others are still being parsed (software WebGL draws on
   * the page's own thread).
   */
  async function render(s) {
    session = s;
    ensureStage();
    fillExamples();
    const grid = (s.state && s.state.grid) || [];
    const token = ++renderToken;
    const ids = grid.slice(0, CELLS).map((g) => g.plant);
    selected = selected.filter((id) => ids.includes(id));
    const loads = [];
    cells.forEach((cell, i) => {
      const entry = grid[i];
      const id = entry ? entry.plant : null;
      cell.el.dataset.plant = id === null ? "" : String(id);
      if (id === cell.plant) return;
      cell.plant = id;
      cell.el.classList.toggle("empty", id === null);
      if (id === null) {
        cell.label.textContent = "";
        cell.view.setContent(null);
        return;
      }
      cell.el.classList.add("loading");
      loads.push(
        loadPlant(id, cell.el).then(
          (object) => ({ cell, id, object }),
          (error) => ({ cell, id, error }),
        ),
      );
    });
    cells.forEach((cell, i) => {
      const entry = grid[i];
      if (entry) cell.label.textContent = `#${entry.plant} · dominance ${entry.dominance}`;
    });
    applySelection();
    const arrived = await Promise.all(loads);
    for (const { cell, id, object, error } of arrived) {
      if (cell.plant !== id) continue; // a later render took the cell
      cell.el.classList.remove("loading");
      if (error) {
        cell.view.setContent(null);
        cell.el.classList.add("failed");
        ctx.showError(error, `plant #${id}`);
      } else {
        cell.el.classList.remove("failed");
        cell.view.setContent(object, { plantId: id });
      }
    }
    const loaded = performance.now();
    await stage.nextPaint();
    if (token === renderToken) stats.lastRender = { loadedAt: loaded, paintedAt: performance.now(), plants: loads.length };
    return token === renderToken;
  }

  async function step(action) {
    if (!session) return;
    const t0 = performance.now();
    const s = await ctx.act(action);
    if (!s) return;
    const answered = performance.now();
    selected = [];
    const painted = await ctx.setSession(s);
    if (painted !== false) {
      const now = performance.now();
      const r = stats.lastRender || {};
      stats.lastPaintMs = now - t0;
      stats.lastStep = {
        answerMs: answered - t0,
        loadMs: (r.loadedAt ?? now) - answered,
        drawMs: now - (r.loadedAt ?? now),
        newPlants: r.plants ?? 0,
      };
      stats.paintCount += 1;
      stats.history.push(stats.lastPaintMs);
    }
  }

  function childrenCount() {
    if (children.value.trim() === "") return undefined;
    return readNumber(children, "children");
  }

  function showDominanceError(cell, message) {
    cell.dom.setCustomValidity(message);
    cell.domError.textContent = message;
    cell.domError.hidden = !message;
    cell.el.classList.toggle("dom-invalid", Boolean(message));
  }

  /**
   * A picked plant's dominance, read from its cell's control: a number from 0 to
   * MAX_DOMINANCE, or null once the control shows why not. An empty control, and one whose
   * text is no finite number (1e400: the browser then reports "" as its value), would
   * otherwise be sent as 0, silently leaving the plant out of the cross.
   */
  function readDominance(cell) {
    const text = cell.dom.value.trim();
    const n = Number(text);
    const unreadable = cell.dom.validity.badInput || text === "" || !Number.isFinite(n);
    const ok = !unreadable && n >= 0 && n <= MAX_DOMINANCE;
    const got = unreadable ? "it is empty or not a number" : `got ${text}`;
    showDominanceError(cell, ok ? "" : `Dominance: expected a number from 0 to ${MAX_DOMINANCE}; ${got}`);
    return ok ? n : null;
  }

  function cross() {
    // Every picked plant's control is checked (each shows its own message); none is sent
    // while one is wrong.
    const read = selected.map((id) => {
      const cell = cells.find((c) => c.plant === id);
      return cell ? readDominance(cell) : Number(dominance.get(id) ?? "1");
    });
    if (read.some((d) => d === null)) {
      status.textContent = `a dominance is not a number from 0 to ${MAX_DOMINANCE}: see the picked plants`;
      return;
    }
    const parents = selected.map((id, i) => ({ plant: id, dominance: read[i] }));
    return step(() => {
      const body = { parents, level: level.value };
      if (ctx.locked.size) body.locked = [...ctx.locked];
      const c = childrenCount();
      if (c !== undefined) body.children = c;
      return api.cross(session.id, body);
    });
  }

  function mutate() {
    const plant = selected[0];
    return step(() => {
      const body = { plant, depth: Number(depth.value) };
      if (ctx.locked.size) body.locked = [...ctx.locked];
      const c = childrenCount();
      if (c !== undefined) body.children = c;
      return api.mutate(session.id, body);
    });
  }

  function addRandom() {
    return step(() => api.add(session.id, { random: readNumber(addRandomN, "random") }));
  }

  function addExamples() {
    const model = session?.model;
    const names =
      exampleSelect.value === "*"
        ? (ctx.examples || []).filter((e) => e.model === model).map((e) => e.name)
        : [exampleSelect.value];
    return step(() => api.add(session.id, { examples: names }));
  }

  async function uploadFiles() {
    const files = [...upload.files];
    upload.value = "";
    if (files.length === 0) return;
    await step(async () => {
      const genomes = await readFiles(files);
      return api.add(session.id, { genomes });
    });
  }

  function newSessionForm({ cancel }) {
    const model = h("select", { testid: "new-model" });
    for (const m of ctx.models || []) {
      model.append(h("option", { value: m.name }, `${m.title || m.name} (${m.name})`));
    }
    const preferred = (ctx.models || []).find((m) => m.default);
    if (preferred) model.value = preferred.name;
    const startRandom = h("input", { type: "radio", name: "breed-start", value: "random", testid: "new-start-random" });
    const startExamples = h("input", { type: "radio", name: "breed-start", value: "examples", testid: "new-start-examples" });
    const startFiles = h("input", { type: "radio", name: "breed-start", value: "genomes", testid: "new-start-files" });
    const randomN = num("new-random", 9, { min: 1, max: 9, width: "3.5em" });
    const exampleList = h("div", { class: "checklist", testid: "new-examples" });
    const files = h("input", { type: "file", multiple: true, testid: "new-upload", onchange: () => (startFiles.checked = true) });
    const seed = num("new-seed", 1, { min: 0, step: 1, width: "7em" });
    function fillList() {
      clear(exampleList);
      const list = (ctx.examples || []).filter((e) => e.model === model.value);
      if (list.length === 0) exampleList.append(h("span", { class: "hint" }, "no examples for this model"));
      for (const e of list) {
        exampleList.append(
          h("label", {}, h("input", { type: "checkbox", value: e.name, checked: true, testid: `new-example-${e.name}`, onchange: () => (startExamples.checked = true) }), " ", e.name),
        );
      }
    }
    // The examples by default, as the server does when it has two or more: random PlantMaker
    // genomes grow plants of up to a million triangles.
    function pickDefault() {
      const n = (ctx.examples || []).filter((e) => e.model === model.value).length;
      if (n >= 2) startExamples.checked = true;
      else startRandom.checked = true;
    }
    model.addEventListener("change", () => {
      fillList();
      pickDefault();
    });
    fillList();
    pickDefault();
    const create = h("button", {
      class: "primary",
      testid: "new-create",
      onclick: async () => {
        const t0 = performance.now();
        const made = await ctx.act(async () => {
          const body = { mode: "breed", model: model.value, seed: seedValue(seed.value) };
          if (startRandom.checked) body.start = { random: readNumber(randomN, "random") };
          else if (startExamples.checked) {
            const names = [...exampleList.querySelectorAll("input:checked")].map((i) => i.value);
            body.start = { examples: names };
          } else body.start = { genomes: await readFiles([...files.files]) };
          return api.createSession(body);
        });
        const answered = performance.now();
        if (made && (await ctx.sessionCreated(made)) !== false) {
          const now = performance.now();
          const r = stats.lastRender || {};
          stats.lastCreatePaintMs = now - t0;
          stats.lastCreate = {
            answerMs: answered - t0,
            loadMs: (r.loadedAt ?? now) - answered,
            drawMs: now - (r.loadedAt ?? now),
            newPlants: r.plants ?? 0,
          };
          stats.createCount += 1;
        }
      },
    }, "Create session");
    return h(
      "div",
      { class: "new-session", testid: "new-session-form" },
      h("h2", {}, "New breeding session"),
      h("p", { class: "hint" }, "PlantMaker's main window: nine plants, most dominant first. Cross two or more, or mutate one."),
      field("Model", model),
      h("fieldset", {},
        h("legend", {}, "Start from"),
        h("label", { class: "row", title: "Random PlantMaker plants can be very large (up to a million triangles): slow to draw on software WebGL" }, startRandom, " random plants: ", randomN),
        h("label", { class: "row" }, startExamples, " the examples:"),
        exampleList,
        h("label", { class: "row" }, startFiles, " genome files: ", files),
      ),
      field("Seed", seed),
      h("div", { class: "buttons" }, create, cancel ? h("button", { testid: "new-cancel", onclick: cancel }, "Cancel") : null),
    );
  }

  return {
    name: "breed",
    formHolder,
    workspace,
    render,
    newSessionForm,
    show() {
      ensureStage();
      stage.requestRender();
    },
    hide() {},
    reset() {
      session = null;
      selected = [];
      for (const cell of cells) {
        cell.plant = null;
        cell.view.setContent(null);
        cell.label.textContent = "";
      }
    },
    onKey() {
      return false;
    },
    get stage() {
      return stage;
    },
  };
}

/** Reads genome files as text, refusing more than the studio's 1 MiB body limit. */
export async function readFiles(files) {
  if (files.length === 0) {
    const e = new Error("choose one or more genome files");
    e.field = "genomes";
    throw e;
  }
  let total = 0;
  for (const f of files) total += f.size;
  if (total > MAX_UPLOAD) {
    const e = new Error(`the files add up to ${total} bytes; the studio takes at most 1 MiB in one request`);
    e.field = "genomes";
    throw e;
  }
  return Promise.all(files.map((f) => f.text()));
}
