// The studio's HTTP API (docs/studio.md), as small async functions. Every failure becomes an
// ApiError carrying the server's `{error, field}`; nothing is swallowed here.

import { probeHeaders, suspect } from "./connection.js";

/** An error answered by the server (4xx/5xx) or a failed request. */
export class ApiError extends Error {
  constructor(message, { status = 0, field = "", path = "", offline = false } = {}) {
    super(message);
    this.name = "ApiError";
    this.status = status;
    this.field = field;
    this.path = path;
    /** No answer at all: the studio is gone (or the network is). */
    this.offline = offline;
  }
}

// A token the page was opened with (`?token=...`, for a studio bound beyond loopback). The
// server turns it into a cookie on the first page load; fetches also send it as a bearer token
// so scripts and the page agree.
const token = (() => {
  try {
    const t = new URLSearchParams(location.search).get("token");
    if (t) sessionStorage.setItem("sylva-token", t);
    return t || sessionStorage.getItem("sylva-token") || "";
  } catch {
    return "";
  }
})();

// Seeds are 64-bit integers; JavaScript numbers hold integers exactly only up to 2^53. Answers
// are parsed keeping such integers as their digits (BigInteger), which are sent back as the
// same digits (JSON.rawJSON), so regrowing with a plant's own seed stays the same plant.
const canKeepDigits = (() => {
  try {
    let ok = false;
    JSON.parse("1", (k, v, context) => {
      ok = !!(context && context.source === "1");
      return v;
    });
    return ok && typeof JSON.rawJSON === "function";
  } catch {
    return false;
  }
})();

/** An integer too large for a JavaScript number, kept as its decimal digits. */
export class BigInteger {
  constructor(digits) {
    this.digits = digits;
  }
  toString() {
    return this.digits;
  }
  toJSON() {
    return canKeepDigits ? JSON.rawJSON(this.digits) : Number(this.digits);
  }
}

function reviver(key, value, context) {
  if (typeof value === "number" && !Number.isSafeInteger(value) && Number.isInteger(value) &&
      context && /^-?\d+$/.test(context.source)) {
    return new BigInteger(context.source);
  }
  return value;
}

/** Parses JSON, keeping integers beyond 2^53 exact. */
export function parseJson(text) {
  return canKeepDigits ? JSON.parse(text, reviver) : JSON.parse(text);
}

/** A seed typed by a person: a number, or its digits when it is beyond 2^53. */
export function seedValue(text, name = "seed") {
  const t = String(text).trim();
  if (/^\d+$/.test(t)) {
    const n = Number(t);
    return Number.isSafeInteger(n) ? n : new BigInteger(t.replace(/^0+(?=\d)/, ""));
  }
  const e = new Error(`${name} must be a whole number from 0 (got "${t}")`);
  e.field = name;
  throw e;
}

let pending = 0;
const busyListeners = new Set();
/** Calls `fn(count)` whenever the number of requests in flight changes. */
export function onBusy(fn) {
  busyListeners.add(fn);
}
function setPending(delta) {
  pending += delta;
  for (const fn of busyListeners) fn(pending);
}

/** Headers every request carries. */
export function authHeaders() {
  return token ? { Authorization: `Bearer ${token}` } : {};
}
probeHeaders(authHeaders());

/** The raw fetch, with auth and the busy count; throws ApiError on a non-2xx answer. */
export async function request(method, path, body, { raw = false, cache } = {}) {
  const init = { method, headers: { ...authHeaders() } };
  if (cache) init.cache = cache;
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  setPending(1);
  let res;
  try {
    res = await fetch(path, init);
  } catch (e) {
    setPending(-1);
    suspect();
    throw new ApiError(`${method} ${path}: the studio did not answer (${e.message})`, { path, offline: true });
  }
  try {
    if (!res.ok) {
      let message = `${method} ${path}: ${res.status} ${res.statusText}`;
      let field = "";
      const text = await res.text();
      try {
        const j = JSON.parse(text);
        if (j && typeof j.error === "string") {
          message = j.error;
          field = j.field || "";
        }
      } catch {
        if (text) message += `: ${text.slice(0, 300)}`;
      }
      throw new ApiError(message, { status: res.status, field, path });
    }
    if (raw) return await res.arrayBuffer();
    if (res.status === 204) return null;
    const text = await res.text();
    if (!text) return null;
    try {
      return parseJson(text);
    } catch {
      throw new ApiError(`${method} ${path}: the answer is not JSON: ${text.slice(0, 200)}`, {
        status: res.status,
        path,
      });
    }
  } finally {
    setPending(-1);
  }
}

export const get = (path) => request("GET", path);
export const post = (path, body = {}) => request("POST", path, body);
export const getBytes = (path, opts) => request("GET", path, undefined, { raw: true, ...opts });

const enc = encodeURIComponent;

export const api = {
  modes: () => get("/api/modes"),
  models: () => get("/api/models"),
  examples: () => get("/api/examples"),

  sessions: () => get("/api/sessions"),
  session: (id) => get(`/api/sessions/${enc(id)}`),
  createSession: (body) => post("/api/sessions", body),
  undo: (id) => post(`/api/sessions/${enc(id)}/undo`),
  redo: (id) => post(`/api/sessions/${enc(id)}/redo`),

  cross: (id, body) => post(`/api/sessions/${enc(id)}/cross`, body),
  mutate: (id, body) => post(`/api/sessions/${enc(id)}/mutate`, body),
  add: (id, body) => post(`/api/sessions/${enc(id)}/add`, body),
  edit: (id, body) => post(`/api/sessions/${enc(id)}/edit`, body),

  grow: (id, body) => post(`/api/sessions/${enc(id)}/grow`, body),
  pick: (id, plant) => post(`/api/sessions/${enc(id)}/pick`, { plant }),
  gardenGlbUrl: (id) => `/api/sessions/${enc(id)}/garden.glb`,

  generations: (id, count) => post(`/api/sessions/${enc(id)}/generations`, { count }),
  batch: (id, batch) => post(`/api/sessions/${enc(id)}/batch`, { batch }),
  stats: (id) => get(`/api/sessions/${enc(id)}/stats`),
  member: (id, index) => post(`/api/sessions/${enc(id)}/member`, { index }),

  design: (id, design) => post(`/api/sessions/${enc(id)}/design`, { design }),
  stop: (id) => post(`/api/sessions/${enc(id)}/stop`),
  resume: (id, generations) => post(`/api/sessions/${enc(id)}/resume`, generations === undefined ? {} : { generations }),
  run: (id) => get(`/api/sessions/${enc(id)}/run`),
  eventsUrl: (id) => `/api/sessions/${enc(id)}/events`,

  matchRun: (id) => get(`/api/sessions/${enc(id)}/match/run`),
  matchStop: (id) => post(`/api/sessions/${enc(id)}/match/stop`),
  matchResume: (id, generations) => post(`/api/sessions/${enc(id)}/match/resume`, { generations }),
  matchPictureUrl: (id, view = "front") => `/api/sessions/${enc(id)}/match/picture?view=${view}`,
  matchOverlayUrl: (id, plant) => `/api/sessions/${enc(id)}/match/overlay.png?plant=${enc(plant)}`,

  descriptors: () => get("/api/descriptors"),
  map: (id) => get(`/api/sessions/${enc(id)}/map`),
  mapStop: (id) => post(`/api/sessions/${enc(id)}/map/stop`),
  mapResume: (id, generations) => post(`/api/sessions/${enc(id)}/map/resume`, { generations }),

  plants: (session, offset = 0, limit = 100) =>
    get(`/api/plants?session=${enc(session)}&offset=${offset}&limit=${limit}`),
  plant: (id) => get(`/api/plants/${enc(id)}`),
  lineage: (id, depth = 8) => get(`/api/plants/${enc(id)}/lineage?depth=${depth}`),
  branch: (id, mode) => post(`/api/plants/${enc(id)}/branch`, { mode }),
  plantUrl: (id, file) => `/api/plants/${enc(id)}/${file}`,
  kinds: () => get("/api/kinds"),
  schema: (model) => get(`/api/schema/${enc(model)}`),
  inspect: (id, query = "") => get(`/api/plants/${enc(id)}/inspect${query ? `?${query}` : ""}`),
  pngUrl: (id, size = "256x256", view = "iso") =>
    `/api/plants/${enc(id)}/plant.png?view=${view}&size=${size}`,
};
