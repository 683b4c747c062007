// Family mode: Susinno's deciduous-evolution viewer. A population of binary trees under the
// genetic algorithm: `[` and `]` browse it (fittest first), `s` shows statistics, `g` runs one
// generation, `j` a batch, `J` sets the batch size. A chart of best and mean fitness grows.

import { api, seedValue } from "./api.js";
import { Stage, loadPlant } from "./viewer.js";
import { h, add, clear, field, num, readNumber, fmtNum } from "./dom.js";
import { drawChart } from "./chart.js";
import { stats as probes } from "./stats.js";

export default function createFamilyMode(ctx, root) {
  const genLabel = h("span", { class: "big", testid: "family-generation" }, "–");
  const batchLabel = h("span", { testid: "family-batch" }, "–");
  const memberLabel = h("span", { testid: "family-member" }, "–");
  const batchInput = num("family-batch-input", 10, { min: 1, max: 1000, step: 1, width: "5em" });
  const batchForm = h(
    "form",
    {
      class: "inline-form",
      hidden: true,
      testid: "family-batch-form",
      onsubmit: (e) => {
        e.preventDefault();
        setBatch();
      },
    },
    field("Generations per batch", batchInput),
    h("button", { type: "submit", testid: "family-batch-ok" }, "OK"),
    h("button", { type: "button", onclick: () => (batchForm.hidden = true) }, "Cancel"),
  );
  const btn = (testid, key, label, fn, title) =>
    h("button", { testid, title: `${title} (${key})`, onclick: fn }, h("kbd", {}, key), " ", label);
  const toolbar = h(
    "div",
    { class: "toolbar" },
    h("div", { class: "group" }, h("span", {}, "generation "), genLabel),
    h("div", { class: "group" },
      btn("family-prev", "[", "previous", () => browse(-1), "previous tree: one fitter"),
      memberLabel,
      btn("family-next", "]", "next", () => browse(1), "next tree: one less fit")),
    h("div", { class: "group" },
      btn("family-g", "g", "generation", () => run(1), "run one generation"),
      btn("family-j", "j", "batch", () => run(null), "run a batch of generations"),
      h("span", { class: "hint" }, "batch "), batchLabel,
      btn("family-J", "J", "batch size", () => askBatch(), "change the number of generations per batch")),
    btn("family-stats", "s", "statistics", () => toggleStats(), "show or hide the statistics"),
    batchForm,
  );
  const canvas = h("canvas", { class: "stage-canvas", testid: "family-canvas" });
  const viewEl = h("div", { class: "view-el" });
  const statsPanel = h("div", { class: "stats-panel", testid: "family-stats-panel", hidden: true });
  const wrap = h("div", { class: "view-wrap family-view" }, canvas, viewEl, statsPanel);
  const chart = h("canvas", { class: "chart", testid: "family-chart" });
  const workspace = h("div", { class: "workspace family" }, toolbar, h("div", { class: "split" }, wrap, h("div", { class: "chart-box" }, chart)));
  const formHolder = h("div", { class: "form-holder" });
  root.append(formHolder, workspace);

  let stage = null;
  let view = null;
  let session = null;
  let index = 0;
  let memberKey = "";
  let statsData = null;
  let memberToken = 0;
  let memberPlant = null;

  function ensureStage() {
    if (stage) return;
    stage = new Stage(canvas);
    view = stage.addView(viewEl, { detail: true });
    probes.stages.family = stage;
    new ResizeObserver(() => drawStats()).observe(chart);
  }

  async function render(s) {
    session = s;
    ensureStage();
    const st = s.state || {};
    const members = st.members || [];
    genLabel.textContent = String(st.generation ?? "–");
    batchLabel.textContent = String(st.batch ?? "–");
    if (st.batch) batchInput.value = st.batch;
    if (index >= members.length) index = Math.max(0, members.length - 1);
    const statsP = loadStats();
    const memberP = showMember();
    const [a, b] = await Promise.all([statsP, memberP]);
    return a !== false && b !== false;
  }

  async function loadStats() {
    const id = session.id;
    const data = await ctx.act(() => api.stats(id));
    if (!data || !session || session.id !== id) return false;
    statsData = data;
    drawStats();
    renderStatsPanel();
    return true;
  }

  function drawStats() {
    if (!statsData) return;
    const gens = statsData.generations || [];
    drawChart(chart, [
      { name: "best", points: gens.map((g) => [g.generation, g.best]), color: "#7fd18b", width: 2 },
      { name: "mean", points: gens.map((g) => [g.generation, g.mean]), color: "#e0b85c" },
    ], { title: "fitness per generation" });
  }

  async function showMember() {
    const st = session.state || {};
    const members = st.members || [];
    const m = members[index];
    memberLabel.textContent = m ? `${index + 1} of ${members.length} · fitness ${fmtNum(m.fitness)}` : "no members";
    renderStatsPanel();
    if (!m) return true;
    const key = JSON.stringify([session.id, st.run, st.generation, index, m.index, m.fitness]);
    if (key === memberKey) return true;
    memberKey = key;
    const mine = ++memberToken;
    const sid = session.id;
    const answer = await ctx.act(() => api.member(sid, index));
    if (!answer || mine !== memberToken) return false;
    memberPlant = answer.plant;
    memberLabel.dataset.plant = String(answer.plant);
    try {
      const object = await loadPlant(answer.plant, viewEl);
      if (mine !== memberToken) return false;
      view.setContent(object, { plantId: answer.plant });
      await stage.nextPaint();
    } catch (err) {
      ctx.showError(err, `plant #${answer.plant}`);
      return false;
    }
    ctx.refreshPopulation();
    return true;
  }

  function renderStatsPanel() {
    if (statsPanel.hidden || !session) return;
    clear(statsPanel);
    const st = session.state || {};
    const members = st.members || [];
    const gens = statsData?.generations || [];
    const last = gens[gens.length - 1];
    const terms = statsData?.terms || [];
    const m = members[index];
    add(statsPanel,
      h("h3", {}, "Statistics"),
      h("table", { class: "facts" }, h("tbody", {},
        h("tr", {}, h("th", {}, "generation"), h("td", {}, String(st.generation ?? "–"))),
        h("tr", {}, h("th", {}, "population"), h("td", {}, String(members.length))),
        h("tr", {}, h("th", {}, "this tree"), h("td", {}, m ? `rank ${index + 1}, fitness ${fmtNum(m.fitness)}${memberPlant !== null ? `, plant #${memberPlant}` : ""}` : "–")),
        last ? h("tr", {}, h("th", {}, "best"), h("td", {}, fmtNum(last.best))) : null,
        last ? h("tr", {}, h("th", {}, "mean"), h("td", {}, fmtNum(last.mean))) : null,
      )),
      last && terms.length
        ? h("table", { class: "facts" }, h("caption", {}, "best tree's terms"), h("tbody", {},
            terms.map((t, i) => h("tr", {}, h("th", {}, t), h("td", {}, fmtNum((last.best_terms || [])[i]))))))
        : null,
      memberPlant !== null
        ? h("button", { testid: "family-member-detail", onclick: () => ctx.openPlant(memberPlant) }, "Genome of this tree")
        : null,
    );
  }

  function toggleStats() {
    statsPanel.hidden = !statsPanel.hidden;
    renderStatsPanel();
  }

  function browse(delta) {
    if (!session) return;
    const n = (session.state?.members || []).length;
    if (n === 0) return;
    index = Math.min(n - 1, Math.max(0, index + delta));
    return showMember();
  }

  async function run(count) {
    if (!session) return;
    const c = count ?? session.state?.batch ?? 1;
    const s = await ctx.act(() => api.generations(session.id, c));
    if (s) await ctx.setSession(s);
  }

  function askBatch() {
    batchForm.hidden = !batchForm.hidden;
    if (!batchForm.hidden) {
      batchInput.focus();
      batchInput.select();
    }
  }

  async function setBatch() {
    if (!session) return;
    const s = await ctx.act(() => api.batch(session.id, readNumber(batchInput, "batch")));
    if (s) {
      batchForm.hidden = true;
      await ctx.setSession(s);
    }
  }

  function onKey(e) {
    if (!session || e.ctrlKey || e.metaKey || e.altKey) return false;
    switch (e.key) {
      case "[": browse(-1); return true;
      case "]": browse(1); return true;
      case "s": toggleStats(); return true;
      case "g": run(1); return true;
      case "j": run(null); return true;
      case "J": askBatch(); return true;
      default: return false;
    }
  }

  function newSessionForm({ cancel }) {
    const population = num("family-new-population", 100, { min: 2, step: 1, width: "6em" });
    const seed = num("family-new-seed", 1, { min: 0, step: 1, width: "7em" });
    const extra = h("textarea", {
      rows: 6,
      testid: "family-new-bintree",
      spellcheck: "false",
      placeholder: '{"mutation_rate": 0.02, "weights": {"symmetry": 4.0}}',
    });
    const create = h("button", {
      class: "primary",
      testid: "new-create",
      onclick: async () => {
        const made = await ctx.act(() => {
          const config = { run: { population: readNumber(population, "population"), seed: seedValue(seed.value) } };
          if (extra.value.trim()) {
            try {
              config.bintree = JSON.parse(extra.value);
            } catch (err) {
              const e = new Error(`the [bintree] section is not JSON: ${err.message}`);
              e.field = "bintree";
              throw e;
            }
          }
          return api.createSession({ mode: "family", config });
        });
        if (made) await ctx.sessionCreated(made);
      },
    }, "Make generation 0");
    return h(
      "div",
      { class: "new-session", testid: "new-session-form" },
      h("h2", {}, "New family"),
      h("p", { class: "hint" }, "Susinno's binary trees under his genetic algorithm. Keys: [ ] browse, s statistics, g one generation, j a batch, J batch size."),
      h("div", { class: "row" }, field("Population", population), field("Seed", seed)),
      field("[bintree] section (JSON, optional; defaults as examples/bintree/default.toml)", extra),
      h("div", { class: "buttons" }, create, cancel ? h("button", { testid: "new-cancel", onclick: cancel }, "Cancel") : null),
    );
  }

  /**
   * The population panel's list: every member of the generation shown, fittest first (a
   * member is archived as a plant when it is browsed, so the archive alone lists fewer).
   */
  function population(limit) {
    const members = session?.state?.members || [];
    const items = members.slice(0, limit).map((m, i) => ({
      label: `${i + 1}.`,
      sub: `fitness ${fmtNum(m.fitness)}`,
      shown: i === index,
      title: i === index ? "on screen now" : "show this tree",
      dataset: { member: String(i) },
      open: () => {
        index = i;
        showMember();
      },
    }));
    return { total: members.length, items };
  }

  return {
    name: "family",
    formHolder,
    workspace,
    render,
    newSessionForm,
    onKey,
    population,
    show() {
      ensureStage();
      stage.requestRender();
      drawStats();
    },
    hide() {},
    reset() {
      session = null;
      index = 0;
      memberKey = "";
      statsData = null;
      memberPlant = null;
      if (view) view.setContent(null);
    },
  };
}
