// navlab's viewer page: rviz's displays and tools on a canvas, fed by the server's streams.
import { Link } from "./net.js";
import { Scene, displayOf, FIXED_DISPLAYS } from "./scene.js";
import { drawGraph } from "./graph.js";

const $ = (id) => document.getElementById(id);
const canvas = $("view");
const TELEOP_KEYS = "uiojklm,.qzwxec";

const view = {
  cx: 0, cy: 0, scale: 60, fitted: false,
  toScreen(x, y) { return [canvas.clientWidth / 2 + (x - this.cx) * this.scale, canvas.clientHeight / 2 - (y - this.cy) * this.scale]; },
  toWorld(sx, sy) { return [this.cx + (sx - canvas.clientWidth / 2) / this.scale, this.cy - (sy - canvas.clientHeight / 2) / this.scale]; },
};
const viewNow = () => ({ cx: view.cx, cy: view.cy, scale: view.scale, W: canvas.clientWidth, H: canvas.clientHeight, d: devicePixelRatio });

const store = { state: null, grids: {}, scans: {}, paths: {}, poses: {}, polygons: {}, traces: {}, graph: null };
const layers = {}; // name -> visible
const stats = { fps: 0, frames: 0, bytes: 0, acks: [], errors: [] };
let tool = "pan", drag = null, maxFps = 30, fpsMark = performance.now(), fpsFrames = 0;

function countFrames(n) {
  stats.frames = n; stats.bytes = link.bytes;
  const now = performance.now();
  if (now - fpsMark >= 1000) { stats.fps = ((n - fpsFrames) * 1000) / (now - fpsMark); fpsMark = now; fpsFrames = n; }
}

// The canvas is drawn by a Scene (scene.js): in a worker, on the canvas handed over as an OffscreenCanvas, so
// drawing and the canvas's frames cost the page's own thread nothing; on this thread where a browser cannot
// hand a canvas to a worker (or with ?worker=0 in the address).
function makeRenderer() {
  const asked = new URLSearchParams(location.search).get("worker") !== "0";
  if (asked && canvas.transferControlToOffscreen && typeof Worker === "function") {
    const off = canvas.transferControlToOffscreen();
    const worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module" });
    const waiting = new Map();
    let asks = 0;
    const ask = (key, body) => new Promise((resolve) => { waiting.set(++asks, resolve); worker.postMessage({ [key]: { id: asks, ...body } }); });
    worker.onmessage = (ev) => {
      const m = ev.data;
      if (m.frames !== undefined) countFrames(m.frames);
      else { const r = waiting.get(m.pixel ?? m.renders); waiting.delete(m.pixel ?? m.renders); if (r) r(m.rgba ?? m.value); }
    };
    worker.onerror = (ev) => { stats.errors.push(String(ev.message)); flash(`drawing failed: ${ev.message}`); };
    worker.postMessage({ canvas: off, set: { view: viewNow(), maxFps } }, [off]);
    return {
      worker: true,
      // the message is moved to the worker, not copied (a copy costs this thread ~1 ms a message): what this
      // thread keeps of it (a scan's ranges, a path's points) was copied out of it when decoded
      batch: (buf) => worker.postMessage({ batch: buf }, [buf]),
      keep: (m) => { if (m.data) m.data = m.data.slice(); },
      frame: () => {},
      set: (o) => worker.postMessage({ set: o }),
      pixel: (x, y) => ask("pixel", { x, y }),
      renders: () => ask("renders", {}),
    };
  }
  const scene = new Scene(canvas, countFrames);
  scene.set({ view: viewNow(), maxFps });
  return { worker: false, batch: () => {}, keep: () => {}, frame: (m) => scene.receive(m), set: (o) => scene.set(o),
    pixel: async (x, y) => scene.pixel(x, y), renders: async () => scene.renders() };
}

function display(name, dflt) {
  if (name in layers) return;
  layers[name] = dflt;
  const label = document.createElement("label");
  const box = document.createElement("input");
  box.type = "checkbox"; box.checked = dflt; box.dataset.layer = name;
  box.onchange = () => { layers[name] = box.checked; renderer.set({ layers: { [name]: box.checked } }); };
  // long names keep their distinct end ("…local_costmap/costmap", "…local_costmap/footprint"); the whole in a tooltip
  label.append(box, " " + (name.length > 28 ? "…" + name.slice(-27) : name));
  label.title = name;
  $("layers").append(label);
}

function onMessage(m) {
  renderer.keep(m);
  switch (m.k) {
    case "state":
      if (!store.state) for (const [name, on] of FIXED_DISPLAYS) display(name, on);
      store.state = m; updateStatus(m); break;
    case "grid": case "tiles": {
      const { cells: _, ...geo } = m;
      if (m.k === "grid" || store.grids[m.topic]) store.grids[m.topic] = { geo };
      if (!view.fitted && !m.topic.includes("costmap")) fit();
      break;
    }
    case "scan": store.scans[m.topic] = m; break;
    case "path": store.paths[m.topic] = m; break;
    case "poses": store.poses[m.topic] = m; break;
    case "polygon": store.polygons[m.topic] = m; break;
    case "trace": store.traces[m.topic] = m; break;
    case "cloud": case "image": break; // drawn by the scene (a display toggle each)
    case "graph": store.graph = m; if (!$("graph").hidden) drawGraph($("graphbody"), m); break;
    case "ack": stats.acks.push(m); if (m.error) { stats.errors.push(m.error); flash(m.error); } break;
    case "error": stats.errors.push(m.error); flash(m.error); break;
  }
  const d = displayOf(m);
  if (d) display(...d);
  renderer.frame(m);
}

function flash(text) { $("outcome").textContent = text; $("outcome").className = "bad"; }

const renderer = makeRenderer();
const link = new Link(onMessage, (s) => { $("conn").textContent = s; $("conn").className = s === "connected" ? "good" : "bad"; }, renderer.batch);

function viewChanged() { renderer.set({ view: viewNow() }); }
function dragChanged() { renderer.set({ drag }); }

function fit() {
  const g = Object.entries(store.grids).find(([t]) => !t.includes("costmap"))?.[1]?.geo
    || Object.values(store.grids)[0]?.geo;
  if (!g) return;
  const w = g.w * g.res, h = g.h * g.res;
  view.cx = g.ox + w / 2; view.cy = g.oy + h / 2;
  view.scale = Math.max(5, Math.min(canvas.clientWidth / w, canvas.clientHeight / h) * 0.95);
  view.fitted = true; viewChanged();
}

// The status bar: text is written only when it changed (each change of the page's text costs the browser a
// layout, a paint and a frame of its own). The clock and the RTF, new in every state, are drawn in the canvas's
// corner with the scene; the replay's timeline follows at most STATUS_HZ times a second.
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
    const now = performance.now();
    if (now - statusMark >= 1000 / STATUS_HZ) {
      statusMark = now;
      if (!seekDragging) $("seek").value = s.t;
    } else if (!statusTimer) {
      statusTimer = setTimeout(() => { statusTimer = 0; updateStatus(store.state); }, statusMark + 1000 / STATUS_HZ - now);
    }
  }
  // the same time and precision as the canvas clock (drawClock), on every state, so the two never disagree
  if (s.replay) setText("ttime", `t = ${s.t.toFixed(1)} / ${s.t1.toFixed(1)} s`);
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
  dragChanged();
});

canvas.addEventListener("pointermove", (ev) => {
  const [x, y] = eventWorld(ev);
  $("cursor").textContent = `(${x.toFixed(2)}, ${y.toFixed(2)})`;
  if (!drag) return;
  if (drag.tool === "goal" || drag.tool === "pose") {
    if (Math.hypot(x - drag.x, y - drag.y) > 1e-3) drag.yaw = Math.atan2(y - drag.y, x - drag.x);
  } else if (drag.obstacle) { drag.x = x + drag.dx; drag.y = y + drag.dy; }
  else { view.cx = drag.cx - (ev.clientX - drag.sx) / view.scale; view.cy = drag.cy + (ev.clientY - drag.sy) / view.scale; viewChanged(); return; }
  dragChanged();
});

canvas.addEventListener("pointerup", () => {
  if (!drag) return;
  const frameId = store.state?.fixed;
  if (drag.tool === "goal") link.send({ op: "goal", x: drag.x, y: drag.y, yaw: drag.yaw, frame: frameId });
  else if (drag.tool === "pose") link.send({ op: "initialpose", x: drag.x, y: drag.y, yaw: drag.yaw, frame: frameId });
  else if (drag.obstacle) link.send({ op: "move", name: drag.obstacle, x: drag.x, y: drag.y });
  drag = null; dragChanged();
});

canvas.addEventListener("wheel", (ev) => {
  ev.preventDefault();
  const [x, y] = eventWorld(ev);
  const k = Math.exp(-ev.deltaY * 0.0015);
  view.scale = Math.min(2000, Math.max(2, view.scale * k));
  const [x2, y2] = eventWorld(ev);
  view.cx += x - x2; view.cy += y - y2; viewChanged();
}, { passive: false });

new ResizeObserver(viewChanged).observe(canvas); // the window, or the graph beside the canvas

// --- buttons, keys, teleop ------------------------------------------------------------------------

$("cancel").onclick = () => link.send({ op: "cancel" });
$("pause").onclick = () => link.send({ op: store.state?.paused ? "resume" : "pause" });
$("speed").onchange = () => link.send({ op: "speed", value: Number($("speed").value) });
$("fit").onclick = fit;
$("graphbtn").onclick = () => {
  $("graph").hidden = !$("graph").hidden;
  if (!$("graph").hidden && store.graph) drawGraph($("graphbody"), store.graph);
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
  else if (ev.key === "Escape") { drag = null; setTool("pan"); dragChanged(); }
});

// --- replay timeline --------------------------------------------------------------------------------

let seekDragging = false;
$("seek").addEventListener("input", () => { seekDragging = true; link.send({ op: "seek", t: Number($("seek").value) }); });
$("seek").addEventListener("change", () => { seekDragging = false; });
$("play").onclick = () => link.send({ op: store.state?.paused ? "play" : "pause" });
$("rspeed").onchange = () => link.send({ op: "speed", value: Number($("rspeed").value) });

// draw at most maxFps frames/s (and only when something changed): smooth, and leaves the CPU to the simulation
const settings = {
  get maxFps() { return maxFps; },
  set maxFps(v) { maxFps = v; renderer.set({ maxFps: v }); },
};

// for tests and scripts: the view's transform, what was received and drawn, a pixel of the canvas (a promise),
// how often the scene's caches were drawn anew (a promise)
window.navlab = { view, store, stats, layers, settings, send: (o) => link.send(o), fit, setTool,
  pixel: (x, y) => renderer.pixel(x, y), renders: () => renderer.renders(), worker: renderer.worker };
