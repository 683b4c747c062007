// Figures the end-to-end test reads: `window.sylvaStudio`.
//
// paintCount / lastPaintMs: after a Breed step (Cross, Mutate, Add), the time from the click to
// the frame that has all nine plants drawn, and how many such steps were painted.
// createCount / lastCreatePaintMs: the same for a new breeding session, from the click on
// Create to its grid drawn.
// lastSelectMs: from a click on a grid cell to its highlight being applied.
// gardenProgress: the steps of every garden progress event the page received.
// thumbs: the thumbnail queue's counts (thumbs.js).
// probe(name): draws stage `name` ("breed", "garden", "family", "design") and counts the
// pixels that differ from the background (gl.readPixels, same task as the draw).

import { timings } from "./viewer.js";

export const stats = {
  timings,
  paintCount: 0,
  lastPaintMs: null,
  createCount: 0,
  lastCreatePaintMs: null,
  lastSelectMs: null,
  history: [],
  gardenProgress: [],
  // thumbs.js: thumbnails in flight now and at most, waiting on screen, fetched and aborted
  thumbs: { inFlight: 0, maxInFlight: 0, waiting: 0, fetched: 0, aborted: 0 },
  stages: {},
  ready: false,
  probe(name) {
    const stage = stats.stages[name];
    if (!stage) return null;
    return stage.probe();
  },
};

window.sylvaStudio = stats;
