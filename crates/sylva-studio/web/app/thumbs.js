// Thumbnails: the small pictures of plants in the population panel, the garden's cards, the
// lineage and the map. A picture of a heavy plant can take the studio a second to make, and a
// browser opens at most six connections to it: as plain <img src> dozens of them would be asked
// for at once and a step's request would queue behind them. So they come through this queue:
// at most AT_ONCE fetches at a time, each of low priority, started only once its picture is on
// screen (or near it), and aborted if it leaves the screen (or the page) first. Pictures fetched
// are kept, so a panel drawn again after a step shows them at once.

import { authHeaders } from "./api.js";
import { h } from "./dom.js";
import { stats } from "./stats.js";

/** The most thumbnails fetched at once: whatever else the page asks for finds no more ahead. */
export const AT_ONCE = 2;
/** Pictures kept (object URLs), the least recently shown let go first. */
const KEPT = 600;

const kept = new Map(); // url -> object URL, least recently used first
const observed = new Set(); // images waiting for their picture
const near = new Set(); // ...of them, those on screen or near it, in the order they came
const loading = new Map(); // image -> AbortController of its fetch

const observer = new IntersectionObserver((entries) => {
  for (const e of entries) {
    if (e.isIntersecting) {
      near.add(e.target);
    } else {
      near.delete(e.target);
      loading.get(e.target)?.abort();
    }
  }
  pump();
}, { rootMargin: "100px" });

/** An <img> (`attrs` as h() takes them) whose picture `url` comes through the queue. */
export function thumb(url, attrs) {
  const img = h("img", { ...attrs, decoding: "async" });
  img.dataset.thumb = url;
  const ready = kept.get(url);
  if (ready) {
    keep(url, ready);
    img.src = ready;
  } else {
    observed.add(img);
    observer.observe(img);
    // the images of a panel cleared and drawn again come through here: let go of the old ones
    queueMicrotask(pump);
  }
  return img;
}

function pump() {
  for (const img of observed) {
    if (!img.isConnected) forget(img);
  }
  while (loading.size < AT_ONCE && near.size) {
    const img = near.values().next().value;
    near.delete(img);
    load(img);
  }
  stats.thumbs.waiting = near.size;
}

function forget(img) {
  observed.delete(img);
  near.delete(img);
  observer.unobserve(img);
  loading.get(img)?.abort();
}

async function load(img) {
  const url = img.dataset.thumb;
  const controller = new AbortController();
  loading.set(img, controller);
  stats.thumbs.inFlight = loading.size;
  stats.thumbs.maxInFlight = Math.max(stats.thumbs.maxInFlight, loading.size);
  try {
    let src = kept.get(url);
    if (!src) {
      const res = await fetch(url, { headers: authHeaders(), priority: "low", signal: controller.signal });
      if (!res.ok) throw new Error(`${res.status}`);
      const blob = await res.blob();
      src = kept.get(url) || URL.createObjectURL(blob);
    }
    keep(url, src);
    img.src = src;
    forget(img);
    stats.thumbs.fetched++;
  } catch (e) {
    if (controller.signal.aborted) {
      stats.thumbs.aborted++; // still observed: fetched again if it comes back on screen
    } else {
      img.classList.add("failed"); // its alt text shows; the plant's other views still work
      forget(img);
    }
  } finally {
    loading.delete(img);
    stats.thumbs.inFlight = loading.size;
    pump();
  }
}

function keep(url, src) {
  kept.delete(url);
  kept.set(url, src);
  if (kept.size > KEPT) {
    const [oldest, old] = kept.entries().next().value;
    kept.delete(oldest);
    URL.revokeObjectURL(old);
  }
}
