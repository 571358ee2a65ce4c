// relrl monitor: one page for the live session (server-sent events) and the replay (a
// timeline over the recorded trace). Plain JavaScript, no build step. Read-only: the page only
// ever sends GET requests. plots.js draws the canvases, tree.js the learned tree.
"use strict";

const token = new URLSearchParams(location.search).get("token");
const $ = (id) => document.getElementById(id);
const KEEP = 600;            // points of the necessity plot

const state = { info: null, series: [], view: null, necessities: [], tree: -1,
                frameShown: null, frameLoading: false, cursor: null, status: null,
                events: [] };

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

function items(ul, values, none) {
  clear(ul);
  for (const v of values) {
    const li = document.createElement("li");
    li.textContent = v;
    ul.appendChild(li);
  }
  if (!values.length && none) {
    const li = document.createElement("li");
    li.className = "note";
    li.textContent = none;
    ul.appendChild(li);
  }
}

function fmt(x, digits = 3) { return x == null ? "–" : Number(x).toFixed(digits); }

// -- the header and the status line -------------------------------------------------------

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
  const key = (colour, label) => {
    const s = document.createElement("span");
    const sw = document.createElement("i");
    sw.style.background = colour;
    s.appendChild(sw);
    s.appendChild(document.createTextNode(label));
    legend.appendChild(s);
  };
  state.necessities.forEach((n, i) => key(COLOURS[i % COLOURS.length], n));
  key("#999", "reward (lower strip)");
  if (info.perception === "symbolic")
    $("frame-note").textContent = "symbolic perception: facts are written directly, no frames";
}

// "run 2 of 5", "time unit 34 of 300": how far the current activity is.
function progressOf(s) {
  if (s.total) {
    const done = Math.min(s.done ?? 0, s.total);
    const what = s.activity === "naming" ? "execution" : "run";
    return [done, s.total, `${what} ${Math.min(done + 1, s.total)} of ${s.total}`];
  }
  if ((s.activity === "learning" || s.activity === "acting") && s.steps) {
    const u = state.view ? (state.view.unit ?? state.view.t) : 0;
    return [u, s.steps, `time unit ${u} of ${s.steps}`];
  }
  return [null, null, ""];
}

function showStatus() {
  const s = state.status;
  if (!s) return;
  $("status").dataset.activity = s.activity;
  $("status-activity").textContent = s.activity[0].toUpperCase() + s.activity.slice(1);
  $("status-detail").textContent = s.detail ? `— ${s.detail}` : "";
  const [done, total, count] = progressOf(s);
  const bar = $("status-progress");
  bar.hidden = total == null;
  if (total != null) { bar.max = total; bar.value = done; }
  $("status-count").textContent = count;
}

// Before the first time unit: what each picture will show, and what the session does now.
function showWaiting() {
  if (state.view) return;
  const s = state.status;
  const now = s ? `${s.activity}${progressOf(s)[2] ? " · " + progressOf(s)[2] : ""}`
                : "connecting to the session";
  const frame = $("frame");
  if (state.info && state.info.perception === "symbolic")
    drawNote(frame, ["symbolic perception: no frames", now], true);
  else
    drawNote(frame, ["no frame yet", now, "the robot's view appears when learning starts"],
             true);
  drawNecessities($("plot"), [], null, ["no time unit of learning yet", now]);
  showEvaluations();
}

// -- one time unit: every panel's function, in VIEW_PANELS ------------------------------

function showPercepts(v) {
  items($("percepts"), v.percepts || [], "none in this time unit");
  const mem = $("memory").tBodies[0];
  clear(mem);
  for (const [age, el] of v.memory || []) row(mem, [age, el]);
  $("memory-size").textContent = v.memory_size == null ? "" : `${v.memory_size} elements`;
}

function showNecessityNow(v) {
  text("reward", v.reward);
  text("state", v.state);
  const now = Object.entries(v.activation || {}).map(([k, y]) => `${k} ${fmt(y, 2)}`);
  $("necessity-now").textContent = `active: ${v.necessity || "none"} · ${now.join(", ")}`;
}

function showExplanation(v) {
  text("response", v.response || "nothing (no response allowed)");
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

function showHead(v) {
  const h = v.head;
  const tb = $("head").tBodies[0];
  clear(tb);
  if (!h) { $("head-note").textContent = "no head in this session (--head PORT drives one)"; return; }
  for (const [name, s] of Object.entries(h.servos || {}))
    row(tb, [name, s.us, (s.offset_us > 0 ? "+" : "") + s.offset_us, s.deg]);
  $("head-note").textContent = `looking ${h.looking_at || "?"}; ` +
    `angles nominal (0.09°/µs); ${h.clamped} values clamped to the calibration so far`;
}

function showGaze(v) {
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

// The leaf this time unit's response came from (tg: the chosen response's own leaf).
function showLeaf(v) {
  const e = v.explanation || {};
  const mine = (e.ranked || []).find((r) => r.response === v.response && r.leaf != null);
  markLeaf(mine ? mine.leaf : e.leaf ?? null);
}

const VIEW_PANELS = [showPercepts, showNecessityNow, showExplanation, showHead, showGaze,
                     showLeaf];

function showView(v) {
  if (!v) return;
  state.view = v;
  text("t", v.t);
  text("phase", v.phase);
  for (const panel of VIEW_PANELS) panel(v);
  showStatus();
}

// -- the camera frame with what perception found ------------------------------------------

function drawFrame(img, overlay) {
  const c = $("frame");
  if (c.width !== img.naturalWidth || c.height !== img.naturalHeight) {
    c.width = img.naturalWidth; c.height = img.naturalHeight;
  }
  const g = c.getContext("2d");
  g.drawImage(img, 0, 0);
  delete c.dataset.note;
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

function drawPlot() {
  drawNecessities($("plot"), state.series, state.cursor,
                  ["no time unit of learning yet", state.status ? state.status.activity : ""]);
}

// -- evaluations (the CGI curve) and naming ---------------------------------------------

function showEvents(events) {
  state.events = events || [];
  showEvaluations();
  const naming = state.events.filter((e) => e.kind === "naming").map((e) =>
    `t ${e.t}: execution ${e.execution}${e.on && e.on !== "simulator" ? " (SIMULATED)" : ""}` +
    `: ${Object.entries(e.counts || {}).map(([k, n]) => `${k} ${n}`).join(", ")}`);
  items($("naming"), naming, "no naming execution yet");
}

function showEvaluations() {
  const points = state.events.filter((e) => e.kind === "evaluation" && e.cgi_mean != null)
    .map((e) => ({ t: e.t ?? 0, units: e.units, mean: e.cgi_mean, std: e.cgi_std ?? 0,
                   simulated: !!(e.on && e.on !== "simulator") }));
  const info = state.info || {};
  const tMax = Math.max(info.last ?? 0, info.steps ?? 0, state.view ? state.view.t : 0);
  const s = state.status;
  const running = s && (s.activity === "initial evaluation" || s.activity === "evaluating");
  const empty = running ? [`the ${s.activity === "evaluating" ? "evaluation" : s.activity} ` +
                           "is running", progressOf(s)[2]]
                        : ["no evaluation yet", "the episode's script says when"];
  const cursor = info.mode === "replay" ? state.cursor : null;
  drawCgi($("cgi-plot"), points, tMax, cursor, empty);
  const shown = points.filter((p) => cursor == null || p.t <= cursor);
  const last = shown[shown.length - 1];
  $("cgi-last").textContent = last ? `last: CGI ${fmt(last.mean, 2)} ± ${fmt(last.std, 2)} ` +
    `at t ${last.t}${last.units != null ? ` (after ${last.units} time units of learning)` : ""}` +
    (last.simulated ? " · SIMULATED on the scripted world" : "") : "";
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
    if (msg.status) state.status = msg.status;
    for (const p of msg.series || []) state.series.push(p);
    if (state.series.length > KEEP) state.series.splice(0, state.series.length - KEEP);
    const v = msg.view;
    if (v) {
      showView(v);
      if (v.frame_seq != null) loadFrame(url("frame.jpg", { seq: v.frame_seq }), v.frame_seq,
                                         v.overlay);
    }
    showStatus();
    if (state.view) drawPlot(); else showWaiting();
    showEvents(msg.events);
    if (msg.tree_version !== state.tree) {
      state.tree = msg.tree_version;
      loadTree({ v: msg.tree_version }).catch(() => {});
    }
    if (msg.finished) {
      $("mode").textContent = "finished"; $("mode").className = "pill finished"; es.close();
    }
  };
  es.onerror = () => {
    if ($("mode").textContent !== "finished") {
      $("mode").textContent = "connection lost"; $("mode").className = "pill lost";
      state.status = { activity: "connection lost", detail: "the session's monitor stopped " +
                       "answering (the session ended, or its process was stopped)" };
      showStatus();
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
  function say() {    // the player's state, in the status line
    const t = Number(scrub.value), v = state.view;
    const at = `t ${t} of ${info.last}${v && v.phase ? `, phase "${v.phase}"` : ""}`;
    state.status = playing ? { activity: "playing", detail: `${at} · ❚❚ (or space) pauses` }
      : t >= info.last ? { activity: "at the end", detail: `${at} · press ▶ to play from ` +
                           "the start" }
      : { activity: "paused", detail: `press ▶ to play (or space); drag the slider or step ` +
          `with ← → · ${at}` };
    showStatus();
  }
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
      showEvaluations();
      if (v.frame_index != null)
        loadFrame(url(`frames/${v.frame_index}.jpg`), v.frame_index, v.overlay_of_frame ||
                  (v.frame_t === v.t ? v.overlay : null));
      else if (state.frameShown == null)
        drawNote($("frame"), ["no frame recorded", "at or before this time unit"], true);
      if (v.tree_version !== state.tree) {
        state.tree = v.tree_version;
        loadTree({ t: v.t }).catch(() => {});
      }
      say();
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
  const pause = () => { clearInterval(playing); playing = null; $("play").textContent = "▶"; };
  $("play").onclick = () => {
    if (playing) { pause(); say(); return; }
    if (Number(scrub.value) >= info.last) { scrub.value = info.first; go(info.first); }
    $("play").textContent = "❚❚";
    playing = setInterval(() => {
      if (Number(scrub.value) >= info.last) { pause(); say(); return; }
      step(1);
    }, 200);
    say();
  };
  document.addEventListener("keydown", (e) => {
    if (e.target === scrub && e.key.startsWith("Arrow")) return;   // the slider moves itself
    if (e.key === "ArrowLeft") step(-1);
    if (e.key === "ArrowRight") step(1);
    if (e.key === " " && e.target.tagName !== "BUTTON") { e.preventDefault(); $("play").onclick(); }
  });
  say();
  go(info.first);
}

async function main() {
  const info = await getJSON("api/info");
  showInfo(info);
  setUpTree();
  showEvents([]);
  showWaiting();
  if (info.mode === "replay") await replay(info); else live();
}

window.addEventListener("resize", () => { drawPlot(); showEvaluations(); });
main().catch((e) => { $("mode").textContent = "error"; $("mode").className = "pill lost";
                      console.error(e); });
