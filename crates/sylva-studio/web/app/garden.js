// Garden mode: Bornhofen and Lattaud's biomorph loop (§4.1). The mother and her mutated
// children grow together in one voxel world; click one (its card, or the plant itself) to make
// it the next mother. Light and steps are controls; biomass and light are shown per plant.

import { api } from "./api.js";
import { Stage, loadGlb, THREE } from "./viewer.js";
import { h, clear, field, num, readNumber, fmtNum } from "./dom.js";
import { stats } from "./stats.js";
import { suspect } from "./connection.js";
import { thumb } from "./thumbs.js";

export default function createGardenMode(ctx, root) {
  // the server's defaults for a new garden: neighbours meet and shade each other
  const STEPS = 150;
  const SPACING = 1.0;
  const steps = num("garden-steps", STEPS, { min: 0, max: 1000, step: 1, width: "5em" });
  const spacing = num("garden-spacing", SPACING, { min: 0.25, max: 2.5, step: 0.05, width: "4.5em" });
  const elevation = num("garden-elevation", 90, { min: 0, max: 90, width: "4.5em" });
  const azimuth = num("garden-azimuth", 0, { min: 0, max: 360, width: "4.5em" });
  const children = num("garden-children", 8, { min: 0, max: 8, step: 1, width: "3.5em" });
  const growBtn = h("button", { class: "primary", testid: "garden-grow", onclick: () => grow() }, "Grow again");
  // the whole garden as one GLB scene, as it is shown
  const exportGlb = h("a", { class: "button", testid: "garden-export-glb", title: "The whole garden as one GLB scene" }, "Export GLB");
  const info = h("span", { class: "hint", testid: "garden-status" });
  // how far a garden has grown, while it grows (the session's `progress` events)
  const progressBar = h("progress", { testid: "garden-progress", max: 1, value: 0, hidden: true });
  const toolbar = h(
    "div",
    { class: "toolbar" },
    field("Steps", steps, "growing time of the garden, 0 to 1000"),
    field("Spacing m", spacing, "metres between neighbouring seeds, 0.25 to 2.5"),
    field("Light elevation °", elevation, "0 to 90 (90: from straight above)"),
    field("Azimuth °", azimuth, "0 to 360"),
    field("Children", children, "mutated children grown beside the mother, 0 to 8"),
    growBtn,
    exportGlb,
    progressBar,
    info,
  );
  const canvas = h("canvas", { class: "stage-canvas", testid: "garden-canvas" });
  const viewEl = h("div", { class: "view-el", title: "Drag to orbit; click a plant to make it the mother" });
  const wrap = h("div", { class: "view-wrap garden-view" }, canvas, viewEl);
  const cards = h("div", { class: "cards", testid: "specimens" });
  const workspace = h("div", { class: "workspace garden" }, toolbar, wrap, cards);
  const formHolder = h("div", { class: "form-holder" });
  root.append(formHolder, workspace);

  let stage = null;
  let view = null;
  let session = null;
  let gardenKey = "";
  let markers = null;
  let ringRadius = 0.4;

  function ensureStage() {
    if (stage) return;
    stage = new Stage(canvas);
    view = stage.addView(viewEl, { detail: true });
    stats.stages.garden = stage;
    let down = null;
    viewEl.addEventListener("pointerdown", (e) => (down = { x: e.clientX, y: e.clientY, b: e.button }));
    viewEl.addEventListener("pointerup", (e) => {
      if (!down || down.b !== 0) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      down = null;
      if (moved < 5) pickAt(e);
    });
  }

  function pickAt(e) {
    if (!session) return;
    const specimens = session.state?.specimens || [];
    if (specimens.length === 0) return;
    const rect = viewEl.getBoundingClientRect();
    const ndc = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1, -((e.clientY - rect.top) / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, view.camera);
    // a plant hit, or else the place on the ground inside a plant's ring
    const hits = ray.intersectObject(view.content, true);
    let p = hits.length ? hits[0].point : null;
    let reach = Infinity;
    if (!p) {
      p = ray.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 1, 0), 0), new THREE.Vector3());
      reach = ringRadius * 1.15;
    }
    if (!p) return;
    let best = null;
    let bestD = Infinity;
    for (const s of specimens) {
      const d = Math.hypot(s.x - p.x, s.z - p.z);
      if (d < bestD) {
        bestD = d;
        best = s;
      }
    }
    if (best && bestD <= reach && !best.is_mother) pick(best.plant);
  }

  async function render(s) {
    session = s;
    ensureStage();
    follow(s.id);
    const st = s.state || {};
    const set = st.settings || {};
    if (set.steps !== undefined) steps.value = set.steps;
    if (set.spacing !== undefined) spacing.value = set.spacing;
    if (set.elevation !== undefined) elevation.value = set.elevation;
    if (set.azimuth !== undefined) azimuth.value = set.azimuth;
    if (set.children !== undefined) children.value = set.children;
    const specimens = st.specimens || [];
    info.textContent = `mother #${st.mother ?? "–"} · ${specimens.length} plants`;
    exportGlb.href = api.gardenGlbUrl(s.id);
    exportGlb.download = `garden-${s.id}.glb`;
    renderCards(specimens);
    const key = JSON.stringify([s.id, st.mother, specimens.map((p) => p.plant), set]);
    if (key === gardenKey) return true;
    gardenKey = key;
    try {
      const scene = await loadGlb(api.gardenGlbUrl(s.id));
      if (gardenKey !== key) return false;
      // the rings go first, so that the framing takes in every seed's place, grown or not
      drawMarkers(specimens);
      view.setContent(scene);
      await stage.nextPaint();
      return true;
    } catch (err) {
      gardenKey = "";
      ctx.showError(err, "garden");
      return false;
    }
  }

  function drawMarkers(specimens) {
    if (markers) view.helpers.remove(markers);
    markers = new THREE.Group();
    // half the distance to the nearest neighbour, so that rings do not overlap
    let spacing = Infinity;
    for (const a of specimens) for (const b of specimens) if (a !== b) spacing = Math.min(spacing, Math.hypot(a.x - b.x, a.z - b.z));
    const r = Number.isFinite(spacing) && spacing > 0 ? spacing * 0.4 : 0.4;
    ringRadius = r;
    for (const s of specimens) {
      const ring = new THREE.Mesh(
        new THREE.RingGeometry(r * 0.88, r, 48),
        // light rings on the light ground: where each seed is, without weighing on the plants
        new THREE.MeshBasicMaterial({ color: s.is_mother ? 0xe8b440 : 0x9aa392, transparent: true, opacity: s.is_mother ? 0.9 : 0.55, side: THREE.DoubleSide, depthWrite: false }),
      );
      ring.rotation.x = -Math.PI / 2;
      ring.position.set(s.x, r * 0.004, s.z);
      ring.userData.plant = s.plant;
      markers.add(ring);
    }
    view.helpers.add(markers);
    stage.requestRender();
  }

  function renderCards(specimens) {
    clear(cards);
    specimens.forEach((s, i) => {
      const card = h(
        "button",
        {
          class: "card" + (s.is_mother ? " mother" : ""),
          testid: `specimen-${i}`,
          dataset: { plant: String(s.plant), mother: s.is_mother ? "true" : "false" },
          title: s.is_mother ? "the mother" : "make this plant the next mother",
          onclick: () => pick(s.plant),
        },
        thumb(api.pngUrl(s.plant, "96x96"), { width: 96, height: 96, alt: `plant ${s.plant}` }),
        h("span", { class: "card-title" }, `#${s.plant}`, s.is_mother ? h("span", { class: "badge" }, "mother") : null),
        h("span", { class: "card-line" }, `biomass ${fmtNum(s.biomass, 3)}`),
        h("span", { class: "card-line" }, `light ${fmtNum(s.light, 3)}`),
        h("span", { class: "card-line dim" }, `leaves ${s.leaves ?? "–"} · roots ${s.fine_roots ?? "–"}`),
      );
      card.addEventListener("contextmenu", (e) => {
        e.preventDefault();
        ctx.openPlant(s.plant);
      });
      cards.append(card);
    });
    cards.append(h("p", { class: "hint" }, "Click a plant to make it the next mother; right-click for its genome."));
  }

  function settings() {
    return {
      steps: readNumber(steps, "steps"),
      spacing: readNumber(spacing, "spacing"),
      elevation: readNumber(elevation, "elevation"),
      azimuth: readNumber(azimuth, "azimuth"),
      children: readNumber(children, "children"),
    };
  }

  async function grow() {
    if (!session) return;
    const s = await ctx.act(() => api.grow(session.id, { settings: settings() }));
    doneGrowing();
    if (s) await ctx.setSession(s);
  }

  async function pick(plant) {
    if (!session) return;
    const s = await ctx.act(() => api.pick(session.id, plant));
    doneGrowing();
    if (s) await ctx.setSession(s);
  }

  // ---- progress while a garden grows ----------------------------------------------------------
  let events = null;
  let eventsSession = null;
  function follow(id) {
    // a stream still open goes on; one closed or reconnecting (the studio was away) starts again
    if (events && eventsSession === id && events.readyState === EventSource.OPEN) return;
    unfollow();
    eventsSession = id;
    events = new EventSource(api.eventsUrl(id));
    // a dropped stream may be a studio that is gone: the page follows again when it is back
    events.addEventListener("error", () => suspect());
    events.addEventListener("progress", (e) => {
      let p;
      try {
        p = JSON.parse(e.data);
      } catch {
        return;
      }
      if (!session || session.id !== id) return;
      stats.gardenProgress.push(p.step);
      progressBar.max = Math.max(p.steps, 1);
      progressBar.value = p.step;
      progressBar.hidden = p.step >= p.steps;
      info.textContent = p.step >= p.steps ? "meshing…" : `growing: step ${p.step} of ${p.steps}`;
    });
  }
  function unfollow() {
    if (events) events.close();
    events = null;
    eventsSession = null;
  }
  function doneGrowing() {
    progressBar.hidden = true;
  }

  function newSessionForm({ cancel }) {
    const gardenModels = (ctx.models || []).filter((m) => (m.modes || []).includes("garden")).map((m) => m.name);
    const examples = (ctx.examples || []).filter((e) => gardenModels.includes(e.model));
    const fromExample = h("input", { type: "radio", name: "garden-start", checked: true, testid: "garden-new-example-radio" });
    const fromEmpty = h("input", { type: "radio", name: "garden-start", testid: "garden-new-empty" });
    const fromPlant = h("input", { type: "radio", name: "garden-start", testid: "garden-new-plant-radio" });
    const example = h("select", { testid: "garden-new-example", onchange: () => (fromExample.checked = true) });
    for (const e of examples) example.append(h("option", { value: e.name }, e.name));
    if (examples.some((e) => e.name === "lsystem/herb")) example.value = "lsystem/herb";
    const plant = num("garden-new-plant", "", { min: 1, step: 1, width: "6em" });
    plant.addEventListener("input", () => (fromPlant.checked = true));
    const nSteps = num("garden-new-steps", STEPS, { min: 0, max: 1000, step: 1, width: "5em" });
    const nSpacing = num("garden-new-spacing", SPACING, { min: 0.25, max: 2.5, step: 0.05, width: "4.5em" });
    const nElevation = num("garden-new-elevation", 90, { min: 0, max: 90, width: "4.5em" });
    const nAzimuth = num("garden-new-azimuth", 0, { min: 0, max: 360, width: "4.5em" });
    const nChildren = num("garden-new-children", 8, { min: 0, max: 8, step: 1, width: "3.5em" });
    const create = h("button", {
      class: "primary",
      testid: "new-create",
      onclick: async () => {
        const made = await ctx.act(() => {
          let start;
          if (fromEmpty.checked) start = { empty: true };
          else if (fromPlant.checked) start = { plant: readNumber(plant, "plant") };
          else start = { example: example.value };
          return api.createSession({
            mode: "garden",
            start,
            settings: {
              steps: readNumber(nSteps, "steps"),
              spacing: readNumber(nSpacing, "spacing"),
              elevation: readNumber(nElevation, "elevation"),
              azimuth: readNumber(nAzimuth, "azimuth"),
              children: readNumber(nChildren, "children"),
            },
          });
        });
        if (made) await ctx.sessionCreated(made);
      },
    }, "Grow the first garden");
    return h(
      "div",
      { class: "new-session", testid: "new-session-form" },
      h("h2", {}, "New garden"),
      h("p", { class: "hint" }, "A mother and her mutated children grow together and shade each other (Bornhofen and Lattaud, §4.1)."),
      h("fieldset", {},
        h("legend", {}, "Mother"),
        h("label", { class: "row" }, fromExample, " example: ", example),
        h("label", { class: "row" }, fromEmpty, " start from empty rules"),
        h("label", { class: "row" }, fromPlant, " archived plant #", plant),
      ),
      h("div", { class: "row" }, field("Steps", nSteps), field("Spacing m", nSpacing), field("Elevation °", nElevation), field("Azimuth °", nAzimuth), field("Children", nChildren)),
      h("div", { class: "buttons" }, create, cancel ? h("button", { testid: "new-cancel", onclick: cancel }, "Cancel") : null),
    );
  }

  return {
    name: "garden",
    formHolder,
    workspace,
    render,
    newSessionForm,
    show() {
      ensureStage();
      if (session) follow(session.id);
      stage.requestRender();
    },
    hide() {
      unfollow();
    },
    reset() {
      unfollow();
      doneGrowing();
      session = null;
      gardenKey = "";
      exportGlb.removeAttribute("href");
      if (view) view.setContent(null);
      clear(cards);
    },
    onKey() {
      return false;
    },
  };
}
