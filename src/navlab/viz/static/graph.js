// rqt_graph in the page: nodes (ellipses) and topics (boxes, with their rate), publisher -> topic -> subscriber,
// left to right, at the positions Graphviz's dot gave the server (graph.layout: layered, cycles handled, no
// overlaps); without Graphviz on the server, in columns by the longest path from the sources (cycles cut).
const SVG = "http://www.w3.org/2000/svg";
const HIDDEN_TOPICS = ["/tf_static", "/clock", "/rosout"];

function el(name, attrs, text) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text; // text nodes only: names never become markup
  return e;
}

export function layout(graph) {
  const succ = new Map();
  const add = (v) => { if (!succ.has(v)) succ.set(v, []); };
  graph.nodes.forEach(add);
  for (const [t, { pub, sub }] of Object.entries(graph.topics)) {
    if (HIDDEN_TOPICS.includes(t) || (!pub.length && !sub.length)) continue;
    add(t);
    for (const p of pub) { add(p); succ.get(p).push(t); }
    for (const s of sub) { add(s); succ.get(t).push(s); }
  }
  const layer = new Map([...succ.keys()].map((v) => [v, 0]));
  const n = succ.size;
  for (let k = 0; k < n; k++) {
    let changed = false;
    for (const [v, outs] of succ) for (const w of outs) {
      if (layer.get(w) < layer.get(v) + 1 && layer.get(v) + 1 < n) { layer.set(w, layer.get(v) + 1); changed = true; }
    }
    if (!changed) break;
  }
  return { succ, layer };
}

function arrowDefs(svg) {
  const defs = el("defs", {});
  const marker = el("marker", { id: "arrow", viewBox: "0 0 10 10", refX: 10, refY: 5, markerWidth: 6, markerHeight: 6, orient: "auto" });
  marker.append(el("path", { d: "M0,0 L10,5 L0,10 z", fill: "#555" }));
  defs.append(marker); svg.append(defs);
}

function drawLaidOut(host, graph) {
  const { width, height, vertices, edges } = graph.layout;
  const pad = 8;
  const svg = el("svg", { width: width + 2 * pad, height: height + 2 * pad, viewBox: `${-pad} ${-pad} ${width + 2 * pad} ${height + 2 * pad}` });
  arrowDefs(svg);
  for (const { points } of edges) {
    const [p0, ...rest] = points;
    let d = `M${p0[0]},${p0[1]}`;
    for (let i = 0; i + 2 < rest.length; i += 3) d += ` C${rest[i]} ${rest[i + 1]} ${rest[i + 2]}`;
    svg.append(el("path", { d, fill: "none", stroke: "#888", "marker-end": "url(#arrow)" }));
  }
  for (const v of Object.values(vertices)) {
    const isTopic = v.kind === "topic";
    const g = el("g", { "data-name": v.name, "data-kind": v.kind });
    if (isTopic) g.append(el("rect", { x: v.x - v.w / 2, y: v.y - v.h / 2, width: v.w, height: v.h, fill: "#e8f0ff", stroke: "#47a" }));
    else g.append(el("ellipse", { cx: v.x, cy: v.y, rx: v.w / 2, ry: v.h / 2, fill: "#fff2cc", stroke: "#a83" }));
    const rate = isTopic && graph.rates ? graph.rates[v.name] : undefined;
    g.append(el("text", { x: v.x, y: v.y + (isTopic ? -3 : 4), "text-anchor": "middle", "font-size": 11 }, v.name));
    if (isTopic) g.append(el("text", { x: v.x, y: v.y + 12, "text-anchor": "middle", "font-size": 10, fill: "#456" }, rate !== undefined ? `${rate} Hz` : ""));
    g.append(el("title", {}, isTopic ? `${v.name} (${graph.types?.[v.name] || ""}) ${rate ?? ""} Hz` : v.name));
    svg.append(g);
  }
  host.replaceChildren(svg);
}

export function drawGraph(host, graph) {
  if (graph.layout) return drawLaidOut(host, graph);
  const { succ, layer } = layout(graph);
  const cols = new Map();
  for (const v of [...layer.keys()].sort()) {
    const c = layer.get(v);
    if (!cols.has(c)) cols.set(c, []);
    cols.get(c).push(v);
  }
  const colW = 190, rowH = 34, pos = new Map();
  let rows = 1;
  for (const [c, vs] of cols) { vs.forEach((v, r) => pos.set(v, [20 + c * colW, 24 + r * rowH])); rows = Math.max(rows, vs.length); }
  const svg = el("svg", { width: 40 + cols.size * colW, height: 40 + rows * rowH });
  arrowDefs(svg);
  const boxW = 160;
  for (const [v, outs] of succ) for (const w of outs) {
    const [x1, y1] = pos.get(v), [x2, y2] = pos.get(w);
    svg.append(el("line", { x1: x1 + boxW, y1, x2, y2, stroke: "#888", "marker-end": "url(#arrow)" }));
  }
  for (const [v, [x, y]] of pos) {
    const isTopic = v in graph.topics;
    const g = el("g", { "data-name": v });
    if (isTopic) g.append(el("rect", { x, y: y - 12, width: boxW, height: 24, fill: "#e8f0ff", stroke: "#47a" }));
    else g.append(el("ellipse", { cx: x + boxW / 2, cy: y, rx: boxW / 2, ry: 13, fill: "#fff2cc", stroke: "#a83" }));
    const rate = isTopic && graph.rates ? graph.rates[v] : undefined;
    const label = v.length > 26 ? "…" + v.slice(-25) : v;
    g.append(el("text", { x: x + 6, y: y + 4 }, rate !== undefined ? `${label}  ${rate} Hz` : label));
    g.append(el("title", {}, isTopic ? `${v} (${graph.types?.[v] || ""}) ${rate ?? ""} Hz` : v));
    svg.append(g);
  }
  host.replaceChildren(svg);
}
