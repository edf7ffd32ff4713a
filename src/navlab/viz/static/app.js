// navlab's viewer page: rviz's displays and tools on a canvas, fed by the server's streams.
import { Link } from "./net.js";
import * as R from "./render.js";
import { drawGraph } from "./graph.js";

const $ = (id) => document.getElementById(id);
const canvas = $("view");
const ctx = canvas.getContext("2d");
const TELEOP_KEYS = "uiojklm,.qzwxec";
const MAP_PAL = R.mapPalette(), COST_PAL = R.costmapPalette();

const view = {
  cx: 0, cy: 0, scale: 60, fitted: false,
  apply(c) { const d = devicePixelRatio; c.setTransform(d * this.scale, 0, 0, -d * this.scale,
    d * (canvas.clientWidth / 2 - this.cx * this.scale), d * (canvas.clientHeight / 2 + this.cy * this.scale)); },
  toScreen(x, y) { return [canvas.clientWidth / 2 + (x - this.cx) * this.scale, canvas.clientHeight / 2 - (y - this.cy) * this.scale]; },
  toWorld(sx, sy) { return [this.cx + (sx - canvas.clientWidth / 2) / this.scale, this.cy - (sy - canvas.clientHeight / 2) / this.scale]; },
};

const store = { state: null, grids: {}, scans: {}, paths: {}, poses: {}, polygons: {}, traces: {}, graph: null };
const layers = {}; // name -> visible
const stats = { fps: 0, frames: 0, bytes: 0, acks: [], errors: [] };
let dirty = true, tool = "pan", drag = null, framesThisSecond = 0, fpsMark = performance.now();

function layerOn(name, dflt = true) {
  if (!(name in layers)) {
    layers[name] = dflt;
    const label = document.createElement("label");
    const box = document.createElement("input");
    box.type = "checkbox"; box.checked = dflt; box.dataset.layer = name;
    box.onchange = () => { layers[name] = box.checked; dirty = true; };
    label.append(box, " " + name);
    $("layers").append(label);
  }
  return layers[name];
}

function onMessage(m) {
  switch (m.k) {
    case "state": store.state = m; updateStatus(m); break;
    case "grid": case "tiles": {
      const pal = m.topic.includes("costmap") ? COST_PAL : MAP_PAL;
      (store.grids[m.topic] ||= new R.GridLayer(pal)).apply(m);
      if (!view.fitted && !m.topic.includes("costmap")) fit();
      break;
    }
    case "scan": store.scans[m.topic] = m; break;
    case "path": store.paths[m.topic] = m; break;
    case "poses": store.poses[m.topic] = m; break;
    case "polygon": store.polygons[m.topic] = m; break;
    case "trace": store.traces[m.topic] = m; break;
    case "graph": store.graph = m; if (!$("graph").hidden) drawGraph($("graphbody"), m); break;
    case "ack": stats.acks.push(m); if (m.error) { stats.errors.push(m.error); flash(m.error); } break;
    case "error": stats.errors.push(m.error); flash(m.error); break;
  }
  dirty = true;
}

function flash(text) { $("outcome").textContent = text; $("outcome").className = "bad"; }

const link = new Link(onMessage, (s) => { $("conn").textContent = s; $("conn").className = s === "connected" ? "good" : "bad"; });

function fit() {
  const g = Object.entries(store.grids).find(([t]) => !t.includes("costmap"))?.[1]?.geo
    || Object.values(store.grids)[0]?.geo;
  if (!g) return;
  const w = g.w * g.res, h = g.h * g.res;
  view.cx = g.ox + w / 2; view.cy = g.oy + h / 2;
  view.scale = Math.max(5, Math.min(canvas.clientWidth / w, canvas.clientHeight / h) * 0.95);
  view.fitted = true; dirty = true;
}

function updateStatus(s) {
  $("simtime").textContent = `t = ${s.t.toFixed(1)} s`;
  $("rtf").textContent = s.replay ? `replay ${s.speed}x` : `RTF ${s.rtf.toFixed(2)} (${s.speed > 0 ? s.speed + "x" : "max"})`;
  $("pause").textContent = s.paused ? "Resume" : "Pause";
  if (!s.replay && document.activeElement !== $("speed")) $("speed").value = String(s.speed);
  const mb = s.move_base;
  $("mbstate").textContent = mb ? `move_base: ${mb.state}` : "";
  const out = mb && mb.outcome;
  if (out) {
    $("outcome").textContent = `goal (${out.goal.map((v) => v.toFixed(2)).join(", ")}): ${out.state}${out.reason ? " — " + out.reason : ""}`;
    $("outcome").className = out.state === "SUCCEEDED" ? "good" : "bad";
  }
  document.body.classList.toggle("replay", !!s.replay);
  if (s.replay) {
    $("timeline").hidden = false;
    const seek = $("seek");
    seek.min = s.t0; seek.max = s.t1;
    if (!seekDragging) seek.value = s.t;
    $("ttime").textContent = `${s.t.toFixed(2)} / ${s.t1.toFixed(2)} s`;
    $("play").textContent = s.paused ? "Play" : "Pause";
  }
}

function gridOrder(t) { return t.includes("local_costmap") ? 2 : t.includes("costmap") ? 1 : 0; }
function pathColor(t) { return t.includes("local_plan") ? "#2c2" : t.includes("plan") ? "#36f" : "#dd4"; }

function draw() {
  const d = devicePixelRatio, W = canvas.clientWidth, H = canvas.clientHeight;
  if (canvas.width !== Math.round(W * d) || canvas.height !== Math.round(H * d)) {
    canvas.width = Math.round(W * d); canvas.height = Math.round(H * d);
  }
  const s = store.state;
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  if (!s) { ctx.fillStyle = "#303030"; ctx.fillRect(0, 0, canvas.width, canvas.height); return; }
  const tf = s.tf;
  drawBackground(tf);
  ctx.drawImage(bg, 0, 0);
  const traceColor = (t) => (t.includes("ground_truth") ? "#fff" : "#f90");
  for (const [t, f] of Object.entries(store.traces)) if (layerOn("trace " + t)) R.drawPolyline(ctx, view, tf[f.frame], f.data, traceColor(t), 1.5);
  for (const [t, f] of Object.entries(store.paths)) if (layerOn(t)) R.drawPolyline(ctx, view, tf[f.frame], f.data, pathColor(t), 2.5);
  for (const [t, f] of Object.entries(store.scans)) {
    if (layerOn(t)) R.drawScan(ctx, view, f.pose && f.fixed === s.fixed ? f.pose : tf[f.frame], f, "#f33");
  }
  for (const [t, f] of Object.entries(store.poses)) {
    if (t.endsWith("current_goal")) { if (layerOn(t) && f.n) R.drawArrow(ctx, view, R.compose(tf[f.frame] || [0, 0, 0], [...f.data]), "#f0f", 0.5); }
    else if (layerOn(t)) R.drawArrows(ctx, view, tf[f.frame], f.data, "#f55", 8);
  }
  for (const [t, f] of Object.entries(store.polygons)) if (layerOn(t, t.includes("local")) && tf[f.frame]) R.drawPolyline(ctx, view, tf[f.frame], f.data, "#0f0", 2, true);
  if (layerOn("robot")) R.drawRobot(ctx, view, tf[s.base], "#ff0", 0.2);
  if (layerOn("tf", false)) for (const [name, T] of Object.entries(tf)) R.drawAxes(ctx, view, T, name, true);
  if (layerOn("obstacles")) for (const o of s.obstacles || []) R.drawObstacle(ctx, view, o, drag && drag.obstacle === o.name ? "#fff" : "#fa0");
  if (drag && (drag.tool === "goal" || drag.tool === "pose")) {
    R.drawArrow(ctx, view, [drag.x, drag.y, drag.yaw], drag.tool === "goal" ? "#f0f" : "#0f0", 0.5);
  }
  if (drag && drag.obstacle) {
    const o = (s.obstacles || []).find((q) => q.name === drag.obstacle);
    if (o) R.drawObstacle(ctx, view, { ...o, x: drag.x, y: drag.y }, "#fff");
  }
}

// draw at most maxFps frames/s (and only when something changed): smooth, and leaves the CPU to the simulation
const settings = { maxFps: 30 };
let lastDraw = 0;
// The grids change a few times a second: they are drawn into a background canvas only when they, the view,
// the layers or their frames' poses changed, and each frame starts from a copy of it.
const bg = document.createElement("canvas");
const bgCtx = bg.getContext("2d");
let bgKey = "";
function drawBackground(tf) {
  const order = Object.keys(store.grids).sort((a, b) => gridOrder(a) - gridOrder(b)).filter((t) => layerOn(t));
  const frames = order.map((t) => store.grids[t].geo && tf[store.grids[t].geo.frame]);
  const key = JSON.stringify([canvas.width, canvas.height, view.cx, view.cy, view.scale, order,
    order.map((t) => store.grids[t].version), frames.map((T) => T && T.map((v) => v.toFixed(3)))]);
  if (key === bgKey) return;
  bgKey = key;
  if (bg.width !== canvas.width || bg.height !== canvas.height) { bg.width = canvas.width; bg.height = canvas.height; }
  bgCtx.setTransform(1, 0, 0, 1, 0, 0);
  bgCtx.fillStyle = "#303030"; bgCtx.fillRect(0, 0, bg.width, bg.height);
  for (const t of order) store.grids[t].draw(bgCtx, view, tf, t.includes("costmap") ? 0.7 : 1.0);
}

function frame(now) {
  if (dirty && now - lastDraw >= 1000 / settings.maxFps - 2) { dirty = false; lastDraw = now; draw(); stats.frames++; framesThisSecond++; }
  if (now - fpsMark >= 1000) { stats.fps = (framesThisSecond * 1000) / (now - fpsMark); framesThisSecond = 0; fpsMark = now; }
  stats.bytes = link.bytes;
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);

// --- tools --------------------------------------------------------------------------------------

function setTool(name) {
  tool = name;
  for (const b of document.querySelectorAll("#tools button")) b.classList.toggle("on", b.dataset.tool === name);
}
for (const b of document.querySelectorAll("#tools button")) b.onclick = () => setTool(b.dataset.tool);

function eventWorld(ev) { const r = canvas.getBoundingClientRect(); return view.toWorld(ev.clientX - r.left, ev.clientY - r.top); }

function obstacleAt(x, y) {
  for (const o of store.state?.obstacles || []) {
    const half = o.kind === "cylinder" ? o.dims[0] : Math.max(o.dims[0], o.dims[1]) / 2;
    if (Math.hypot(x - o.x, y - o.y) <= half + 0.05) return o;
  }
  return null;
}

canvas.addEventListener("pointerdown", (ev) => {
  canvas.focus();
  const [x, y] = eventWorld(ev);
  canvas.setPointerCapture(ev.pointerId);
  if (tool === "goal" || tool === "pose") drag = { tool, x, y, yaw: 0 };
  else if (tool === "box" || tool === "cylinder") { link.send({ op: "spawn", kind: tool, x, y, frame: store.state?.fixed }); }
  else if (tool === "delete") { const o = obstacleAt(x, y); if (o) link.send({ op: "delete", name: o.name }); }
  else {
    const o = obstacleAt(x, y);
    drag = o ? { tool: "pan", obstacle: o.name, x: o.x, y: o.y, dx: o.x - x, dy: o.y - y }
      : { tool: "pan", sx: ev.clientX, sy: ev.clientY, cx: view.cx, cy: view.cy };
  }
  dirty = true;
});

canvas.addEventListener("pointermove", (ev) => {
  const [x, y] = eventWorld(ev);
  $("cursor").textContent = `(${x.toFixed(2)}, ${y.toFixed(2)})`;
  if (!drag) return;
  if (drag.tool === "goal" || drag.tool === "pose") {
    if (Math.hypot(x - drag.x, y - drag.y) > 1e-3) drag.yaw = Math.atan2(y - drag.y, x - drag.x);
  } else if (drag.obstacle) { drag.x = x + drag.dx; drag.y = y + drag.dy; }
  else { view.cx = drag.cx - (ev.clientX - drag.sx) / view.scale; view.cy = drag.cy + (ev.clientY - drag.sy) / view.scale; }
  dirty = true;
});

canvas.addEventListener("pointerup", () => {
  if (!drag) return;
  const frameId = store.state?.fixed;
  if (drag.tool === "goal") link.send({ op: "goal", x: drag.x, y: drag.y, yaw: drag.yaw, frame: frameId });
  else if (drag.tool === "pose") link.send({ op: "initialpose", x: drag.x, y: drag.y, yaw: drag.yaw, frame: frameId });
  else if (drag.obstacle) link.send({ op: "move", name: drag.obstacle, x: drag.x, y: drag.y });
  drag = null; dirty = true;
});

canvas.addEventListener("wheel", (ev) => {
  ev.preventDefault();
  const [x, y] = eventWorld(ev);
  const k = Math.exp(-ev.deltaY * 0.0015);
  view.scale = Math.min(2000, Math.max(2, view.scale * k));
  const [x2, y2] = eventWorld(ev);
  view.cx += x - x2; view.cy += y - y2; dirty = true;
}, { passive: false });

window.addEventListener("resize", () => { dirty = true; });

// --- buttons, keys, teleop ------------------------------------------------------------------------

$("cancel").onclick = () => link.send({ op: "cancel" });
$("pause").onclick = () => link.send({ op: store.state?.paused ? "resume" : "pause" });
$("speed").onchange = () => link.send({ op: "speed", value: Number($("speed").value) });
$("fit").onclick = fit;
$("graphbtn").onclick = () => {
  $("graph").hidden = !$("graph").hidden;
  if (!$("graph").hidden && store.graph) drawGraph($("graphbody"), store.graph);
  dirty = true;
};
for (const k of "uiojklm,.") {
  const b = document.createElement("button");
  b.textContent = k; b.dataset.key = k;
  b.onclick = () => link.send({ op: "key", key: k });
  $("teleop").append(b);
}
document.addEventListener("keydown", (ev) => {
  if (ev.ctrlKey || ev.metaKey || ev.altKey || ev.target.tagName === "INPUT" || ev.target.tagName === "SELECT") return;
  if (TELEOP_KEYS.includes(ev.key)) { link.send({ op: "key", key: ev.key }); ev.preventDefault(); }
  else if (ev.key === "Escape") { drag = null; setTool("pan"); dirty = true; }
});

// --- replay timeline --------------------------------------------------------------------------------

let seekDragging = false;
$("seek").addEventListener("input", () => { seekDragging = true; link.send({ op: "seek", t: Number($("seek").value) }); });
$("seek").addEventListener("change", () => { seekDragging = false; });
$("play").onclick = () => link.send({ op: store.state?.paused ? "play" : "pause" });
$("rspeed").onchange = () => link.send({ op: "speed", value: Number($("rspeed").value) });

// for tests and scripts: the view's transform, what was received and drawn
window.navlab = { view, store, stats, layers, settings, send: (o) => link.send(o), fit, setTool };
