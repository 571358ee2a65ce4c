// relrl monitor: the learned tree. Graphviz's SVG (from /api/tree) is rebuilt from a short
// list of drawing elements and attributes -- no links, scripts, styles or foreign objects
// can come through, whatever a label held -- then panned (drag), zoomed (wheel, buttons),
// and the current leaf and its path from the root are marked. Plain JavaScript.
"use strict";

const SVG_NS = "http://www.w3.org/2000/svg";
const TREE_TAGS = new Set(["svg", "g", "title", "polygon", "polyline", "path", "ellipse",
                           "text", "tspan"]);
const TREE_ATTRS = new Set(["class", "transform", "points", "d", "cx", "cy", "rx", "ry", "x",
                            "y", "fill", "stroke", "stroke-width", "stroke-dasharray",
                            "font-family", "font-size", "font-weight", "font-style",
                            "text-anchor", "viewBox"]);

const tree = { svg: null, base: null, view: null, names: {}, parents: {}, nodes: {},
               edges: {}, marked: [], leaf: null, moved: false, follow: false };

// The drawing elements of an SVG text, copied into this page's document.
function cleanSvg(text) {
  const doc = new DOMParser().parseFromString(text, "image/svg+xml");
  const root = doc.documentElement;
  if (root.localName !== "svg" || root.namespaceURI !== SVG_NS ||
      doc.getElementsByTagName("parsererror").length) throw new Error("not an SVG picture");
  const copy = (node) => {
    if (node.nodeType === Node.TEXT_NODE) return document.createTextNode(node.nodeValue);
    if (node.nodeType !== Node.ELEMENT_NODE || node.namespaceURI !== SVG_NS ||
        !TREE_TAGS.has(node.localName)) return null;
    const el = document.createElementNS(SVG_NS, node.localName);
    for (const a of node.attributes)
      if (!a.namespaceURI && TREE_ATTRS.has(a.name)) el.setAttribute(a.name, a.value);
    for (const child of node.childNodes) {
      const c = copy(child);
      if (c) el.appendChild(c);
    }
    return el;
  };
  return copy(root);
}

function applyView() {
  if (tree.svg && tree.view) tree.svg.setAttribute("viewBox", tree.view.join(" "));
}

// Client pixels -> the picture's own units (the view's scale, as the SVG is fitted).
function unitsPerPixel() {
  const box = $("tree-box");
  return Math.max(tree.view[2] / (box.clientWidth || 1), tree.view[3] / (box.clientHeight || 1));
}

function toUser(clientX, clientY) {
  const m = tree.svg.getScreenCTM();
  if (!m) return [tree.view[0] + tree.view[2] / 2, tree.view[1] + tree.view[3] / 2];
  const p = new DOMPoint(clientX, clientY).matrixTransform(m.inverse());
  return [p.x, p.y];
}

function zoomTree(factor, at) {
  if (!tree.view) return;
  const [x, y, w, h] = tree.view;
  const [cx, cy] = at || [x + w / 2, y + h / 2];
  const nw = Math.min(Math.max(w * factor, 20), tree.base[2] * 8);
  const f = nw / w;
  tree.view = [cx - (cx - x) * f, cy - (cy - y) * f, w * f, h * f];
  tree.moved = true;
  applyView();
}

// The whole tree in the box, never drawn larger than its own size.
function fitView() {
  const box = $("tree-box"), [x, y, w, h] = tree.base;
  const bw = box.clientWidth, bh = box.clientHeight;
  if (!bw || !bh) return [...tree.base];
  const s = Math.max(w / bw, h / bh, 1);
  return [x + (w - bw * s) / 2, y + (h - bh * s) / 2, bw * s, bh * s];
}

function fitTree() {
  if (!tree.base) return;
  tree.view = fitView();
  tree.moved = false;
  applyView();
}

// The view centred on the current leaf, at the picture's own size (text as drawn), or the
// whole tree when it is smaller than the box.
function centreOnLeaf() {
  const el = tree.nodes[tree.names[String(tree.leaf)]];
  if (!el || !tree.svg) return;
  const box = $("tree-box"), r = el.getBoundingClientRect();
  const [cx, cy] = toUser(r.left + r.width / 2, r.top + r.height / 2);
  const w = Math.min(tree.base[2], box.clientWidth), h = Math.min(tree.base[3], box.clientHeight);
  const scale = Math.max(w / (box.clientWidth || 1), h / (box.clientHeight || 1));
  const vw = (box.clientWidth || 1) * scale, vh = (box.clientHeight || 1) * scale;
  tree.view = [cx - vw / 2, cy - vh / 2, vw, vh];
  applyView();
}

// Mark the leaf `leafId` (a node id of the learner's graph) and its path from the root.
function markLeaf(leafId) {
  tree.leaf = leafId;
  for (const el of tree.marked) el.classList.remove("current", "on-path");
  tree.marked = [];
  const box = $("tree-box");
  const name = leafId == null ? null : tree.names[String(leafId)];
  box.dataset.leaf = "";
  box.dataset.path = "0";
  if (!tree.svg) return;
  const leaf = name && tree.nodes[name];
  if (!leaf) {
    $("tree-note").textContent = leafId == null ? "" :
      "(this time unit's leaf is not in the tree drawn yet: it is redrawn once a second)";
    return;
  }
  $("tree-note").textContent = "";
  leaf.classList.add("current");
  tree.marked.push(leaf);
  let n = name, steps = 0;
  const seen = new Set([n]);
  while (tree.parents[n] && !seen.has(tree.parents[n])) {
    const p = tree.parents[n];
    for (const el of [tree.nodes[p], tree.edges[`${p}->${n}`]])
      if (el) { el.classList.add("on-path"); tree.marked.push(el); }
    seen.add(p); n = p; steps++;
  }
  box.dataset.leaf = name;
  box.dataset.path = String(steps);
  if (tree.follow) centreOnLeaf();
}

// A new picture of the tree (`data` from /api/tree); the view is kept when the user moved
// it, else the whole tree is shown.
function showTreePicture(data) {
  const svg = cleanSvg(data.svg);
  svg.setAttribute("preserveAspectRatio", "xMidYMid meet");
  const vb = (svg.getAttribute("viewBox") || "").split(/[\s,]+/).map(Number);
  const base = vb.length === 4 && vb.every(Number.isFinite) ? vb : [0, 0, 100, 100];
  tree.base = base;
  tree.svg = svg;
  tree.names = data.names || {};
  tree.parents = data.parents || {};
  tree.nodes = {}; tree.edges = {}; tree.marked = [];
  for (const g of svg.querySelectorAll("g.node")) {
    const title = g.querySelector("title");
    if (title) tree.nodes[title.textContent] = g;
  }
  for (const g of svg.querySelectorAll("g.edge")) {
    const title = g.querySelector("title");
    if (title) tree.edges[title.textContent] = g;
  }
  const holder = $("tree");
  clear(holder);
  holder.appendChild(svg);
  holder.hidden = false;
  holder.dataset.nodes = String(Object.keys(tree.nodes).length);
  if (!tree.moved || !tree.view) tree.view = fitView();
  applyView();
  const dl = $("leaf-legend");
  clear(dl);
  for (const entry of data.legend || []) {
    const dt = document.createElement("dt");
    dt.textContent = entry.example;
    const dd = document.createElement("dd");
    dd.textContent = entry.says;
    dl.appendChild(dt); dl.appendChild(dd);
  }
  markLeaf(tree.leaf);
}

function noTree(message) {
  tree.svg = null;
  $("tree").hidden = true;
  $("tree-note").textContent = message;
}

// Fetch and show the tree (live: the newest; replay: `{ t }`).
async function loadTree(params) {
  const r = await fetch(url("api/tree", params), { cache: "no-store" });
  if (r.status === 404) { noTree("(no tree: this learner has none yet)"); return; }
  if (!r.ok) { noTree(`(${(await r.text()).trim()})`); return; }
  showTreePicture(await r.json());
}

function setUpTree() {
  const box = $("tree-box");
  let drag = null;
  box.addEventListener("pointerdown", (e) => {
    if (!tree.view) return;
    drag = { x: e.clientX, y: e.clientY, view: [...tree.view], scale: unitsPerPixel() };
    box.setPointerCapture(e.pointerId);
    box.classList.add("dragging");
  });
  box.addEventListener("pointermove", (e) => {
    if (!drag) return;
    tree.view = [drag.view[0] - (e.clientX - drag.x) * drag.scale,
                 drag.view[1] - (e.clientY - drag.y) * drag.scale, drag.view[2], drag.view[3]];
    tree.moved = true;
    applyView();
  });
  const end = () => { drag = null; box.classList.remove("dragging"); };
  box.addEventListener("pointerup", end);
  box.addEventListener("pointercancel", end);
  box.addEventListener("wheel", (e) => {
    if (!tree.svg) return;
    e.preventDefault();
    zoomTree(Math.exp(e.deltaY * 0.0015), toUser(e.clientX, e.clientY));
  }, { passive: false });
  window.addEventListener("resize", () => { if (tree.svg && !tree.moved) fitTree(); });
  $("tree-fit").onclick = () => { $("tree-follow").checked = tree.follow = false; fitTree(); };
  $("tree-in").onclick = () => zoomTree(1 / 1.25);
  $("tree-out").onclick = () => zoomTree(1.25);
  $("tree-follow").onchange = (e) => {
    tree.follow = e.target.checked;
    if (tree.follow) { tree.moved = true; centreOnLeaf(); } else fitTree();
  };
}
