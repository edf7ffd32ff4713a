// What the canvas shows, and when it is drawn: the frames received, the view, the displays switched on and the
// tool being dragged. It runs in a worker on the page's canvas handed over as an OffscreenCanvas (worker.js), or
// on the page's thread where a browser cannot do that (app.js). It never touches the page's document.
import * as R from "./render.js";

const MAP_PAL = R.mapPalette(), COST_PAL = R.costmapPalette();
const ALPHA = (t) => (t.includes("costmap") ? 0.7 : 1.0);
const gridOrder = (t) => (t.includes("local_costmap") ? 2 : t.includes("costmap") ? 1 : 0);
const pathColor = (t) => (t.includes("local_plan") ? "#2c2" : t.includes("plan") ? "#36f" : "#dd4");
const traceColor = (t) => (t.includes("ground_truth") ? "#1a9e3a" : "#f90"); // truth green (as in the PNGs), visible on white
// the display each kind of frame belongs to, and whether it is shown before the user says
export function displayOf(m) {
  switch (m.k) {
    case "grid": case "tiles": case "scan": case "path": case "poses": case "cloud": case "image": return [m.topic, true];
    case "polygon": return [m.topic, m.topic.includes("local")];
    case "trace": return ["trace " + m.topic, true];
    default: return null;
  }
}
export const FIXED_DISPLAYS = [["robot", true], ["tf", false], ["obstacles", true]];

export class Scene {
  // onFrame(count): called after each frame drawn
  constructor(canvas, onFrame) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d", { alpha: false });
    this.onFrame = onFrame;
    this.store = { state: null, grids: {}, scans: {}, paths: {}, poses: {}, polygons: {}, traces: {}, clouds: {}, images: {} };
    this.layers = {};
    for (const [name, on] of FIXED_DISPLAYS) this.layers[name] = on;
    this.drag = null;
    this.maxFps = 30;
    this.frames = 0;
    const scene = this;
    this.view = {
      cx: 0, cy: 0, scale: 60, W: canvas.width, H: canvas.height, d: 1,
      apply(c) { const d = this.d; c.setTransform(d * this.scale, 0, 0, -d * this.scale, d * (this.W / 2 - this.cx * this.scale), d * (this.H / 2 + this.cy * this.scale)); },
      toScreen(x, y) { return [this.W / 2 + (x - this.cx) * this.scale, this.H / 2 - (y - this.cy) * this.scale]; },
    };
    // The grids in the fixed frame (the map, the global costmap) change a few times a second: they are drawn
    // into a background canvas only when they, the view or the displays changed, and each frame starts from a copy.
    this.bg = R.makeCanvas(1, 1);
    this.bgKey = ""; this.bgRenders = 0;
    this.moving = {}; // topic -> R.MovingGrid: grids in a moving frame (the local costmap in odom)
    this.traces = {}; // topic -> R.Trace
    this.dirty = false; this.scheduled = false; this.lastDraw = -1e9;
    this.tick = (now) => scene.frame(now);
  }

  // a decoded frame from the server
  receive(m) {
    const s = this.store;
    switch (m.k) {
      case "state": s.state = m; break;
      case "grid": case "tiles": (s.grids[m.topic] ||= new R.GridLayer(m.topic.includes("costmap") ? COST_PAL : MAP_PAL)).apply(m); break;
      case "scan": s.scans[m.topic] = m; break;
      case "path": s.paths[m.topic] = m; break;
      case "poses": s.poses[m.topic] = m; break;
      case "polygon": s.polygons[m.topic] = m; break;
      case "trace": s.traces[m.topic] = m; break;
      case "cloud": s.clouds[m.topic] = m; break;
      case "image": s.images[m.topic] = R.imageCanvas(m); break;
      default: return;
    }
    const d = displayOf(m);
    if (d && !(d[0] in this.layers)) this.layers[d[0]] = d[1];
    this.invalidate();
  }

  // what the page changed: {view: {cx, cy, scale, W, H, d}, layers: {name: on}, drag, maxFps}
  set(o) {
    if (o.view) {
      Object.assign(this.view, o.view);
      const w = Math.round(this.view.W * this.view.d), h = Math.round(this.view.H * this.view.d);
      if (this.canvas.width !== w || this.canvas.height !== h) { this.canvas.width = w; this.canvas.height = h; }
    }
    if (o.layers) Object.assign(this.layers, o.layers);
    if ("drag" in o) this.drag = o.drag;
    if (o.maxFps) this.maxFps = o.maxFps;
    this.invalidate();
  }

  // RGBA of the canvas at CSS px (x, y)
  pixel(x, y) {
    const d = this.view.d;
    return Array.from(this.ctx.getImageData(Math.round(x * d), Math.round(y * d), 1, 1).data);
  }

  // A frame is drawn only when something changed, and no sooner than 1/maxFps after the last one: an idle page
  // asks the browser for no frames at all (a requestAnimationFrame loop costs the browser every vsync).
  invalidate() {
    this.dirty = true;
    if (this.scheduled) return;
    this.scheduled = true;
    const raf = typeof requestAnimationFrame === "function" ? requestAnimationFrame : (f) => setTimeout(() => f(performance.now()), 0);
    const wait = this.lastDraw + 1000 / this.maxFps - performance.now();
    if (wait > 1) setTimeout(() => raf(this.tick), wait);
    else raf(this.tick);
  }

  frame(now) {
    this.scheduled = false;
    if (!this.dirty) return;
    this.dirty = false; this.lastDraw = now;
    this.draw();
    this.frames++;
    this.onFrame(this.frames);
  }

  on(name) { return this.layers[name] !== false; }

  // the fixed-frame grids into the background canvas (when changed); returns the grids in moving frames
  background(tf, fixed) {
    const grids = this.store.grids, bg = this.bg, canvas = this.canvas;
    const order = Object.keys(grids).sort((a, b) => gridOrder(a) - gridOrder(b)).filter((t) => this.on(t));
    let n = 0;
    while (n < order.length && grids[order[n]].geo?.frame === fixed) n++;
    const still = order.slice(0, n), v = this.view;
    const key = JSON.stringify([canvas.width, canvas.height, v.cx, v.cy, v.scale, fixed, still, still.map((t) => grids[t].version)]);
    if (key !== this.bgKey) {
      this.bgKey = key; this.bgRenders++;
      if (bg.width !== canvas.width || bg.height !== canvas.height) { bg.width = canvas.width; bg.height = canvas.height; }
      const c = bg.getContext("2d", { alpha: false });
      c.setTransform(1, 0, 0, 1, 0, 0);
      c.fillStyle = "#303030"; c.fillRect(0, 0, bg.width, bg.height);
      for (const t of still) grids[t].draw(c, v, tf, ALPHA(t));
    }
    return order.slice(n);
  }

  draw() {
    const ctx = this.ctx, s = this.store.state, view = this.view, st = this.store, drag = this.drag;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    if (!s) { ctx.fillStyle = "#303030"; ctx.fillRect(0, 0, this.canvas.width, this.canvas.height); return; }
    const tf = s.tf;
    const moving = this.background(tf, s.fixed);
    ctx.drawImage(this.bg, 0, 0);
    for (const t of moving) (this.moving[t] ||= new R.MovingGrid()).draw(ctx, view, st.grids[t], tf, ALPHA(t));
    for (const [t, f] of Object.entries(st.traces)) if (this.on("trace " + t)) (this.traces[t] ||= new R.Trace()).draw(ctx, view, tf[f.frame], f, traceColor(t));
    for (const [t, f] of Object.entries(st.paths)) if (this.on(t)) R.drawPolyline(ctx, view, tf[f.frame], f.data, pathColor(t), 2.5);
    for (const [t, f] of Object.entries(st.clouds)) if (this.on(t)) R.drawCloud(ctx, view, tf[f.frame], f);
    for (const [t, f] of Object.entries(st.scans)) if (this.on(t)) R.drawScan(ctx, view, f.pose && f.fixed === s.fixed ? f.pose : tf[f.frame], f, "#f33");
    for (const [t, f] of Object.entries(st.poses)) {
      if (!this.on(t)) continue;
      if (t.endsWith("current_goal")) { if (f.n) R.drawArrow(ctx, view, R.compose(tf[f.frame] || [0, 0, 0], [...f.data]), "#f0f", 0.5); }
      else R.drawArrows(ctx, view, tf[f.frame], f.data, "#f55", 8);
    }
    for (const [t, f] of Object.entries(st.polygons)) if (this.on(t) && tf[f.frame]) R.drawPolyline(ctx, view, tf[f.frame], f.data, "#0f0", 2, true);
    if (this.on("robot")) R.drawRobot(ctx, view, tf[s.base], "#ff0", 0.2);
    if (this.on("tf")) {
      for (const [name, T] of Object.entries(tf)) R.drawAxes(ctx, view, T, name, false);
      R.drawFrameLabels(ctx, view, tf);
    }
    if (this.on("obstacles")) for (const o of s.obstacles || []) R.drawObstacle(ctx, view, o, drag && drag.obstacle === o.name ? "#fff" : "#fa0");
    if (drag && (drag.tool === "goal" || drag.tool === "pose")) {
      R.drawArrow(ctx, view, [drag.x, drag.y, drag.yaw], drag.tool === "goal" ? "#f0f" : "#0f0", 0.5);
    }
    if (drag && drag.obstacle) {
      const o = (s.obstacles || []).find((q) => q.name === drag.obstacle);
      if (o) R.drawObstacle(ctx, view, { ...o, x: drag.x, y: drag.y }, "#fff");
    }
    R.drawImages(ctx, view, Object.entries(st.images).filter(([t]) => this.on(t)));
    R.drawClock(ctx, view, s);
  }

  // how often the caches were drawn anew (for scripts and the docs' figures)
  renders() {
    return { background: this.bgRenders, moving: Object.fromEntries(Object.entries(this.moving).map(([t, m]) => [t, m.renders])),
      traces: Object.fromEntries(Object.entries(this.traces).map(([t, m]) => [t, m.renders])) };
  }
}
