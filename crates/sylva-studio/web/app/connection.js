// Whether the studio answers. A request that gets no answer, or an event stream that drops,
// makes the page ask the studio directly; when that fails too the connection is lost: a
// banner says so (what the page shows may be out of date), and the page keeps asking every
// second until the studio answers again, then tells its listeners so they refresh what they
// show and follow their runs again. While all is well the page asks every few seconds too,
// so that a studio killed while nothing happens is seen as well.

const PROBE = "/api/modes";
const RETRY_MS = 1000;
const IDLE_MS = 5000;

let headers = {};
let lost = false;
let checking = null;
let timer = 0;
const backListeners = new Set();

/** Sends `extra` headers (the access token) with every probe. */
export function probeHeaders(extra) {
  headers = extra;
}

/** Calls `fn()` whenever the studio answers again after the connection was lost. */
export function onReconnect(fn) {
  backListeners.add(fn);
}

/** Whether the connection is lost now. */
export function isLost() {
  return lost;
}

async function answers() {
  try {
    const res = await fetch(PROBE, { headers, cache: "no-store" });
    // any answer (even a refusal) is a studio that is there
    return res.status > 0;
  } catch {
    return false;
  }
}

function banner() {
  return document.getElementById("connection");
}

function setLost(on) {
  if (lost === on) return;
  lost = on;
  document.body.dataset.connection = on ? "lost" : "ok";
  const b = banner();
  if (b) b.hidden = !on;
  if (!on) for (const fn of backListeners) fn();
}

/**
 * Something suggests the studio is gone (a request without an answer, a dropped event
 * stream): asks it, and shows the connection as lost if it does not answer.
 */
export function suspect() {
  if (checking) return checking;
  checking = (async () => {
    const ok = await answers();
    setLost(!ok);
    checking = null;
    schedule();
  })();
  return checking;
}

function schedule() {
  clearTimeout(timer);
  timer = setTimeout(() => {
    // a hidden tab waits until it is looked at again
    if (document.visibilityState === "hidden" && !lost) return schedule();
    suspect();
  }, lost ? RETRY_MS : IDLE_MS);
}

document.addEventListener("visibilitychange", () => {
  if (document.visibilityState === "visible") suspect();
});
schedule();
