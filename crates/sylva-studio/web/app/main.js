// The studio page: modes as tabs, sessions, undo and redo, the population and the history of the
// open session, the plant panel, the lineage view, and the message area where every error from
// the studio is shown.
//
// The modes are the studio's list (`GET /api/modes`): a tab and a view for each, in its order,
// made by the default export of the mode's page module, imported when the page starts. This
// page names no mode: it opens in the first one listed.

import { api, onBusy } from "./api.js";
import { h, clear, summarize } from "./dom.js";
import { stats } from "./stats.js";
import { createDetail } from "./detail.js";
import { createLineage } from "./lineage.js";
import { onReconnect } from "./connection.js";
import { thumb } from "./thumbs.js";

/** The modes' names, in the order of their tabs (filled from the studio's list). */
const MODES = [];
const $ = (id) => document.getElementById(id);

const ui = {
  sessionSelect: $("session-select"),
  newSession: $("new-session"),
  undo: $("undo"),
  redo: $("redo"),
  busy: $("busy"),
  message: $("message"),
  messageText: $("message-text"),
  population: $("population"),
  populationTotal: $("population-total"),
  populationMore: $("population-more"),
  history: $("history"),
};

// ---- messages ----------------------------------------------------------------------------------

let infoTimer = 0;
function showError(err, context = "") {
  console.error(context, err);
  const field = err && err.field ? ` (field: ${err.field})` : "";
  const status = err && err.status ? ` [${err.status}]` : "";
  const text = `${context ? context + ": " : ""}${err && err.message ? err.message : String(err)}${field}${status}`;
  ui.message.dataset.kind = "error";
  // a request the studio never answered: cleared when the studio is back
  ui.message.dataset.offline = err && err.offline ? "true" : "false";
  ui.messageText.textContent = text;
  ui.message.hidden = false;
  clearTimeout(infoTimer);
}
function showInfo(text) {
  if (!ui.message.hidden && ui.message.dataset.kind === "error") return;
  ui.message.dataset.kind = "info";
  ui.messageText.textContent = text;
  ui.message.hidden = false;
  clearTimeout(infoTimer);
  infoTimer = setTimeout(() => {
    if (ui.message.dataset.kind === "info") ui.message.hidden = true;
  }, 4000);
}
function clearMessage() {
  ui.message.hidden = true;
  ui.messageText.textContent = "";
  delete ui.message.dataset.kind;
}
$("message-close").addEventListener("click", clearMessage);
window.addEventListener("unhandledrejection", (e) => showError(e.reason, "unexpected"));
window.addEventListener("error", (e) => showError(e.error || new Error(e.message), "script error"));
// a new click on a button starts a new action: the last error has been read
document.addEventListener(
  "click",
  (e) => {
    const b = e.target.closest && e.target.closest("button");
    if (b && b.id !== "message-close" && ui.message.dataset.kind === "error") clearMessage();
  },
  true,
);
onBusy((n) => (ui.busy.hidden = n === 0));

// ---- the context the modes share ---------------------------------------------------------------

const ctx = {
  models: [],
  /** The studio's modes as `GET /api/modes` lists them. */
  modeList: [],
  examples: [],
  sessions: [],
  session: null,
  mode: null,
  /** Fields (paths) the plant panel locked: Mutate and Cross keep them as the parent has them. */
  locked: new Set(),
  showError,
  showInfo,
  /** Runs `fn`, showing any error it throws; returns its result, or undefined on error. */
  async act(fn) {
    try {
      return await fn();
    } catch (err) {
      showError(err);
      return undefined;
    }
  },
  setSession,
  openSession,
  sessionCreated,
  refreshSessions,
  refreshPopulation,
  openPlant: (id) => detail.open(id),
  openLineage: (id) => lineage.open(id),
};
stats.session = () => ctx.session;

/** Each mode's view, by name, as its page module made it. */
const modes = {};
const detail = createDetail(ctx, $("detail"));
const lineage = createLineage(ctx, $("lineage"));
const lastByMode = {};

// ---- sessions ----------------------------------------------------------------------------------

async function refreshSessions() {
  const list = await ctx.act(() => api.sessions());
  if (list) ctx.sessions = list;
  fillSessionSelect();
}

function fillSessionSelect() {
  const sel = ui.sessionSelect;
  clear(sel);
  const mine = ctx.sessions.filter((s) => s.mode === ctx.mode);
  sel.append(h("option", { value: "" }, mine.length ? "— choose a session —" : "— no sessions yet —"));
  for (const s of mine) {
    sel.append(
      h("option", { value: String(s.id) },
        `#${s.id} ${s.title || s.mode}${s.model ? ` · ${s.model}` : ""} · ${s.steps ?? 0} steps`),
    );
  }
  sel.value = ctx.session && ctx.session.mode === ctx.mode ? String(ctx.session.id) : "";
}

ui.sessionSelect.addEventListener("change", () => {
  const id = ui.sessionSelect.value;
  if (id) openSession(id);
});

async function openSession(id) {
  const s = await ctx.act(() => api.session(id));
  if (s) return setSession(s);
  return false;
}

async function sessionCreated(s) {
  await refreshSessions();
  const r = await setSession(s);
  showInfo(`session #${s.id} started`);
  return r;
}

/** Shows session `s` (an answer of the studio) in its mode; resolves when it is drawn. */
async function setSession(s) {
  if (!s || typeof s !== "object" || s.id === undefined) {
    showError(new Error("the studio answered without a session"));
    return false;
  }
  const changed = !ctx.session || ctx.session.id !== s.id;
  ctx.session = s;
  lastByMode[s.mode] = s.id;
  if (ctx.mode !== s.mode) switchMode(s.mode, { open: false });
  showWorkspace(s.mode);
  if (!ctx.sessions.some((x) => x.id === s.id)) await refreshSessions();
  else {
    const entry = ctx.sessions.find((x) => x.id === s.id);
    if (entry) {
      entry.steps = (s.history || []).length;
      // a match's trials choose its model after it started
      entry.model = s.model;
    }
    fillSessionSelect();
  }
  setHash(s.mode, s.id);
  ui.undo.disabled = !s.can_undo;
  ui.redo.disabled = !s.can_redo;
  renderHistory(s);
  if (changed) populationLimit = 100;
  const mode = modes[s.mode];
  if (!mode) {
    showError(new Error(`unknown mode "${s.mode}"`));
    return false;
  }
  const drawn = mode.render(s);
  refreshPopulation();
  return drawn;
}

function renderHistory(s) {
  clear(ui.history);
  for (const step of s.history || []) {
    ui.history.append(
      h("li", { class: step.undone ? "undone" : "", testid: "history-item", dataset: { seq: String(step.seq) }, title: JSON.stringify(step.action) },
        h("span", { class: "seq" }, `${step.seq}.`), " ", describeAction(step.action), step.undone ? " (undone)" : ""),
    );
  }
  ui.history.scrollTop = ui.history.scrollHeight;
}

function describeAction(a) {
  if (a === null || a === undefined) return "–";
  if (typeof a !== "object") return String(a);
  for (const k of ["action", "op", "type", "kind"]) {
    if (typeof a[k] === "string") {
      const rest = { ...a };
      delete rest[k];
      const s = summarize(rest, 70);
      return s ? `${a[k]}: ${s}` : a[k];
    }
  }
  const keys = Object.keys(a);
  if (keys.length === 1 && a[keys[0]] && typeof a[keys[0]] === "object") return `${keys[0]}: ${summarize(a[keys[0]], 70)}`;
  return summarize(a, 80);
}

// ---- population --------------------------------------------------------------------------------

let populationLimit = 100;
let populationBusy = null;
let populationDirty = false;

async function refreshPopulation() {
  if (populationBusy) {
    populationDirty = true;
    return populationBusy;
  }
  populationBusy = (async () => {
    do {
      populationDirty = false;
      await loadPopulation();
    } while (populationDirty);
  })();
  try {
    await populationBusy;
  } finally {
    populationBusy = null;
  }
}

async function loadPopulation() {
  const s = ctx.session;
  if (!s) {
    clear(ui.population);
    ui.populationTotal.textContent = "";
    ui.populationMore.hidden = true;
    return;
  }
  const own = modes[s.mode] && modes[s.mode].population;
  if (own) {
    // a mode whose population is not (only) archived plants lists it itself
    const list = own(populationLimit);
    clear(ui.population);
    ui.populationTotal.textContent = `(${list.total})`;
    for (const item of list.items) {
      ui.population.append(
        h("li", {},
          h("button", {
            class: "pop-item" + (item.shown ? " shown" : ""),
            testid: "population-item",
            dataset: item.dataset,
            title: item.title || "",
            onclick: item.open,
          },
          h("span", { class: "pop-text" }, h("b", {}, item.label), " ", h("span", { class: "dim" }, item.sub || "")))),
      );
    }
    ui.populationMore.hidden = !(list.total > list.items.length);
    return;
  }
  const list = await ctx.act(() => api.plants(s.id, 0, Math.min(populationLimit, 1000)));
  if (!list || !ctx.session || ctx.session.id !== s.id) return;
  const inGrid = new Set(((s.state && s.state.grid) || []).map((g) => g.plant));
  const specimens = new Set(((s.state && s.state.specimens) || []).map((g) => g.plant));
  clear(ui.population);
  ui.populationTotal.textContent = `(${list.total})`;
  for (const p of list.plants || []) {
    const shown = inGrid.has(p.id) || specimens.has(p.id);
    ui.population.append(
      h("li", {},
        h("button", {
          class: "pop-item" + (shown ? " shown" : "") + (detail.current && detail.current.id === p.id ? " current" : ""),
          testid: "population-item",
          dataset: { plant: String(p.id) },
          title: shown ? "on screen now" : "",
          onclick: () => detail.open(p.id),
        },
        thumb(api.pngUrl(p.id, "48x48"), { width: 48, height: 48, alt: "" }),
        h("span", { class: "pop-text" },
          h("b", {}, `#${p.id}`), " ", p.operator || "",
          h("span", { class: "dim" }, (p.parents && p.parents.length ? ` ← ${p.parents.map((x) => "#" + x).join(" ")}` : "") + ` · seed ${p.seed}`))),
      ),
    );
  }
  ui.populationMore.hidden = !(list.total > (list.plants || []).length && populationLimit < 1000);
}
ui.populationMore.addEventListener("click", () => {
  populationLimit = Math.min(populationLimit + 100, 10000);
  refreshPopulation();
});

// ---- modes ---------------------------------------------------------------------------------------

function showWorkspace(mode) {
  const m = modes[mode];
  clear(m.formHolder);
  m.formHolder.hidden = true;
  m.workspace.hidden = false;
}

function showNewSessionForm(mode) {
  const m = modes[mode];
  const hasSession = ctx.session && ctx.session.mode === mode;
  const form = m.newSessionForm({
    cancel: hasSession ? () => showWorkspace(mode) : null,
  });
  if (!form) {
    // the mode's workspace is its own form (design): leave the open session
    if (hasSession) {
      ctx.session = null;
      m.reset();
      afterSessionClosed(mode);
    }
    showWorkspace(mode);
    return;
  }
  clear(m.formHolder);
  m.formHolder.append(form);
  m.formHolder.hidden = false;
  m.workspace.hidden = true;
}

function afterSessionClosed(mode) {
  ui.undo.disabled = ui.redo.disabled = true;
  clear(ui.history);
  refreshPopulation();
  fillSessionSelect();
  setHash(mode, null);
}

/**
 * Makes a tab and a view for each mode the studio lists, each view by the default export of
 * the mode's page module (`export default function (ctx, root)`). A module that fails to load
 * is reported and its mode left out; the others work.
 */
async function loadModes(list) {
  const roots = list.map((m) => {
    const root = h("section", { class: "mode-view", id: `view-${m.name}`, dataset: { view: m.name }, hidden: true });
    $("main").append(root);
    return root;
  });
  const pages = await Promise.allSettled(list.map((m) => import(m.page)));
  list.forEach((m, i) => {
    const page = pages[i];
    const make = page.status === "fulfilled" ? page.value.default : null;
    if (typeof make !== "function") {
      roots[i].remove();
      showError(page.reason || new Error(`${m.page} has no default export making its view`), `the ${m.label} mode`);
      return;
    }
    modes[m.name] = make(ctx, roots[i]);
    MODES.push(m.name);
    const tab = h("button", { role: "tab", testid: `mode-${m.name}`, title: m.hint, dataset: { mode: m.name } }, m.label);
    tab.addEventListener("click", () => {
      // the plant panel belongs to what was on screen; another mode gets the room
      if (m.name !== ctx.mode) detail.close();
      switchMode(m.name);
    });
    $("modes").append(tab);
  });
}

/** Shows mode `mode`; with `open`, opens its last (or newest) session or the new-session form. */
function switchMode(mode, { open = true } = {}) {
  if (!MODES.includes(mode)) mode = MODES[0];
  const previous = ctx.mode;
  ctx.mode = mode;
  for (const b of document.querySelectorAll(".modes [data-mode]")) {
    const on = b.dataset.mode === mode;
    b.classList.toggle("active", on);
    b.setAttribute("aria-selected", on ? "true" : "false");
  }
  for (const m of MODES) $(`view-${m}`).hidden = m !== mode;
  if (previous && previous !== mode) modes[previous].hide();
  modes[mode].show();
  fillSessionSelect();
  if (!open) return;
  if (ctx.session && ctx.session.mode === mode) return;
  const id = lastByMode[mode] ?? (ctx.sessions.find((s) => s.mode === mode) || {}).id;
  if (id !== undefined) {
    openSession(id);
  } else {
    ctx.session = null;
    modes[mode].reset();
    afterSessionClosed(mode);
    showNewSessionForm(mode);
  }
}

ui.newSession.addEventListener("click", () => showNewSessionForm(ctx.mode));

// ---- undo and redo -------------------------------------------------------------------------------

async function undoRedo(which) {
  const s0 = ctx.session;
  if (!s0) return;
  const s = await ctx.act(() => (which === "undo" ? api.undo(s0.id) : api.redo(s0.id)));
  if (s) await setSession(s);
}
ui.undo.addEventListener("click", () => undoRedo("undo"));
ui.redo.addEventListener("click", () => undoRedo("redo"));

document.addEventListener("keydown", (e) => {
  const t = e.target;
  const typing = t && (t.isContentEditable || ["INPUT", "TEXTAREA", "SELECT"].includes(t.tagName));
  if (e.key === "Escape") {
    if (lineage.isOpen) lineage.close();
    else if (!$("detail").hidden) detail.close();
    return;
  }
  if (typing) return;
  const mod = e.ctrlKey || e.metaKey;
  if (mod && !e.altKey && (e.key === "z" || e.key === "Z")) {
    e.preventDefault();
    undoRedo(e.shiftKey ? "redo" : "undo");
    return;
  }
  if (mod && !e.altKey && (e.key === "y" || e.key === "Y")) {
    e.preventDefault();
    undoRedo("redo");
    return;
  }
  if (lineage.isOpen) return;
  if (modes[ctx.mode] && modes[ctx.mode].onKey(e)) e.preventDefault();
});

// ---- the address: #/mode/session ---------------------------------------------------------------

let settingHash = false;
function setHash(mode, id) {
  const want = id === null || id === undefined ? `#/${mode}` : `#/${mode}/${id}`;
  if (location.hash === want) return;
  settingHash = true;
  history.replaceState(null, "", `${location.pathname}${location.search}${want}`);
  settingHash = false;
}
function parseHash() {
  const m = location.hash.match(/^#\/(\w+)(?:\/(\d+))?/);
  return m ? { mode: m[1], id: m[2] } : { mode: null, id: null };
}
window.addEventListener("hashchange", () => {
  if (settingHash) return;
  navigate();
});
async function navigate() {
  const { mode, id } = parseHash();
  if (id) {
    const ok = await openSession(id);
    if (ok !== false && ctx.session) return;
  }
  switchMode(mode);
}

// ---- a studio that was away -------------------------------------------------------------------

// Back after the connection was lost: the sessions and the open one are read again, which
// follows its runs' event streams again.
onReconnect(async () => {
  if (ui.message.dataset.kind === "error" && ui.message.dataset.offline === "true") clearMessage();
  showInfo("the studio answers again");
  await refreshSessions();
  if (ctx.session) await openSession(ctx.session.id);
});

// ---- start ---------------------------------------------------------------------------------------

async function init() {
  const [list, models, examples] = await Promise.all([
    ctx.act(() => api.modes()),
    ctx.act(() => api.models()),
    ctx.act(() => api.examples()),
    refreshSessions(),
  ]);
  ctx.models = models || [];
  ctx.modeList = list || [];
  ctx.examples = examples || [];
  if (list) await ctx.act(() => loadModes(list));
  if (MODES.length === 0) return;
  await navigate();
  stats.ready = true;
  document.body.dataset.ready = "true";
  document.body.dataset.connection ??= "ok";
}
init();
