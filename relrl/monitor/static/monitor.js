// relrl monitor: one page for the live session (server-sent events) and the replay (a
// timeline over the recorded trace). Plain JavaScript, no build step. Read-only: the page only
// ever sends GET requests.
"use strict";

const token = new URLSearchParams(location.search).get("token");
const $ = (id) => document.getElementById(id);
const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"];
const KEEP = 600;            // points of the necessity plot

const state = { info: null, series: [], view: null, necessities: [], tree: -1,
                frameShown: null, frameLoading: false, cursor: null };

function url(path, params = {}) {
  const q = new URLSearchParams(params);
  if (token) q.set("token", token);
  const s = q.toString();
  return s ? `${path}?${s}` : path;
}

async function getJSON(path, params) {
  const r = await fetch(url(path, params), { cache: "no-store" });
  if (!r.ok) throw new Error(`${path}: ${r.status}`);
  return r.json();
}

function text(id, value) { $(id).textContent = value == null ? "–" : String(value); }

function clear(el) { while (el.firstChild) el.removeChild(el.firstChild); }

function row(tbody, cells, cls) {
  const tr = document.createElement("tr");
  if (cls) tr.className = cls;
  for (const c of cells) {
    const td = document.createElement("td");
    td.textContent = c == null ? "" : String(c);
    tr.appendChild(td);
  }
  tbody.appendChild(tr);
}

function fmt(x, digits = 3) { return x == null ? "–" : Number(x).toFixed(digits); }

// -- the header -------------------------------------------------------------------------

function showInfo(info) {
  state.info = info;
  state.necessities = info.necessities || [];
  const mode = $("mode");
  mode.textContent = info.mode === "replay" ? "replay" : "live";
  mode.className = "pill " + info.mode;
  text("title", `${info.episode || ""} · ${info.learner || ""} · seed ${info.seed ?? "–"}`);
  const where = info.where || {};
  const lines = [];
  if (where.learning) lines.push(`learning on the ${where.learning}`);
  if (where.metrics) lines.push(`gaze metrics: ${where.metrics}`);
  if (where.simulated_evaluation)
    lines.push("evaluations and naming are SIMULATED (the scripted world, not the devices)");
  if (lines.length) { $("where").hidden = false; $("where").textContent = lines.join(" · "); }
  const legend = $("legend");
  clear(legend);
  state.necessities.forEach((n, i) => {
    const s = document.createElement("span");
    const sw = document.createElement("i");
    sw.style.background = COLOURS[i % COLOURS.length];
    s.appendChild(sw);
    s.appendChild(document.createTextNode(n));
    legend.appendChild(s);
  });
  const r = document.createElement("span");
  const sw = document.createElement("i");
  sw.style.background = "#999";
  r.appendChild(sw);
  r.appendChild(document.createTextNode("reward (lower strip)"));
  legend.appendChild(r);
  if (info.perception === "symbolic")
    $("frame-note").textContent = "symbolic perception: facts are written directly, no frames";
}

// -- one time unit ----------------------------------------------------------------------

function showView(v) {
  if (!v) return;
  state.view = v;
  text("t", v.t);
  text("phase", v.phase);
  text("reward", v.reward);
  text("state", v.state);
  text("response", v.response || "nothing (no response allowed)");
  const now = Object.entries(v.activation || {}).map(([k, y]) => `${k} ${fmt(y, 2)}`);
  $("necessity-now").textContent = `active: ${v.necessity || "none"} · ${now.join(", ")}`;
  // percepts and working memory
  const ul = $("percepts");
  clear(ul);
  for (const p of v.percepts || []) {
    const li = document.createElement("li");
    li.textContent = p;
    ul.appendChild(li);
  }
  const mem = $("memory").tBodies[0];
  clear(mem);
  for (const [age, el] of v.memory || []) row(mem, [age, el]);
  $("memory-size").textContent = v.memory_size == null ? "" : `${v.memory_size} elements`;
  showExplanation(v);
  showHead(v.head);
  const m = v.metrics || {};
  text("cgi", m.cgi == null ? "n/a" : fmt(m.cgi));
  text("shifts", `${m.correct_shifts ?? "–"}/${m.shifts ?? "–"}`);
  text("contacts", `${m.eye_contacts ?? "–"}/${m.opportunities ?? "–"}`);
  const cg = v.caregiver || {};
  const objs = Object.entries(cg.objects || {}).map(([p, k]) => `${k} at ${p}`).join(", ");
  $("caregiver").textContent = `caregiver looks ${cg.look ?? "?"}${cg.estimated ?
    " (estimated from perception)" : ""}${cg.mode ? ", " + cg.mode : ""}${objs ? "; " + objs :
    ""}; robot looks ${v.focus ?? "?"}${v.heard && v.heard.length ? "; heard " +
    v.heard.join(", ") : ""}${v.said ? '; says "' + v.said + '"' : ""}`;
}

function showExplanation(v) {
  const e = v.explanation || {};
  const box = $("explanation");
  box.dataset.t = v.t;
  $("exp-head").textContent = `${e.learner || ""} · state ${e.state ?? "–"} · necessity ` +
    `${e.necessity ?? "–"}` + ("leaf" in e ? ` · leaf ${e.leaf ?? "null"}` : "");
  const path = $("path");
  clear(path);
  for (const s of e.path || []) {
    const li = document.createElement("li");
    li.className = s.holds ? "yes" : "no";
    li.textContent = `${s.test} → ${s.holds ? "yes" : "no"}`;
    path.appendChild(li);
  }
  const tb = $("ranked").tBodies[0];
  clear(tb);
  const ranked = e.ranked || [];
  for (const r of ranked) {
    const value = r.q ?? r.fitness ?? r.value;
    row(tb, [r.response, value == null ? "" : fmt(value, 3)],
        r.response === v.response ? "chosen" : "");
  }
  if (v.response && !ranked.some((r) => r.response === v.response))
    row(tb, [v.response, "initial value (nothing stored for it here yet)"], "chosen");
  if (!ranked.length && !v.response)
    row(tb, ["no stored choices here: every response starts equal", ""]);
  $("allowed").textContent = `allowed: ${(v.allowed || []).join(", ")}`;
}

function showHead(h) {
  const tb = $("head").tBodies[0];
  clear(tb);
  if (!h) { $("head-note").textContent = "no head in this session (--head PORT drives one)"; return; }
  for (const [name, s] of Object.entries(h.servos || {}))
    row(tb, [name, s.us, (s.offset_us > 0 ? "+" : "") + s.offset_us, s.deg]);
  $("head-note").textContent = `looking ${h.looking_at || "?"}; ` +
    `angles nominal (0.09°/µs); ${h.clamped} values clamped to the calibration so far`;
}

// -- the camera frame with what perception found ------------------------------------------

function drawFrame(img, overlay) {
  const c = $("frame");
  if (c.width !== img.naturalWidth || c.height !== img.naturalHeight) {
    c.width = img.naturalWidth; c.height = img.naturalHeight;
  }
  const g = c.getContext("2d");
  g.drawImage(img, 0, 0);
  const lines = [];
  if (overlay && overlay.face) {
    const [x, y, w, h] = overlay.face.box;
    g.strokeStyle = "#00ff66"; g.lineWidth = 2; g.strokeRect(x, y, w, h);
    g.fillStyle = "#00ff66"; g.font = "11px sans-serif";
    g.fillText(`${overlay.face.pose} pan ${overlay.face.pan} tilt ${overlay.face.tilt}`,
               x, Math.max(11, y - 3));
    lines.push(`face: pose ${overlay.face.pose} (pan ${overlay.face.pan}°, tilt ` +
               `${overlay.face.tilt}°, ${overlay.face.detector})`);
  }
  if (overlay && overlay.object) {
    const o = overlay.object;
    const [x, y, w, h] = o.box;
    g.strokeStyle = "#ffd400"; g.lineWidth = 2; g.strokeRect(x, y, w, h);
    const [px, py] = o.peak;
    g.beginPath(); g.moveTo(px - 6, py); g.lineTo(px + 6, py); g.moveTo(px, py - 6);
    g.lineTo(px, py + 6); g.strokeStyle = "#ff3b30"; g.stroke();
    g.fillStyle = "#ffd400"; g.font = "11px sans-serif";
    g.fillText(`${o.colour || "object"} @ ${o.place}`, x, Math.max(11, y - 3));
    lines.push(`object: ${o.colour || "no colour name"} at ${o.place}; saliency peak ` +
               `(${px}, ${py}) = ${o.saliency}`);
  }
  $("overlay-text").textContent = lines.join(" · ") || "perception found no face and no object";
  c.dataset.framesDrawn = String(Number(c.dataset.framesDrawn) + 1);
}

function loadFrame(src, key, overlay) {
  // only the newest frame is wanted; one request at a time (a slow browser skips frames)
  state.wanted = { src, key, overlay };
  if (state.frameLoading || key === state.frameShown) return;
  state.frameLoading = true;
  const img = new Image();
  img.onload = () => {
    state.frameLoading = false; state.frameShown = key;
    $("frame").dataset.frameSeq = String(key); drawFrame(img, overlay);
    const w = state.wanted;                     // a newer one arrived meanwhile: fetch it now
    if (w && w.key !== key) loadFrame(w.src, w.key, w.overlay);
  };
  img.onerror = () => { state.frameLoading = false; };
  img.src = src;
}

// -- the necessity plot -----------------------------------------------------------------

function drawPlot() {
  const c = $("plot");
  const w = c.clientWidth || c.width;
  if (c.width !== w) c.width = w;
  const g = c.getContext("2d");
  const H = c.height, strip = 40, top = 8, plotH = H - strip - top - 14;
  g.clearRect(0, 0, c.width, H);
  const pts = state.series;
  c.dataset.points = String(pts.length);
  if (!pts.length) return;
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
  // reward strip
  const base = H - 14 - strip / 2, scale = (strip / 2 - 2) / Math.max(1, rhi, -rlo);
  for (const [t, , r] of pts) {
    g.fillStyle = r > 0 ? "#2f8132" : r < 0 ? "#b3261e" : "#999";
    g.fillRect(X(t) - 1, r > 0 ? base - r * scale : base, 2, Math.max(1, Math.abs(r) * scale));
  }
  if (state.cursor != null) {
    g.strokeStyle = "#1f2933"; g.setLineDash([4, 3]);
    g.beginPath(); g.moveTo(X(state.cursor), top); g.lineTo(X(state.cursor), H - 14); g.stroke();
    g.setLineDash([]);
  }
}

// -- events (evaluations, naming) -------------------------------------------------------

function showEvents(events) {
  const ul = $("events");
  clear(ul);
  for (const e of events || []) {
    const li = document.createElement("li");
    const sim = e.on && e.on !== "simulator" ? " (SIMULATED)" : "";
    li.textContent = e.kind === "evaluation"
      ? `t ${e.t}: evaluation${sim} CGI ${fmt(e.cgi_mean)} ± ${fmt(e.cgi_std)}`
      : `t ${e.t}: naming execution ${e.execution}${sim}: ${JSON.stringify(e.counts)}`;
    if (sim) li.className = "sim";
    ul.appendChild(li);
  }
  if (!ul.firstChild) ul.appendChild(document.createTextNode("none yet"));
}

function showTree(param) {
  const img = $("tree");
  img.onload = () => { img.hidden = false; $("tree-note").textContent = ""; };
  img.onerror = () => {
    img.hidden = true;
    $("tree-note").textContent = "(no tree: this learner has none yet)";
    fetch(img.src, { cache: "no-store" }).then(async (r) => {   // say why, when it is not 404
      if (r.status !== 404) $("tree-note").textContent = `(${(await r.text()).trim()})`;
    }).catch(() => {});
  };
  img.src = url("tree.svg", param);
}

// -- live -------------------------------------------------------------------------------

function live() {
  const es = new EventSource(url("api/events"));
  es.onmessage = (ev) => {
    const msg = JSON.parse(ev.data);
    const info = JSON.stringify(msg.info);
    if (msg.info && info !== state.infoText) {
      state.infoText = info;
      showInfo({ mode: "live", ...msg.info });
    }
    for (const p of msg.series || []) state.series.push(p);
    if (state.series.length > KEEP) state.series.splice(0, state.series.length - KEEP);
    drawPlot();
    const v = msg.view;
    if (v) {
      showView(v);
      if (v.frame_seq != null) loadFrame(url("frame.jpg", { seq: v.frame_seq }), v.frame_seq,
                                         v.overlay);
    }
    showEvents(msg.events);
    if (msg.tree_version !== state.tree) { state.tree = msg.tree_version;
                                           showTree({ v: msg.tree_version }); }
    if (msg.finished) {
      $("mode").textContent = "finished"; $("mode").className = "pill finished"; es.close();
    }
  };
  es.onerror = () => {
    if ($("mode").textContent !== "finished") {
      $("mode").textContent = "connection lost"; $("mode").className = "pill lost";
    }
  };
}

// -- replay -----------------------------------------------------------------------------

async function replay(info) {
  $("timeline").hidden = false;
  const scrub = $("scrub");
  scrub.min = info.first; scrub.max = info.last; scrub.value = info.first;
  state.series = await getJSON("api/series");
  showEvents(info.events);
  let playing = null, pending = null, busy = false;
  async function go(t) {
    if (busy) { pending = t; return; }
    busy = true;
    try {
      const v = await getJSON(`api/step/${t}`);
      state.cursor = v.t;
      $("scrub-label").textContent = `t ${v.t} of ${info.last}` +
        (v.frame_t != null ? ` · frame of t ${v.frame_t}` : " · no frame recorded");
      showView(v);
      drawPlot();
      if (v.frame_index != null)
        loadFrame(url(`frames/${v.frame_index}.jpg`), v.frame_index, v.overlay_of_frame ||
                  (v.frame_t === v.t ? v.overlay : null));
      if (v.tree_version !== state.tree) { state.tree = v.tree_version;
                                           showTree({ t: v.t }); }
    } finally {
      busy = false;
      if (pending != null) { const p = pending; pending = null; go(p); }
    }
  }
  scrub.addEventListener("input", () => go(Number(scrub.value)));
  const step = (d) => { scrub.value = Math.min(info.last, Math.max(info.first,
                                               Number(scrub.value) + d)); go(Number(scrub.value)); };
  $("prev").onclick = () => step(-1);
  $("next").onclick = () => step(1);
  $("play").onclick = () => {
    if (playing) { clearInterval(playing); playing = null; $("play").textContent = "▶"; return; }
    $("play").textContent = "❚❚";
    playing = setInterval(() => {
      if (Number(scrub.value) >= info.last) { $("play").onclick(); return; }
      step(1);
    }, 200);
  };
  document.addEventListener("keydown", (e) => {
    if (e.key === "ArrowLeft") step(-1);
    if (e.key === "ArrowRight") step(1);
  });
  go(info.first);
}

async function main() {
  const info = await getJSON("api/info");
  showInfo(info);
  showEvents([]);
  if (info.mode === "replay") await replay(info); else live();
}

window.addEventListener("resize", drawPlot);
$("tree").addEventListener("click", () => $("tree").classList.toggle("fit"));
main().catch((e) => { $("mode").textContent = "error"; $("mode").className = "pill lost";
                      console.error(e); });
