// navlab's viewer page: rviz's displays and tools on a canvas, fed by the server's streams.
import { Link } from "./net.js";
import * as R from "./render.js";
import { drawGraph } from "./graph.js";

const $ = (id) => document.getElementById(id);
const canvas = $("view");
const ctx = canvas.getContext("2d", { alpha: false });
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
let dirty = false, tool = "pan", drag = null, framesThisSecond = 0, fpsMark = performance.now();

function layerOn(name, dflt = true) {
  if (!(name in layers)) {
    layers[name] = dflt;
    const label = document.createElement("label");
    const box = document.createElement("input");
    box.type = "checkbox"; box.checked = dflt; box.dataset.layer = name;
    box.onchange = () => { layers[name] = box.checked; invalidate(); };
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
  invalidate();
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
  view.fitted = true; invalidate();
}

// The status bar: text is written only when it changed, and the clock and RTF (new in every state) at most
// STATUS_HZ times a second: each change of the page's text costs the browser a layout, a paint and a frame.
const STATUS_HZ = 5;
let statusMark = -1e9, statusTimer = 0;
function setText(id, text, cls) {
  const e = $(id);
  if (e.textContent !== text) e.textContent = text;
  if (cls !== undefined && e.className !== cls) e.className = cls;
}

function updateStatus(s) {
  if (document.body.classList.contains("replay") !== !!s.replay) document.body.classList.toggle("replay", !!s.replay);
  if (s.replay) {
    $("timeline").hidden = false;
    const seek = $("seek");
    if (seek.min !== String(s.t0)) seek.min = s.t0;
    if (seek.max !== String(s.t1)) seek.max = s.t1;
  }
  const now = performance.now();
  if (now - statusMark >= 1000 / STATUS_HZ) {
    statusMark = now;
    setText("simtime", `t = ${s.t.toFixed(1)} s`);
    setText("rtf", s.replay ? `replay ${s.speed}x` : `RTF ${s.rtf.toFixed(2)} (${s.speed > 0 ? s.speed + "x" : "max"})`);
    if (s.replay) {
      if (!seekDragging) $("seek").value = s.t;
      setText("ttime", `${s.t.toFixed(2)} / ${s.t1.toFixed(2)} s`);
    }
  } else if (!statusTimer) {
    statusTimer = setTimeout(() => { statusTimer = 0; updateStatus(store.state); }, statusMark + 1000 / STATUS_HZ - now);
  }
  setText("pause", s.paused ? "Resume" : "Pause");
  if (!s.replay && document.activeElement !== $("speed") && $("speed").value !== String(s.speed)) $("speed").value = String(s.speed);
  const mb = s.move_base;
  setText("mbstate", mb ? `move_base: ${mb.state}` : "");
  const out = mb && mb.outcome;
  if (out) {
    setText("outcome", `goal (${out.goal.map((v) => v.toFixed(2)).join(", ")}): ${out.state}${out.reason ? " — " + out.reason : ""}`,
      out.state === "SUCCEEDED" ? "good" : "bad");
  }
  if (s.replay) setText("play", s.paused ? "Play" : "Pause");
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
  const moving = drawBackground(tf, s.fixed);
  ctx.drawImage(bg, 0, 0);
  for (const t of moving) store.grids[t].draw(ctx, view, tf, t.includes("costmap") ? 0.7 : 1.0);
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
// The grids in the fixed frame (the map, the global costmap) change a few times a second: they are drawn into
// a background canvas only when they, the view or the layers changed, and each frame starts from a copy of
// it. Grids in a moving frame (the local costmap in odom, placed by tf) are drawn over it in every frame.
const bg = document.createElement("canvas");
const bgCtx = bg.getContext("2d", { alpha: false });
let bgKey = "";
function drawBackground(tf, fixed) {
  const order = Object.keys(store.grids).sort((a, b) => gridOrder(a) - gridOrder(b)).filter((t) => layerOn(t));
  let n = 0;
  while (n < order.length && store.grids[order[n]].geo?.frame === fixed) n++;
  const still = order.slice(0, n);
  const key = JSON.stringify([canvas.width, canvas.height, view.cx, view.cy, view.scale, fixed, still,
    still.map((t) => store.grids[t].version)]);
  if (key !== bgKey) {
    bgKey = key;
    if (bg.width !== canvas.width || bg.height !== canvas.height) { bg.width = canvas.width; bg.height = canvas.height; }
    bgCtx.setTransform(1, 0, 0, 1, 0, 0);
    bgCtx.fillStyle = "#303030"; bgCtx.fillRect(0, 0, bg.width, bg.height);
    for (const t of still) store.grids[t].draw(bgCtx, view, tf, t.includes("costmap") ? 0.7 : 1.0);
  }
  return order.slice(n);
}

// A frame is requested only when something changed, and no sooner than 1/maxFps after the last one: an idle
// page asks the browser for no frames at all (a requestAnimationFrame loop costs the browser every vsync).
let scheduled = false;
function invalidate() {
  dirty = true;
  if (scheduled) return;
  scheduled = true;
  const wait = lastDraw + 1000 / settings.maxFps - performance.now();
  if (wait > 1) setTimeout(() => requestAnimationFrame(frame), wait);
  else requestAnimationFrame(frame);
}
function frame(now) {
  scheduled = false;
  if (!dirty) return;
  dirty = false; lastDraw = now;
  draw();
  stats.frames++; framesThisSecond++;
  if (now - fpsMark >= 1000) { stats.fps = (framesThisSecond * 1000) / (now - fpsMark); framesThisSecond = 0; fpsMark = now; }
  stats.bytes = link.bytes;
}
invalidate();

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
  invalidate();
});

canvas.addEventListener("pointermove", (ev) => {
  const [x, y] = eventWorld(ev);
  $("cursor").textContent = `(${x.toFixed(2)}, ${y.toFixed(2)})`;
  if (!drag) return;
  if (drag.tool === "goal" || drag.tool === "pose") {
    if (Math.hypot(x - drag.x, y - drag.y) > 1e-3) drag.yaw = Math.atan2(y - drag.y, x - drag.x);
  } else if (drag.obstacle) { drag.x = x + drag.dx; drag.y = y + drag.dy; }
  else { view.cx = drag.cx - (ev.clientX - drag.sx) / view.scale; view.cy = drag.cy + (ev.clientY - drag.sy) / view.scale; }
  invalidate();
});

canvas.addEventListener("pointerup", () => {
  if (!drag) return;
  const frameId = store.state?.fixed;
  if (drag.tool === "goal") link.send({ op: "goal", x: drag.x, y: drag.y, yaw: drag.yaw, frame: frameId });
  else if (drag.tool === "pose") link.send({ op: "initialpose", x: drag.x, y: drag.y, yaw: drag.yaw, frame: frameId });
  else if (drag.obstacle) link.send({ op: "move", name: drag.obstacle, x: drag.x, y: drag.y });
  drag = null; invalidate();
});

canvas.addEventListener("wheel", (ev) => {
  ev.preventDefault();
  const [x, y] = eventWorld(ev);
  const k = Math.exp(-ev.deltaY * 0.0015);
  view.scale = Math.min(2000, Math.max(2, view.scale * k));
  const [x2, y2] = eventWorld(ev);
  view.cx += x - x2; view.cy += y - y2; invalidate();
}, { passive: false });

window.addEventListener("resize", () => { invalidate(); });

// --- buttons, keys, teleop ------------------------------------------------------------------------

$("cancel").onclick = () => link.send({ op: "cancel" });
$("pause").onclick = () => link.send({ op: store.state?.paused ? "resume" : "pause" });
$("speed").onchange = () => link.send({ op: "speed", value: Number($("speed").value) });
$("fit").onclick = fit;
$("graphbtn").onclick = () => {
  $("graph").hidden = !$("graph").hidden;
  if (!$("graph").hidden && store.graph) drawGraph($("graphbody"), store.graph);
  invalidate();
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
  else if (ev.key === "Escape") { drag = null; setTool("pan"); invalidate(); }
});

// --- replay timeline --------------------------------------------------------------------------------

let seekDragging = false;
$("seek").addEventListener("input", () => { seekDragging = true; link.send({ op: "seek", t: Number($("seek").value) }); });
$("seek").addEventListener("change", () => { seekDragging = false; });
$("play").onclick = () => link.send({ op: store.state?.paused ? "play" : "pause" });
$("rspeed").onchange = () => link.send({ op: "speed", value: Number($("rspeed").value) });

// for tests and scripts: the view's transform, what was received and drawn
window.navlab = { view, store, stats, layers, settings, send: (o) => link.send(o), fit, setTool };
