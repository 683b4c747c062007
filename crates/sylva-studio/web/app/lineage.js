// The lineage of a plant: a layered graph, the plant at the bottom and its ancestors above by
// depth, each a thumbnail with its operator and settings; edges labelled with dominance.

import { api } from "./api.js";
import { h, clear, fmtNum, summarize } from "./dom.js";
import { thumb } from "./thumbs.js";

const NODE_W = 150;
const NODE_H = 196;
const GAP_X = 24;
const GAP_Y = 64;
const SVG_NS = "http://www.w3.org/2000/svg";

export function createLineage(ctx, overlay) {
  let plantId = null;
  const depthSelect = h("select", { testid: "lineage-depth", onchange: () => plantId !== null && open(plantId) });
  for (const d of [1, 2, 4, 8, 16, 32, 64]) depthSelect.append(h("option", { value: d }, `${d} generations`));
  depthSelect.value = "8";
  const title = h("h2", {});
  const body = h("div", { class: "lineage-body", testid: "lineage-graph" });
  const close = () => {
    overlay.hidden = true;
    plantId = null;
  };
  overlay.append(
    h("div", { class: "lineage-head" }, title, depthSelect,
      h("button", { class: "close", testid: "lineage-close", title: "Close (Esc)", onclick: close }, "×")),
    body,
  );

  async function open(id) {
    const data = await ctx.act(() => api.lineage(id, Number(depthSelect.value)));
    if (!data) return;
    plantId = id;
    title.textContent = `Lineage of plant #${id}`;
    overlay.hidden = false;
    draw(data, id);
  }

  function draw(data, rootId) {
    clear(body);
    const nodes = data.nodes || [];
    const edges = data.edges || [];
    const layers = [];
    for (const n of nodes) {
      const d = n.depth ?? 0;
      (layers[d] ||= []).push(n);
    }
    for (let d = 0; d < layers.length; d++) layers[d] ||= [];
    const maxDepth = layers.length - 1;

    // order each layer by the mean position of its children below (fewer crossings)
    const pos = new Map();
    const childrenOf = new Map();
    for (const e of edges) {
      if (!childrenOf.has(e.parent)) childrenOf.set(e.parent, []);
      childrenOf.get(e.parent).push(e.child);
    }
    layers.forEach((layer, d) => {
      if (d > 0) {
        const key = (n) => {
          const xs = (childrenOf.get(n.id) || []).filter((c) => pos.has(c)).map((c) => pos.get(c));
          return xs.length ? xs.reduce((a, b) => a + b, 0) / xs.length : Infinity;
        };
        layer.sort((a, b) => key(a) - key(b) || a.id - b.id);
      }
      layer.forEach((n, i) => pos.set(n.id, i - (layer.length - 1) / 2));
    });

    const widest = Math.max(1, ...layers.map((l) => l.length));
    const width = widest * (NODE_W + GAP_X) + GAP_X;
    const height = (maxDepth + 1) * (NODE_H + GAP_Y) + GAP_Y / 2;
    const canvas = h("div", { class: "lineage-canvas", style: { width: `${width}px`, height: `${height}px` } });
    const svg = document.createElementNS(SVG_NS, "svg");
    svg.setAttribute("width", width);
    svg.setAttribute("height", height);
    svg.setAttribute("class", "lineage-edges");
    canvas.append(svg);

    const xy = new Map();
    layers.forEach((layer, d) => {
      const y = (maxDepth - d) * (NODE_H + GAP_Y) + GAP_Y / 2;
      const layerW = layer.length * (NODE_W + GAP_X) - GAP_X;
      const x0 = (width - layerW) / 2;
      layer.forEach((n, i) => xy.set(n.id, { x: x0 + i * (NODE_W + GAP_X), y }));
    });

    for (const e of edges) {
      const c = xy.get(e.child);
      const p = xy.get(e.parent);
      if (!c || !p) continue;
      const x1 = c.x + NODE_W / 2, y1 = c.y;
      const x2 = p.x + NODE_W / 2, y2 = p.y + NODE_H;
      const line = document.createElementNS(SVG_NS, "line");
      line.setAttribute("x1", x1);
      line.setAttribute("y1", y1);
      line.setAttribute("x2", x2);
      line.setAttribute("y2", y2);
      line.setAttribute("data-testid", "lineage-edge");
      line.setAttribute("data-child", e.child);
      line.setAttribute("data-parent", e.parent);
      svg.append(line);
      if (e.dominance !== undefined && e.dominance !== null) {
        const t = document.createElementNS(SVG_NS, "text");
        const f = 0.5;
        t.setAttribute("x", x1 + (x2 - x1) * f);
        t.setAttribute("y", y1 + (y2 - y1) * f);
        t.setAttribute("text-anchor", "middle");
        t.textContent = fmtNum(e.dominance, 3);
        svg.append(t);
      }
    }

    for (const n of nodes) {
      const at = xy.get(n.id);
      const settings = summarize(n.settings, 60);
      const node = h(
        "button",
        {
          class: "lnode" + (n.id === rootId ? " root" : ""),
          testid: "lineage-node",
          dataset: { plant: String(n.id), depth: String(n.depth ?? 0) },
          style: { left: `${at.x}px`, top: `${at.y}px`, width: `${NODE_W}px`, height: `${NODE_H}px` },
          title: `#${n.id} ${n.operator || ""} ${settings}\nseed ${n.seed}\nclick to show this plant`,
          onclick: () => ctx.openPlant(n.id),
        },
        thumb(api.pngUrl(n.id, "128x128"), { width: 128, height: 128, alt: `plant ${n.id}` }),
        h("span", { class: "lcap" }, h("b", {}, `#${n.id}`), " ", n.operator || "–"),
        settings ? h("span", { class: "lset" }, settings) : null,
      );
      canvas.append(node);
    }
    if (nodes.length === 0) canvas.append(h("p", { class: "hint" }, "no ancestors"));
    body.append(canvas);
    // show the plant (bottom) first
    requestAnimationFrame(() => {
      body.scrollTop = body.scrollHeight;
      body.scrollLeft = (width - body.clientWidth) / 2;
    });
  }

  return {
    open,
    close,
    get isOpen() {
      return !overlay.hidden;
    },
  };
}
