// A line chart drawn by hand on a 2D canvas: axes, ticks, a legend, one polyline per series.

export const PALETTE = [
  "#7fd18b", "#e0b85c", "#6fb3e8", "#e07a6f", "#b994e6", "#5fd0c8", "#d98fc0", "#c9d36a",
  "#8aa0b8", "#f0a060",
];

function niceStep(span, count) {
  const raw = span / Math.max(count, 1);
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const norm = raw / mag;
  const nice = norm < 1.5 ? 1 : norm < 3 ? 2 : norm < 7 ? 5 : 10;
  return nice * mag;
}

function fmt(v) {
  const a = Math.abs(v);
  if (a === 0) return "0";
  if (Number.isInteger(v) && a < 1e5) return String(v);
  if (a >= 1e5 || a < 1e-3) return v.toExponential(1);
  if (a >= 100) return v.toFixed(0);
  if (a >= 10) return v.toFixed(1);
  return v.toPrecision(3).replace(/\.?0+$/, "");
}

/**
 * Draws `series` ([{name, color?, points: [[x, y], ...]}]) on `canvas`.
 * Options: title, xLabel, log (a logarithmic y axis; values ≤ 0 are clamped).
 */
export function drawChart(canvas, series, { title = "", xLabel = "generation", log = false } = {}) {
  const dpr = Math.min(window.devicePixelRatio || 1, 2);
  const cssW = canvas.clientWidth || 400;
  const cssH = canvas.clientHeight || 200;
  if (canvas.width !== Math.round(cssW * dpr) || canvas.height !== Math.round(cssH * dpr)) {
    canvas.width = Math.round(cssW * dpr);
    canvas.height = Math.round(cssH * dpr);
  }
  const ctx = canvas.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, cssW, cssH);
  ctx.fillStyle = "#202328";
  ctx.fillRect(0, 0, cssW, cssH);
  ctx.font = "11px system-ui, sans-serif";

  // the legend goes above the plot, in as many rows as it needs
  const pad = { l: 52, r: 12, t: title ? 22 : 8, b: 30 };
  const legend = [];
  {
    let lx = pad.l, row = 0;
    for (const [i, s] of series.entries()) {
      const tw = ctx.measureText(s.name).width + 26;
      if (lx + tw > cssW - pad.r && lx > pad.l) {
        lx = pad.l;
        row += 1;
      }
      legend.push({ x: lx, row, s, color: s.color || PALETTE[i % PALETTE.length] });
      lx += tw;
    }
    const legendTop = pad.t;
    if (series.length) pad.t += (row + 1) * 14 + 4;
    for (const l of legend) l.y = legendTop + l.row * 14 + 6;
  }
  const w = cssW - pad.l - pad.r;
  const h = Math.max(cssH - pad.t - pad.b, 10);
  if (title) {
    ctx.fillStyle = "#c9ced6";
    ctx.fillText(title, pad.l, 14);
  }

  const finite = (v) => typeof v === "number" && Number.isFinite(v);
  if (log === "auto") {
    // logarithmic when the positive values span more than two decades
    let lo = Infinity, hi = 0;
    for (const s of series) for (const [, y] of s.points) if (finite(y) && y > 0) { lo = Math.min(lo, y); hi = Math.max(hi, y); }
    log = hi > 0 && hi / lo > 100;
  }
  // on a log axis, values at or below zero are left out (gaps)
  const usable = (y) => finite(y) && (!log || y > 0);
  const ty = (v) => (log ? Math.log10(v) : v);
  let xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity;
  for (const s of series) {
    for (const [x, y] of s.points) {
      if (!finite(x) || !usable(y)) continue;
      xmin = Math.min(xmin, x);
      xmax = Math.max(xmax, x);
      const v = ty(y);
      ymin = Math.min(ymin, v);
      ymax = Math.max(ymax, v);
    }
  }
  ctx.strokeStyle = "#454b55";
  ctx.lineWidth = 1;
  ctx.strokeRect(pad.l + 0.5, pad.t + 0.5, w, h);
  if (!Number.isFinite(xmin)) {
    ctx.fillStyle = "#8b929c";
    ctx.fillText("no data yet", pad.l + 10, pad.t + h / 2);
    return;
  }
  if (xmax === xmin) xmax = xmin + 1;
  if (ymax === ymin) {
    ymax += log ? 0.5 : Math.abs(ymax) * 0.05 || 1;
    ymin -= log ? 0.5 : Math.abs(ymin) * 0.05 || 1;
  } else {
    const m = (ymax - ymin) * 0.06;
    ymax += m;
    if (!(ymin >= 0 && ymin - m < 0 && !log)) ymin -= m;
  }
  const X = (x) => pad.l + ((x - xmin) / (xmax - xmin)) * w;
  const Y = (v) => pad.t + h - ((v - ymin) / (ymax - ymin)) * h;

  // grid and ticks
  ctx.fillStyle = "#8b929c";
  ctx.strokeStyle = "#30353c";
  ctx.textAlign = "right";
  ctx.textBaseline = "middle";
  if (log) {
    for (let e = Math.ceil(ymin); e <= Math.floor(ymax); e++) {
      const y = Y(e);
      ctx.beginPath();
      ctx.moveTo(pad.l, y + 0.5);
      ctx.lineTo(pad.l + w, y + 0.5);
      ctx.stroke();
      ctx.fillText(fmt(Math.pow(10, e)), pad.l - 4, y);
    }
  } else {
    const step = niceStep(ymax - ymin, 5);
    for (let v = Math.ceil(ymin / step) * step; v <= ymax; v += step) {
      const y = Y(v);
      ctx.beginPath();
      ctx.moveTo(pad.l, y + 0.5);
      ctx.lineTo(pad.l + w, y + 0.5);
      ctx.stroke();
      ctx.fillText(fmt(v), pad.l - 4, y);
    }
  }
  ctx.textAlign = "center";
  ctx.textBaseline = "top";
  const xstep = Math.max(1, niceStep(xmax - xmin, 6));
  for (let x = Math.ceil(xmin / xstep) * xstep; x <= xmax; x += xstep) {
    ctx.fillText(fmt(x), X(x), pad.t + h + 4);
  }
  ctx.fillText(xLabel, pad.l + w / 2, pad.t + h + 16);

  // lines
  series.forEach((s, i) => {
    const color = s.color || PALETTE[i % PALETTE.length];
    ctx.strokeStyle = color;
    ctx.fillStyle = color;
    ctx.lineWidth = s.width || 1.6;
    ctx.beginPath();
    let started = false;
    const pts = s.points.filter(([x, y]) => finite(x) && usable(y));
    for (const [x, y] of s.points) {
      if (!finite(x) || !usable(y)) {
        started = false;
        continue;
      }
      const px = X(x), py = Y(ty(y));
      if (!started) {
        ctx.moveTo(px, py);
        started = true;
      } else ctx.lineTo(px, py);
    }
    ctx.stroke();
    if (pts.length === 1) {
      ctx.beginPath();
      ctx.arc(X(pts[0][0]), Y(ty(pts[0][1])), 2.5, 0, Math.PI * 2);
      ctx.fill();
    }
  });

  // legend
  ctx.textAlign = "left";
  ctx.textBaseline = "middle";
  for (const l of legend) {
    ctx.fillStyle = l.color;
    ctx.fillRect(l.x, l.y - 1, 14, 3);
    ctx.fillStyle = "#c9ced6";
    ctx.fillText(l.s.name, l.x + 18, l.y);
  }
}
