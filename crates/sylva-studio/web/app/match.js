// Match mode: design from a picture. Drop a picture of the tree the scene needs (dark ink on a
// light background, a photo against the sky, or a cut-out), choose a model or let the studio
// try each, start, and watch the best plant's outline come over the target generation by
// generation. Each generation's best is archived: open it to branch it into a breeding
// session or export it with wind and levels of detail. Runs go on in the server; the page
// follows them through server-sent events. An auto match tries each model first: while it
// does, the status says which model is on trial, its generation and best IoU, the overlay
// shows that model's best outline so far, and the chart draws each model's trial.

import { api, seedValue } from "./api.js";
import { h, clear, field, num, readNumber, fmtNum } from "./dom.js";
import { drawChart } from "./chart.js";
import { follow } from "./follow.js";

const RUNNING = "running";
// The studio takes requests of up to 1 MiB: larger pictures are scaled down in the page.
const MAX_BYTES = 700_000;
const MAX_SIDE = 1024;

export default function createMatchMode(ctx, root) {
  // ---- the form ------------------------------------------------------------------------------
  const file = h("input", { type: "file", accept: "image/png,image/jpeg", testid: "match-file" });
  const drop = h("div", { class: "match-drop", testid: "match-drop" }, "Drop a picture here, or choose one:", h("br"), file);
  const preview = h("img", { class: "match-preview", testid: "match-preview", alt: "", hidden: true });
  const model = h("select", { testid: "match-model" });
  const generations = num("match-generations", 100, { min: 1, max: 10000, step: 1, width: "6em" });
  const population = num("match-population", 100, { min: 2, max: 5000, step: 1, width: "6em" });
  const seed = num("match-seed", 1, { min: 0, step: 1, width: "7em" });
  const prune = h("input", { type: "checkbox", testid: "match-topiary", checked: false });
  const startBtn = h("button", { class: "primary", testid: "match-start", onclick: () => start() }, "Start");
  const stopBtn = h("button", { testid: "match-stop", onclick: () => stop() }, "Stop");
  const resumeBtn = h("button", { testid: "match-resume", title: "Go on: twice the generations asked so far", onclick: () => resume() }, "Resume");
  let picture = null; // the chosen picture as a data: URL

  const form = h(
    "div",
    { class: "design-form match-form", testid: "match-form" },
    h("h3", {}, "Target"),
    drop,
    preview,
    h("p", { class: "hint" }, "The outline of the tree you want: dark on light, a photo against the sky, or a cut-out. It is matched from the front and the side."),
    h("h3", {}, "Run"),
    field("model", model, "auto tries each model for a tenth of the run and goes on with the best"),
    h("div", { class: "weights" },
      field("generations", generations, "1 to 10000"),
      field("population", population, "2 to 5000"),
      field("seed", seed)),
    h("label", { title: "Cut what would show outside the outline, as a topiary is clipped; off: the outline is a goal only" },
      prune, " topiary: clip to the outline"),
    h("div", { class: "buttons sticky" }, startBtn, stopBtn, resumeBtn),
  );

  // ---- the target, the outline and the figures -------------------------------------------------
  const statusEl = h("div", { class: "run-status", testid: "match-status" }, "no match");
  const target = h("img", { class: "match-target", testid: "match-target", alt: "the target" });
  const overlay = h("img", { class: "match-overlay", testid: "match-overlay", alt: "the best plant's outline over the target" });
  const targetFigure = shownWhenLoaded(target, "target");
  const overlayFigure = shownWhenLoaded(overlay, "blue: target · orange: the best plant · green: both");
  const openBest = h("button", { testid: "match-open-best", title: "Open the best plant: branch it, export it", onclick: () => best !== null && ctx.openPlant(best) }, "Open the best plant");
  const chart = h("canvas", { class: "chart", testid: "match-chart" });
  const right = h("div", { class: "design-right match-right" },
    h("div", { class: "toolbar" }, statusEl, openBest),
    h("div", { class: "match-pictures" }, targetFigure, overlayFigure),
    h("div", { class: "charts" }, chart));
  const workspace = h("div", { class: "workspace design match" }, form, right);
  const formHolder = h("div", { class: "form-holder" });
  root.append(formHolder, workspace);

  let session = null;
  let run = null;
  let rows = new Map();
  let trials = new Map(); // an auto match's trial generations, by "model generation", in the order bred
  let begun = null; // the trial begun and not yet bred a generation: {model, runoff}
  let best = null; // the plant shown
  let es = null;
  let esSession = null;
  let listed = false; // whether the session list has been read since the trials chose

  function fillModels() {
    if (model.options.length) return;
    model.append(h("option", { value: "auto" }, "auto (try each)"));
    for (const m of ctx.models) model.append(h("option", { value: m.name }, m.title || m.name));
  }

  // ---- the picture -----------------------------------------------------------------------------
  async function choose(f) {
    if (!f) return;
    const url = await ctx.act(() => fitted(f));
    if (!url) return;
    picture = url;
    preview.src = url;
    preview.hidden = false;
  }
  file.addEventListener("change", () => choose(file.files[0]));
  drop.addEventListener("dragover", (e) => {
    e.preventDefault();
    drop.classList.add("over");
  });
  drop.addEventListener("dragleave", () => drop.classList.remove("over"));
  drop.addEventListener("drop", (e) => {
    e.preventDefault();
    drop.classList.remove("over");
    choose(e.dataTransfer.files[0]);
  });

  /** The picture as a data: URL the studio takes: as it is when small, else scaled down. */
  async function fitted(f) {
    if (!/^image\/(png|jpeg)$/.test(f.type)) {
      const e = new Error(`a target must be a PNG or JPEG picture, not ${f.type || "this file"}`);
      e.field = "match.picture";
      throw e;
    }
    const url = await new Promise((resolve, reject) => {
      const r = new FileReader();
      r.onload = () => resolve(r.result);
      r.onerror = () => reject(r.error);
      r.readAsDataURL(f);
    });
    if (f.size <= MAX_BYTES) return url;
    const img = new Image();
    await new Promise((resolve, reject) => {
      img.onload = resolve;
      img.onerror = () => reject(new Error("the picture could not be read"));
      img.src = url;
    });
    const k = Math.min(1, MAX_SIDE / Math.max(img.naturalWidth, img.naturalHeight));
    const canvas = h("canvas", {});
    canvas.width = Math.max(1, Math.round(img.naturalWidth * k));
    canvas.height = Math.max(1, Math.round(img.naturalHeight * k));
    canvas.getContext("2d").drawImage(img, 0, 0, canvas.width, canvas.height);
    return canvas.toDataURL("image/png");
  }

  // ---- the run ---------------------------------------------------------------------------------
  async function render(s) {
    fillModels();
    const changed = !session || session.id !== s.id;
    session = s;
    if (changed) {
      rows = new Map();
      trials = new Map();
      begun = null;
      best = null;
      listed = false;
      clearPicture(overlay);
      target.src = api.matchPictureUrl(s.id);
    }
    openEvents(s.id);
    const r = await ctx.act(() => api.matchRun(s.id));
    if (!r || !session || session.id !== s.id) return false;
    applyRun(r);
    return true;
  }

  function applyRun(r) {
    run = r;
    for (const row of r.rows || []) rows.set(row.generation, row);
    for (const t of r.trials || []) noteTrial(t);
    const last = [...rows.values()].sort((a, b) => b.generation - a.generation)[0];
    if (last && last.plant !== undefined && last.plant !== null) showBest(last.plant, last);
    else showTrial();
    drawChart_();
    setStatus(r.status, r.generation, r.generations, r.error);
    noteModel();
    if (r.status !== RUNNING) closeEvents();
  }

  // A trial generation (from the run's view or a `trial` event), kept in the order bred: a
  // generation bred again (the studio restarted during its trial) moves to the end.
  function noteTrial(t) {
    const key = `${t.model} ${t.generation}`;
    trials.delete(key);
    trials.set(key, t);
    if (begun && begun.model === t.model && begun.runoff === t.runoff) begun = null;
  }

  /** The trial generation bred last, while the run has none of its own yet. */
  function currentTrial() {
    if (rows.size || !trials.size) return null;
    return [...trials.values()][trials.size - 1];
  }

  // While the trials go on, the overlay shows the best outline of the model on trial.
  function showTrial() {
    const t = currentTrial();
    if (t && t.plant !== undefined && t.plant !== null) showBest(t.plant, { best_terms: [t.iou] });
  }

  // An auto match starts under the first model and names the one its trials chose when its
  // first generation is made: the session list is read again then, to name it.
  function noteModel() {
    if (listed || !session || !(session.state && session.state.auto) || rows.size === 0) return;
    listed = true;
    ctx.refreshSessions();
  }

  function showBest(plant, row) {
    if (plant === best) return;
    best = plant;
    overlay.src = api.matchOverlayUrl(session.id, plant);
    overlay.dataset.plant = String(plant);
    openBest.disabled = false;
    if (row) statusEl.dataset.iou = String((row.best_terms || [])[0] ?? row.best);
  }

  function drawChart_() {
    const sorted = [...rows.values()].sort((a, b) => a.generation - b.generation);
    // each model's trials (first trial and run-off), a line of its own under the run's
    const byModel = new Map();
    for (const t of trials.values()) {
      if (!byModel.has(t.model)) byModel.set(t.model, []);
      byModel.get(t.model).push([t.generation, t.iou]);
    }
    const tried = [...byModel.entries()].map(([m, points], i) => ({
      name: `trial: ${m}`,
      points: points.sort((a, b) => a[0] - b[0]),
      color: TRIAL_COLOURS[i % TRIAL_COLOURS.length],
    }));
    drawChart(chart, [
      { name: "best IoU × stem factor", points: sorted.map((r) => [r.generation, (r.best_terms || [])[0] ?? r.best]), color: "#7fd18b", width: 2 },
      { name: "mean score", points: sorted.map((r) => [r.generation, r.mean]), color: "#e0b85c" },
      ...tried,
    ], { title: tried.length ? "the outline: best and mean, and each model's trial" : "the outline: best and mean" });
    chart.dataset.trials = String(byModel.size);
  }

  function setStatus(status, generation, total, error) {
    statusEl.dataset.status = status || "";
    statusEl.dataset.generation = String(generation ?? "");
    statusEl.className = `run-status ${status || ""}`;
    const last = [...rows.values()].sort((a, b) => b.generation - a.generation)[0];
    const score = last ? ` · best ${fmtNum(last.best, 3)}` : "";
    const t = currentTrial();
    const b = rows.size || status !== RUNNING ? null : begun;
    statusEl.dataset.trial = b ? b.model : t ? t.model : "";
    const where = b
      ? `${b.runoff ? "run-off" : "trial"}: ${b.model}, ${b.runoff ? "going on" : "making its first generation"}`
      : t
        ? `${t.runoff ? "run-off" : "trial"}: ${t.model}, generation ${t.generation}, IoU ${fmtNum(t.iou, 3)}`
        : `generation ${generation ?? "–"} of ${total ?? "–"}${score}`;
    statusEl.textContent = `${status || "–"} · ${where}${error ? ` · ${error}` : ""}`;
    stopBtn.disabled = status !== RUNNING;
    resumeBtn.disabled = !(status === "stopped" || status === "done");
    openBest.disabled = best === null;
    if (status === "failed" && error) ctx.showError(new Error(`the match failed: ${error}`));
  }

  function openEvents(id) {
    // a stream still open goes on; one closed or reconnecting (the studio was away) starts again
    if (es && esSession === id && es.readyState === EventSource.OPEN) return;
    closeEvents();
    esSession = id;
    es = follow(ctx, api.eventsUrl(id), id, {
      generation: async (g) => {
        if (!session || session.id !== id) return;
        // the first generation after the trials: the chosen model's trial generations
        // became the run's first, read again with the run
        const chosen = rows.size === 0 && trials.size > 0;
        rows.set(g.generation, g);
        if (g.plant !== undefined && g.plant !== null) showBest(g.plant, g);
        drawChart_();
        setStatus(g.status || RUNNING, g.generation, run?.generations, null);
        noteModel();
        ctx.refreshPopulation();
        if (chosen) {
          const r = await ctx.act(() => api.matchRun(id));
          if (r && session && session.id === id) applyRun(r);
        }
      },
      trial: (t) => {
        if (!session || session.id !== id) return;
        noteTrial(t);
        showTrial();
        drawChart_();
        setStatus(t.status || RUNNING, 0, run?.generations, null);
      },
      "trial-begun": (b) => {
        if (!session || session.id !== id) return;
        begun = { model: b.model, runoff: b.runoff };
        setStatus(RUNNING, 0, run?.generations, null);
      },
      status: async (st) => {
        if (!session || session.id !== id) return;
        if (st.status && st.status !== RUNNING) closeEvents();
        const r = await ctx.act(() => api.matchRun(id));
        if (r && session && session.id === id) applyRun(r);
      },
    }, "match");
  }

  function closeEvents() {
    if (es) es.close();
    es = null;
    esSession = null;
  }

  async function start() {
    const body = await ctx.act(() => {
      if (!picture) {
        const e = new Error("choose a picture of the target first");
        e.field = "match.picture";
        throw e;
      }
      return {
        mode: "match",
        match: {
          picture,
          model: model.value,
          generations: readNumber(generations, "match.generations"),
          population: readNumber(population, "match.population"),
          seed: seedValue(seed.value, "match.seed"),
          topiary: prune.checked,
        },
      };
    });
    if (!body) return;
    const made = await ctx.act(() => api.createSession(body));
    if (made) await ctx.sessionCreated(made);
  }

  async function stop() {
    if (!session) return;
    const s = await ctx.act(() => api.matchStop(session.id));
    if (s) await ctx.setSession(s);
  }

  async function resume() {
    if (!session || !run) return;
    const s = await ctx.act(() => api.matchResume(session.id, Math.min(10000, Math.max(run.generations, run.generation) * 2)));
    if (s) {
      await ctx.setSession(s);
      openEvents(s.id);
    }
  }

  return {
    name: "match",
    formHolder,
    workspace,
    alwaysShowWorkspace: true,
    render,
    // the form on the left is the new match's, and Start makes it
    newSessionForm: () => null,
    show() {
      fillModels();
      drawChart_();
    },
    hide() {},
    reset() {
      closeEvents();
      session = null;
      run = null;
      rows = new Map();
      trials = new Map();
      begun = null;
      best = null;
      clearPicture(target);
      clearPicture(overlay);
      drawChart_();
      setStatus(null, null, null, null);
    },
    onKey() {
      return false;
    },
  };
}

// Colours of the models' trial lines on the chart: muted, under the run's own.
const TRIAL_COLOURS = ["#6fb3e8", "#e07a6f", "#b994e6", "#5fd0c8", "#d98fc0", "#8aa0b8"];

/**
 * A figure of `img` with `caption`, hidden until the picture loads and again when it fails
 * or is taken away: no broken-image icon before a target is chosen or a plant is there.
 */
function shownWhenLoaded(img, caption) {
  const figure = h("figure", { hidden: true }, img, h("figcaption", {}, caption));
  img.addEventListener("load", () => (figure.hidden = false));
  img.addEventListener("error", () => (figure.hidden = true));
  return figure;
}

/** Takes a picture away, hiding its figure. */
function clearPicture(img) {
  img.removeAttribute("src");
  if (img.parentElement) img.parentElement.hidden = true;
}
