// The plant panel: an archived plant's origin, genome fields and packed string, an editable
// genome with Regrow, exports, Branch from here and its lineage. Each field the model's schema
// describes has its meaning, range and unit, and a number a slider: moving it draws a sketch
// of the plant with the new value (recorded nowhere); letting it go records the edit as a
// step of the open breeding session, as Apply does.

import { api, getBytes, request, seedValue, BigInteger } from "./api.js";
import { h, add, clear, fmtNum, summarize } from "./dom.js";

/** Each model's schema (`GET /api/schema/{model}`), asked for once. */
const schemas = new Map();
function schemaOf(model) {
  if (!schemas.has(model)) schemas.set(model, api.schema(model).catch(() => null));
  return schemas.get(model);
}

/** A list item's path as the schema writes it: `branches[2].waves` is `branches[].waves`. */
const general = (path) => path.replace(/\[\d+\]/g, "[]");

export function createDetail(ctx, panel) {
  let current = null;
  let token = 0;

  function close() {
    current = null;
    panel.hidden = true;
    document.body.classList.remove("detail-open");
    clear(panel);
  }

  async function open(id) {
    const mine = ++token;
    const plant = await ctx.act(() => api.plant(id));
    if (!plant || mine !== token) return;
    current = plant;
    render(plant);
    panel.hidden = false;
    document.body.classList.add("detail-open");
  }

  function render(p) {
    clear(panel);
    const parents = (p.parents || []).map((q) =>
      h("a", { href: "#", class: "plant-link", testid: "detail-parent", onclick: (e) => { e.preventDefault(); open(q.plant); } },
        `#${q.plant}`, q.dominance !== undefined && q.dominance !== null ? ` (dominance ${fmtNum(q.dominance)})` : ""),
    );

    // genome fields, editable; the schema's sliders come when it has been read
    const inputs = new Map();
    const fieldRows = (p.fields || []).map((f) => {
      const input = h("input", {
        type: "text",
        value: typeof f.value === "string" ? f.value : JSON.stringify(f.value),
        dataset: { path: f.path },
        testid: `field-${f.path}`,
      });
      input.original = f.value;
      input.initial = input.value;
      inputs.set(f.path, input);
      // Locked, Mutate and Cross keep the field as the parent has it.
      const lock = h("button", {
        class: "lock",
        testid: `lock-${f.path}`,
        "aria-pressed": String(ctx.locked.has(f.path)),
        title: "Lock: Mutate and Cross keep this field as the parent has it",
        onclick: () => {
          if (ctx.locked.has(f.path)) ctx.locked.delete(f.path);
          else ctx.locked.add(f.path);
          lock.setAttribute("aria-pressed", String(ctx.locked.has(f.path)));
          lock.textContent = ctx.locked.has(f.path) ? "locked" : "lock";
        },
      }, ctx.locked.has(f.path) ? "locked" : "lock");
      return h("tr", {}, h("th", { title: f.path }, f.path), h("td", {}, h("div", { class: "value" }, input, lock)));
    });
    const fieldsTable = h("table", { class: "fields", testid: "fields" }, h("tbody", {}, fieldRows));

    const genomeText = h("textarea", { testid: "genome-text", spellcheck: "false", rows: 10 });
    genomeText.value = p.genome_text ?? JSON.stringify(p.genome, null, 2);
    const seed = h("input", { type: "text", inputmode: "numeric", testid: "regrow-seed", value: String(p.seed ?? 1), style: { width: "13em" } });

    // A button for each mode that starts a session from a plant of this one's model.
    const branches = ctx.modeList.filter((m) => m.branch && (m.models || []).includes(p.model));
    // Leaves and bark: a foliage kind and a height, for the GLB exports and the report.
    const foliage = h("select", { testid: "look-foliage", title: "Leaves or needles at their real size" },
      h("option", { value: "" }, "as grown"));
    const height = h("input", { type: "text", inputmode: "decimal", testid: "look-height", placeholder: "as grown", style: { width: "6em" } });
    const lookQuery = () => {
      const q = new URLSearchParams();
      if (foliage.value) q.set("foliage", foliage.value);
      if (height.value.trim()) q.set("height", height.value.trim());
      return q.toString();
    };
    const glbLinks = [];
    const exportLink = (file, label, testid, download) => {
      const a = h("a", { href: api.plantUrl(p.id, file), download, testid, class: "button" }, label);
      a.addEventListener("click", (e) => {
        e.preventDefault();
        save(a);
      });
      if (file.startsWith("plant.glb")) glbLinks.push([a, file]);
      return a;
    };
    const relink = () => {
      const q = lookQuery();
      for (const [a, file] of glbLinks) {
        a.href = api.plantUrl(p.id, q ? `${file}${file.includes("?") ? "&" : "?"}${q}` : file);
      }
    };
    foliage.addEventListener("change", relink);
    height.addEventListener("input", relink);
    api.kinds().then((k) => {
      for (const name of k.foliage || []) add(foliage, h("option", { value: name }, name));
    }).catch(() => {});
    const report = h("div", { testid: "inspect-report" });
    async function inspect() {
      const r = await ctx.act(() => api.inspect(p.id, lookQuery()));
      if (!r) return;
      clear(report);
      const verdict = { real: "", unusual: "unusual", implausible: "IMPLAUSIBLE", none: "not measured" };
      add(report, h("table", { class: "facts inspect" }, h("tbody", {},
        (r.figures || []).map((f) => h("tr", { class: f.verdict, title: f.source },
          h("th", {}, f.label),
          h("td", {}, f.value === null || f.value === undefined ? "–" : `${fmtNum(f.value)}${f.unit ? ` ${f.unit}` : ""}`),
          h("td", { class: "hint" }, `${fmtNum(f.real[0])} to ${fmtNum(f.real[1])}`),
          h("td", {}, verdict[f.verdict] ?? "")))
      )));
    }

    const thumb = h("img", { class: "thumb", src: api.pngUrl(p.id, "320x320"), alt: `plant ${p.id}`, width: 320, height: 320, testid: "detail-thumb" });
    // The sketch a moving slider draws, kept in view above the fields while they scroll.
    const live = h("img", { class: "thumb", alt: `plant ${p.id} as edited`, width: 320, height: 320, testid: "detail-sketch" });
    const liveBox = h("div", { class: "sketch", hidden: true }, live);
    schemaOf(p.model).then((schema) => {
      if (schema && current === p) withSchema(schema, inputs, [thumb, live], liveBox, fieldsTable, seed);
    });

    const title = h("div", { class: "detail-head" },
      h("h2", {}, `Plant #${p.id}`),
      h("button", { class: "close", testid: "detail-close", title: "Close", onclick: close }, "×"));

    add(panel,
      title,
      p.title ? h("div", { class: "detail-title" }, p.title) : null,
      thumb,
      h("table", { class: "facts" }, h("tbody", {},
        h("tr", {}, h("th", {}, "model"), h("td", {}, p.model)),
        h("tr", {}, h("th", {}, "operator"), h("td", { testid: "detail-operator" }, p.operator || "–")),
        h("tr", {}, h("th", {}, "settings"), h("td", { class: "mono" }, summarize(p.settings, 400) || "–")),
        h("tr", {}, h("th", {}, "seed"), h("td", { testid: "detail-seed" }, String(p.seed ?? "–"))),
        h("tr", {}, h("th", {}, "parents"), h("td", { testid: "detail-parents" }, parents.length ? parents.flatMap((a, i) => (i ? [", ", a] : [a])) : "none")),
        h("tr", {}, h("th", {}, "session"), h("td", {}, p.session !== null && p.session !== undefined ? `#${p.session}` : "–")),
        h("tr", {}, h("th", {}, "created"), h("td", {}, p.created || "–")),
      )),
      h("div", { class: "buttons" },
        h("button", { testid: "lineage-open", onclick: () => ctx.openLineage(p.id) }, "Lineage"),
        ...branches.map((m) => h("button", { testid: `branch-${m.name}`, title: m.branch.hint, onclick: () => branch(m.name) }, m.branch.label)),
        h("button", { testid: "add-to-grid", title: "Put this plant back in the current breeding grid", onclick: addToGrid }, "Add to grid"),
      ),
      h("h3", {}, "Leaves and bark"),
      h("div", { class: "buttons" },
        h("label", { class: "field" }, h("span", {}, "Foliage"), foliage),
        h("label", { class: "field" }, h("span", {}, "Height (m)"), height),
        h("button", { testid: "inspect", title: "How this plant measures against real trees", onclick: inspect }, "Inspect"),
      ),
      report,
      h("h3", {}, "Export"),
      h("div", { class: "buttons exports" },
        exportLink("plant.glb", "GLB", "export-glb", `plant-${p.id}.glb`),
        exportLink("plant.glb?wind=true", "GLB + wind", "export-glb-wind", `plant-${p.id}-wind.glb`),
        exportLink("plant.glb?wind=true&lod=4", "GLB + wind + LOD", "export-glb-lod", `plant-${p.id}-lod.glb`),
        exportLink("plant.zip", "OBJ (zip)", "export-obj", `plant-${p.id}.zip`),
        exportLink("plant.stl", "STL", "export-stl", `plant-${p.id}.stl`),
        exportLink("plant.png?view=iso&size=1024x1024", "PNG", "export-png", `plant-${p.id}.png`),
        exportLink("genome.json", "genome.json", "export-genome", `plant-${p.id}.genome.json`),
      ),
      p.packed ? h("div", {}, h("h3", {}, "Packed string"), h("pre", { class: "packed", testid: "packed" }, p.packed)) : null,
      h("h3", {}, "Genome fields"),
      liveBox,
      fieldRows.length ? fieldsTable : h("p", { class: "hint" }, "no fields"),
      fieldRows.length
        ? h("div", { class: "buttons" }, h("button", { testid: "apply-fields", onclick: () => applyFields(fieldsTable, seed) }, "Apply field edits"))
        : null,
      h("h3", {}, "Genome"),
      genomeText,
      h("div", { class: "buttons" },
        h("label", { class: "field" }, h("span", {}, "Seed"), seed),
        h("button", { class: "primary", testid: "regrow", title: "Grow the edited genome (or the same one with another seed) in this plant's place", onclick: () => regrow(genomeText.value, seed) }, "Regrow"),
      ),
    );
  }

  /** Gives each field the schema describes its meaning, range and unit as a tooltip, and a
   * number a slider beside its box (the slider spans the schema's soft range; a typed value
   * may go to the field's ends). A slider moved draws a sketch in the panel's picture, one
   * request at a time and always of the latest values; let go, it records the edit. */
  function withSchema(schema, inputs, [thumb, live], liveBox, table, seedInput) {
    const specs = new Map(schema.fields.map((f) => [f.path, f]));
    let inFlight = false;
    let dirty = false;
    let waitingSince = 0; // the first move no sketch has shown yet
    let sketches = 0;
    let shownUrl = "";
    const moved = () => {
      if (!waitingSince) waitingSince = performance.now();
      sketch();
    };
    async function sketch() {
      if (inFlight) {
        dirty = true;
        return;
      }
      inFlight = true;
      dirty = false;
      const since = waitingSince;
      waitingSince = 0;
      try {
        const fields = changed(table);
        const bytes = await request("POST", api.plantUrl(current.id, "sketch.png"), { fields, size: "320x320" }, { raw: true });
        const url = URL.createObjectURL(new Blob([bytes], { type: "image/png" }));
        live.addEventListener("load", () => {
          thumb.dataset.sketches = String(++sketches);
          thumb.dataset.sketchMs = String(Math.round(performance.now() - since));
        }, { once: true });
        liveBox.hidden = false;
        live.src = url;
        thumb.src = url;
        if (shownUrl) URL.revokeObjectURL(shownUrl);
        shownUrl = url;
      } catch (e) {
        ctx.act(() => Promise.reject(e));
      } finally {
        inFlight = false;
        if (dirty) sketch();
      }
    }
    const order = new Map(schema.fields.map((f, i) => [f.path, i]));
    const groups = [...new Set(schema.fields.map((f) => f.group))];
    const sliders = [];
    for (const [path, input] of inputs) {
      const spec = specs.get(general(path));
      if (!spec) continue;
      const row = input.closest("tr");
      const item = path.match(/\[(\d+)\]/);
      row.group = item ? `${spec.group} ${Number(item[1]) + 1}` : spec.group;
      row.order = [groups.indexOf(spec.group), item ? Number(item[1]) : -1, order.get(spec.path)];
      const range = spec.kind === "number" || spec.kind === "integer"
        ? ` · ${spec.min} to ${spec.max}${spec.unit}` : spec.options ? ` · ${spec.options.join(", ")}` : "";
      input.title = `${spec.meaning}${range}${spec.optional ? " · optional" : ""}`;
      const th = input.closest("tr").querySelector("th");
      th.title = `${path}: ${input.title}`;
      if (spec.shapes) th.classList.add("shapes");
      if ((spec.kind !== "number" && spec.kind !== "integer") || typeof input.original !== "number") continue;
      const slider = h("input", {
        type: "range",
        min: spec.soft_min,
        max: spec.soft_max,
        step: spec.kind === "integer" ? 1 : spec.log ? "any" : spec.step,
        testid: `slider-${path}`,
        "aria-label": `${path}: ${spec.meaning}`,
      });
      const toSlider = (v) => (spec.log ? Math.log(v) : v);
      const fromSlider = (x) => (spec.log ? Number(Math.exp(x).toPrecision(4)) : Number(x));
      if (spec.log) {
        slider.min = Math.log(spec.soft_min);
        slider.max = Math.log(spec.soft_max);
      }
      slider.value = toSlider(input.original);
      slider.addEventListener("input", () => {
        input.value = String(fromSlider(slider.value));
        moved();
      });
      slider.addEventListener("change", () => record(table, seedInput));
      input.addEventListener("change", () => {
        const v = Number(input.value);
        if (Number.isFinite(v)) slider.value = toSlider(v);
        moved();
      });
      const reset = h("button", {
        class: "reset",
        testid: `reset-${path}`,
        title: `Back to this plant's ${input.initial}`,
        "aria-label": `reset ${path}`,
        onclick: () => {
          if (input.value === input.initial) return;
          input.value = input.initial;
          slider.value = toSlider(input.original);
          moved();
        },
      }, "↺");
      input.closest("td").append(h("div", { class: "slider" }, slider, reset));
      sliders.push({ row, spec, input, slider, fromSlider });
    }
    // Rows in the schema's order, under a heading per group (and list item), each with a
    // button that draws that group's numbers at random within their sliders' spans.
    const body = table.tBodies[0];
    const rows = [...body.rows];
    const rank = (r) => r.order || [groups.length, 0, 0];
    rows.sort((a, b) => rank(a)[0] - rank(b)[0] || rank(a)[1] - rank(b)[1] || rank(a)[2] - rank(b)[2]);
    let heading = null;
    for (const row of rows) {
      if (row.group && row.group !== heading) {
        heading = row.group;
        const members = sliders.filter((s) => s.row.group === heading);
        const randomise = members.length
          ? h("button", {
            class: "randomise",
            testid: `randomise-${heading}`,
            title: `Draw ${heading}'s numbers at random within their sliders`,
            onclick: () => {
              for (const s of members) {
                const [lo, hi] = [Number(s.slider.min), Number(s.slider.max)];
                s.slider.value = String(lo + Math.random() * (hi - lo));
                s.input.value = String(s.fromSlider(s.slider.value));
              }
              moved();
              record(table, seedInput);
            },
          }, "Randomise")
          : null;
        body.append(h("tr", { class: "group" }, h("th", { colspan: 2 }, heading, randomise)));
      }
      body.append(row);
    }
  }

  /** A let-go slider's edit, recorded when a session takes edits (otherwise it waits for
   * Apply, the sketch showing it meanwhile). Arrow keys let go at every press, so the step is
   * recorded once they rest. */
  let recordTimer = 0;
  function record(table, seedInput) {
    clearTimeout(recordTimer);
    recordTimer = setTimeout(() => {
      try {
        sessionTaking("edit", "editing");
      } catch {
        return; // no session takes edits: Apply records them once one does
      }
      applyFields(table, seedInput);
    }, 500);
  }

  /** The open session, if its mode takes the step `POST /api/sessions/{id}/${step}` (as the
   * studio's list of modes says); otherwise an error naming a mode that does. */
  function sessionTaking(step, doing) {
    const path = `/api/sessions/{id}/${step}`;
    const takes = (m) => (m.routes || []).some((r) => r.method === "POST" && r.path === path);
    const s = ctx.session;
    if (s && ctx.modeList.some((m) => m.name === s.mode && takes(m))) return s;
    const mode = ctx.modeList.find(takes);
    const how = mode && mode.branch ? ` (${mode.branch.label} makes one from this plant)` : "";
    const e = new Error(`${doing} needs an open ${mode ? mode.label : ""} session${how}`);
    e.field = "session";
    throw e;
  }

  async function regrow(text, seedInput) {
    const p = current;
    const s = await ctx.act(() => {
      const session = sessionTaking("edit", "editing");
      const body = { plant: p.id, genome: text };
      if (seedInput.value.trim() !== "") body.seed = seedValue(seedInput.value);
      return api.edit(session.id, body);
    });
    if (s) await afterEdit(s, p.id);
  }

  async function applyFields(table, seedInput) {
    const p = current;
    const s = await ctx.act(() => {
      const session = sessionTaking("edit", "editing");
      const fields = changed(table);
      if (fields.length === 0) {
        const e = new Error("no field was changed");
        e.field = "fields";
        throw e;
      }
      const body = { plant: p.id, fields };
      if (seedInput.value.trim() !== "") body.seed = seedValue(seedInput.value);
      return api.edit(session.id, body);
    });
    if (s) await afterEdit(s, p.id);
  }

  /** Saves an export link's file. A heavy plant's file takes the studio seconds to make, so
   * the link says it is being prepared, and for how long, until the browser saves it. */
  async function save(link) {
    if (link.dataset.busy) return;
    link.dataset.busy = "true";
    const label = link.textContent;
    const started = performance.now();
    const tick = () => {
      link.textContent = `${label} · preparing ${Math.floor((performance.now() - started) / 1000)} s`;
    };
    tick();
    const timer = setInterval(tick, 1000);
    try {
      const bytes = await ctx.act(() => getBytes(link.href));
      if (!bytes) return;
      const url = URL.createObjectURL(new Blob([bytes]));
      const saving = h("a", { href: url, download: link.download, hidden: true });
      document.body.append(saving);
      saving.click();
      saving.remove();
      setTimeout(() => URL.revokeObjectURL(url), 60_000);
    } finally {
      clearInterval(timer);
      link.textContent = label;
      delete link.dataset.busy;
    }
  }

  async function afterEdit(session, oldId) {
    await ctx.setSession(session);
    // the new plant is the newest of the session
    const list = await ctx.act(() => api.plants(session.id, 0, 1));
    const newest = list && list.plants && list.plants[0];
    if (newest && newest.id !== oldId) await open(newest.id);
  }

  async function branch(mode) {
    const p = current;
    const s = await ctx.act(() => api.branch(p.id, mode));
    if (!s) return;
    await ctx.sessionCreated(s);
    // The panel goes on with the plant as it entered the new session (its copy there,
    // whose parent it is), which the session's steps act on.
    const list = await ctx.act(() => api.plants(s.id, 0, 1000));
    const copy = list && (list.plants || []).find((q) => (q.parents || []).includes(p.id));
    if (copy) await open(copy.id);
    else close();
  }

  async function addToGrid() {
    const p = current;
    const s = await ctx.act(() => api.add(sessionTaking("add", "adding to the grid").id, { plants: [p.id] }));
    if (s) await ctx.setSession(s);
  }

  return {
    open,
    close,
    get current() {
      return current;
    },
  };
}

/** The fields whose boxes differ from the plant's values, as edits. The studio sets them on
 * the stored genome itself, so no digit is lost. */
function changed(table) {
  const fields = [];
  for (const input of table.querySelectorAll("input[data-path]")) {
    if (input.value === input.initial) continue;
    fields.push({ path: input.dataset.path, value: parseValue(input.value, input.original, input.dataset.path) });
  }
  return fields;
}

/** A field's new value from its text, of the type its old value had. */
function parseValue(text, original, path) {
  const t = text.trim();
  if (typeof original === "number" || original instanceof BigInteger) {
    if (/^-?\d+$/.test(t) && !Number.isSafeInteger(Number(t))) return new BigInteger(t);
    const n = Number(t);
    if (t === "" || !Number.isFinite(n)) {
      const e = new Error(`${path} must be a number (got "${text}")`);
      e.field = path;
      throw e;
    }
    return n;
  }
  if (typeof original === "string") return text;
  if (typeof original === "boolean") {
    if (t === "true" || t === "false") return t === "true";
    const e = new Error(`${path} must be true or false (got "${text}")`);
    e.field = path;
    throw e;
  }
  try {
    return JSON.parse(t);
  } catch {
    const e = new Error(`${path}: "${text}" is not a JSON value`);
    e.field = path;
    throw e;
  }
}
