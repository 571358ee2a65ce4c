// relrl monitor: the plots drawn on canvases -- the necessities over time with the reward
// strip, the CGI of the evaluations, and the notes a canvas shows before it has anything to
// draw. Plain JavaScript, no build step.
"use strict";

const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"];

// A canvas as wide as it is laid out (its height is its own).
function fitWidth(c) {
  const w = c.clientWidth || c.width;
  if (c.width !== w) c.width = w;
  return c.getContext("2d");
}

// Lines of text centred on a canvas: what it will show, and why it shows nothing yet.
function drawNote(c, lines, dark = false) {
  c.dataset.note = lines.filter(Boolean).join(" · ");
  const g = c.getContext("2d");
  g.fillStyle = dark ? "#323f4b" : "#ffffff";
  g.fillRect(0, 0, c.width, c.height);
  g.fillStyle = dark ? "#f5f7fa" : "#616e7c";
  g.textAlign = "center";
  const top = c.height / 2 - (lines.length - 1) * 9;
  lines.forEach((line, i) => {
    g.font = i === 0 ? "bold 13px sans-serif" : "12px sans-serif";
    g.fillText(line, c.width / 2, top + i * 18, c.width - 16);
  });
  g.textAlign = "start";
}

// The necessity units' outputs over time (one line each) and the reward in a strip below
// (green positive, red negative); `pts` are [t, [outputs...], reward]; `cursor` a time unit.
function drawNecessities(c, pts, cursor, empty) {
  const g = fitWidth(c);
  const H = c.height, strip = 40, top = 8, plotH = H - strip - top - 14;
  g.clearRect(0, 0, c.width, H);
  c.dataset.points = String(pts.length);
  if (!pts.length) { drawNote(c, empty); return; }
  delete c.dataset.note;
  let lo = 0, hi = 1, rlo = 0, rhi = 0;
  for (const [, ys, r] of pts) {
    for (const y of ys) { if (y < lo) lo = y; if (y > hi) hi = y; }
    if (r < rlo) rlo = r; if (r > rhi) rhi = r;
  }
  const t0 = pts[0][0], t1 = Math.max(pts[pts.length - 1][0], t0 + 1);
  const X = (t) => 30 + (c.width - 36) * (t - t0) / (t1 - t0);
  const Y = (y) => top + plotH * (1 - (y - lo) / (hi - lo || 1));
  g.strokeStyle = "#d9dde2"; g.fillStyle = "#616e7c"; g.font = "10px sans-serif";
  for (const y of [lo, (lo + hi) / 2, hi]) {
    g.beginPath(); g.moveTo(30, Y(y)); g.lineTo(c.width, Y(y)); g.stroke();
    g.fillText(y.toFixed(1), 2, Y(y) + 3);
  }
  g.fillText(`t ${t0}`, 30, H - 2);
  g.fillText(`t ${t1}`, c.width - 44, H - 2);
  const n = pts[0][1].length;
  for (let k = 0; k < n; k++) {
    g.beginPath();
    g.strokeStyle = COLOURS[k % COLOURS.length]; g.lineWidth = 1.5;
    pts.forEach(([t, ys], i) => (i ? g.lineTo(X(t), Y(ys[k])) : g.moveTo(X(t), Y(ys[k]))));
    g.stroke();
  }
  const base = H - 14 - strip / 2, scale = (strip / 2 - 2) / Math.max(1, rhi, -rlo);
  for (const [t, , r] of pts) {
    g.fillStyle = r > 0 ? "#2f8132" : r < 0 ? "#b3261e" : "#999";
    g.fillRect(X(t) - 1, r > 0 ? base - r * scale : base, 2, Math.max(1, Math.abs(r) * scale));
  }
  if (cursor != null) {
    g.strokeStyle = "#1f2933"; g.setLineDash([4, 3]);
    g.beginPath(); g.moveTo(X(cursor), top); g.lineTo(X(cursor), H - 14); g.stroke();
    g.setLineDash([]);
  }
}

// Whole-number ticks, about `n` of them, from 0 to `hi`.
function ticks(hi, n = 5) {
  const raw = Math.max(1, hi / n), mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= raw);
  const out = [];
  for (let v = 0; v <= hi + 1e-9; v += step) out.push(v);
  return out;
}

// The CGI of each evaluation (Fig. 6): the mean over its runs with the s.d. as a bar, over
// the session's time units; evaluations on the scripted world of a session on devices are
// drawn hollow and said to be simulated. `cursor`: replay's time unit (the evaluations after
// it are drawn faint).
function drawCgi(c, points, tMax, cursor, empty) {
  const g = fitWidth(c);
  const W = c.width, H = c.height, left = 34, right = 10, top = 10, bottom = 30;
  g.clearRect(0, 0, W, H);
  c.dataset.points = String(points.length);
  if (!points.length) { drawNote(c, empty); return; }
  delete c.dataset.note;
  const hi = Math.max(1, tMax, ...points.map((p) => p.t));
  const X = (t) => left + (W - left - right) * t / hi;
  const Y = (y) => top + (H - top - bottom) * (1 - y);
  g.font = "10px sans-serif"; g.lineWidth = 1;
  for (const y of [0, 0.25, 0.5, 0.75, 1]) {
    g.strokeStyle = y === 0 || y === 1 ? "#bcc3cb" : "#e4e7eb";
    g.beginPath(); g.moveTo(left, Y(y)); g.lineTo(W - right, Y(y)); g.stroke();
    g.fillStyle = "#616e7c"; g.fillText(y.toFixed(2), 2, Y(y) + 3);
  }
  g.textAlign = "center";
  for (const v of ticks(hi)) g.fillText(String(v), X(v), H - bottom + 12);
  g.fillText("time unit t", left + (W - left - right) / 2, H - 4);
  g.textAlign = "start";
  if (cursor != null) {
    g.strokeStyle = "#1f2933"; g.setLineDash([4, 3]);
    g.beginPath(); g.moveTo(X(cursor), top); g.lineTo(X(cursor), H - bottom); g.stroke();
    g.setLineDash([]);
  }
  g.strokeStyle = COLOURS[0]; g.lineWidth = 1.5;
  g.beginPath();
  points.forEach((p, i) => (i ? g.lineTo(X(p.t), Y(p.mean)) : g.moveTo(X(p.t), Y(p.mean))));
  g.stroke();
  for (const p of points) {
    g.globalAlpha = cursor != null && p.t > cursor ? 0.3 : 1;
    const lo = Math.max(0, p.mean - p.std), up = Math.min(1, p.mean + p.std);
    g.strokeStyle = COLOURS[0]; g.lineWidth = 1;
    g.beginPath(); g.moveTo(X(p.t), Y(lo)); g.lineTo(X(p.t), Y(up));
    g.moveTo(X(p.t) - 3, Y(lo)); g.lineTo(X(p.t) + 3, Y(lo));
    g.moveTo(X(p.t) - 3, Y(up)); g.lineTo(X(p.t) + 3, Y(up)); g.stroke();
    g.beginPath(); g.arc(X(p.t), Y(p.mean), 3.5, 0, 2 * Math.PI);
    g.fillStyle = p.simulated ? "#ffffff" : COLOURS[0]; g.fill(); g.stroke();
  }
  g.globalAlpha = 1;
  const shown = points.filter((p) => cursor == null || p.t <= cursor);
  const last = shown[shown.length - 1];
  if (!last) return;
  g.fillStyle = "#1f2933"; g.font = "bold 11px sans-serif";
  g.textAlign = X(last.t) > W - 60 ? "end" : "start";
  g.fillText(last.mean.toFixed(2), X(last.t) + (g.textAlign === "end" ? -6 : 6),
             Math.max(top + 10, Y(last.mean) - 6));
  g.textAlign = "start";
}
