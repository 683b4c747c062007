// A tiny element builder: h("button", {testid: "cross", onclick}, "Cross").

export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === undefined || v === null || v === false) continue;
    if (k === "testid") el.dataset.testid = v;
    else if (k === "class") el.className = v;
    else if (k === "style" && typeof v === "object") Object.assign(el.style, v);
    else if (k === "dataset") Object.assign(el.dataset, v);
    else if (k.startsWith("on") && typeof v === "function") el.addEventListener(k.slice(2), v);
    else if (k === "value") el.value = v;
    else if (k === "checked") el.checked = !!v;
    else if (v === true) el.setAttribute(k, "");
    else el.setAttribute(k, String(v));
  }
  append(el, children);
  return el;
}

/** Appends children to `el`, skipping null, undefined and false (Element.append would print them). */
export function add(el, ...children) {
  append(el, children);
  return el;
}

function append(el, children) {
  for (const c of children) {
    if (c === undefined || c === null || c === false) continue;
    if (Array.isArray(c)) append(el, c);
    else if (c instanceof Node) el.appendChild(c);
    else el.appendChild(document.createTextNode(String(c)));
  }
}

/** A labelled control: <label><span>text</span> control</label>. */
export function field(label, control, title) {
  return h("label", { class: "field", title }, h("span", {}, label), control);
}

/** A number input. */
export function num(testid, value, { min, max, step = "any", width } = {}) {
  return h("input", {
    type: "number",
    testid,
    value: String(value),
    min,
    max,
    step,
    style: width ? { width } : undefined,
  });
}

/** Reads a number input, throwing a message that names the field when it is not a number. */
export function readNumber(input, name) {
  const v = input.value.trim();
  const n = Number(v);
  if (v === "" || !Number.isFinite(n)) {
    const e = new Error(`${name} must be a number (got "${v}")`);
    e.field = name;
    throw e;
  }
  return n;
}

export function clear(el) {
  while (el.firstChild) el.removeChild(el.firstChild);
  return el;
}

/** Short text for a number. */
export function fmtNum(v, digits = 4) {
  if (v === null || v === undefined) return "–";
  if (typeof v !== "number") return String(v);
  if (!Number.isFinite(v)) return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e6 || a < 1e-3)) return v.toExponential(2);
  if (Number.isInteger(v)) return String(v);
  return v.toPrecision(digits).replace(/(\.\d*?)0+$/, "$1").replace(/\.$/, "");
}

/** A compact one-line rendering of a settings or action object. */
export function summarize(value, max = 90) {
  if (value === null || value === undefined) return "";
  if (typeof value !== "object") return String(value);
  const parts = [];
  for (const [k, v] of Object.entries(value)) {
    let s;
    if (v === null || typeof v !== "object") s = typeof v === "number" ? fmtNum(v) : String(v);
    else s = JSON.stringify(v);
    parts.push(`${k} ${s}`);
  }
  const text = parts.join(", ");
  return text.length > max ? text.slice(0, max - 1) + "…" : text;
}
