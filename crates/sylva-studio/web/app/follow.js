// Following a session's server-sent events (docs/studio.md): each named event's data as
// JSON to its handler, and a message when the stream is lost for good.

import { isLost, suspect } from "./connection.js";

/**
 * Opens the event stream of session `id` and calls `handlers[name](data)` for each event of
 * that name; `what` names what is followed in messages ("map", "match"). Returns the
 * EventSource, for the caller to close.
 */
export function follow(ctx, url, id, handlers, what) {
  const es = new EventSource(url);
  for (const [name, handle] of Object.entries(handlers)) {
    es.addEventListener(name, (e) => {
      let data;
      try {
        data = JSON.parse(e.data);
      } catch {
        ctx.showError(new Error(`a ${name} event that is not JSON: ${String(e.data).slice(0, 120)}`));
        return;
      }
      handle(data);
    });
  }
  es.addEventListener("error", async () => {
    // a dropped stream may be a studio that is gone: the page follows again when it is back
    await suspect();
    if (es.readyState === EventSource.CLOSED && !isLost()) {
      ctx.showError(new Error(`lost the progress stream of session #${id}; reload to follow the ${what} again`));
    }
  });
  return es;
}
