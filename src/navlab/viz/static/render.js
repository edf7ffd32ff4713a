// Drawing: rviz's map and costmap palettes, grids as offscreen canvases, scans, paths, poses, robot, tf.
// Everything is drawn in the fixed frame: a layer in frame F is placed with F's pose from tf (state.tf[F]).

// a canvas that is not shown: an OffscreenCanvas where there is one (the only kind a worker has)
export function makeCanvas(w, h) {
  if (typeof OffscreenCanvas === "function") return new OffscreenCanvas(w, h);
  const c = document.createElement("canvas");
  c.width = w; c.height = h;
  return c;
}

function rgba(r, g, b, a) { return (a << 24) | (b << 16) | (g << 8) | r; } // little-endian ImageData word

// rviz's "map" palette: 0..100 from white to black, -1 (255) a grey-green, anything else flagged
export function mapPalette() {
  const p = new Uint32Array(256);
  for (let i = 0; i <= 100; i++) { const v = 255 - Math.floor((255 * i) / 100); p[i] = rgba(v, v, v, 255); }
  for (let i = 101; i <= 127; i++) p[i] = rgba(0, 255, 0, 255);
  for (let i = 128; i <= 254; i++) p[i] = rgba(255, Math.floor((255 * (i - 128)) / (254 - 128)), 0, 255);
  p[255] = rgba(0x70, 0x89, 0x86, 255);
  return p;
}

// rviz's "costmap" palette: 0 clear, 1..98 blue to red (inflation), 99 cyan (inscribed), 100 purple (lethal)
export function costmapPalette() {
  const p = new Uint32Array(256);
  p[0] = rgba(0, 0, 0, 0);
  for (let i = 1; i <= 98; i++) { const v = Math.floor((255 * i) / 100); p[i] = rgba(v, 0, 255 - v, 255); }
  p[99] = rgba(0, 255, 255, 255);
  p[100] = rgba(255, 0, 255, 255);
  for (let i = 101; i <= 127; i++) p[i] = rgba(0, 255, 0, 255);
  for (let i = 128; i <= 254; i++) p[i] = rgba(255, Math.floor((255 * (i - 128)) / (254 - 128)), 0, 255);
  p[255] = rgba(0x70, 0x89, 0x86, 255);
  return p;
}

export class GridLayer {
  constructor(palette) { this.palette = palette; this.canvas = null; this.geo = null; this.version = 0; }

  apply(f) {
    this.version++;
    const same = this.geo && this.geo.w === f.w && this.geo.h === f.h;
    if (f.k === "grid" || !same) {
      if (f.k === "tiles" && !same) return; // tiles for a grid we never saw whole: wait for a whole one
      this.canvas = makeCanvas(f.w, f.h);
      this.geo = f;
      this.paint(0, 0, f.w, f.h, f.cells);
      return;
    }
    this.geo = f;
    let off = 0;
    for (const [x0, y0, tw, th] of f.tiles) {
      this.paint(x0, y0, tw, th, f.cells.subarray(off, off + tw * th));
      off += tw * th;
    }
  }

  // cells row 0 is at the grid origin (bottom): canvas rows are flipped
  paint(x0, y0, w, h, cells) {
    const img = new ImageData(w, h);
    const out = new Uint32Array(img.data.buffer);
    const pal = this.palette;
    for (let r = 0; r < h; r++) {
      const src = r * w, dst = (h - 1 - r) * w;
      for (let c = 0; c < w; c++) out[dst + c] = pal[cells[src + c]];
    }
    this.canvas.getContext("2d").putImageData(img, x0, this.geo.h - y0 - h);
  }

  draw(ctx, view, tf, alpha) {
    const g = this.geo;
    if (!g || !this.canvas) return;
    const T = tf[g.frame];
    if (!T) return;
    ctx.save();
    view.apply(ctx);
    place(ctx, T);
    place(ctx, [g.ox, g.oy, g.oyaw]);
    ctx.transform(g.res, 0, 0, -g.res, 0, g.h * g.res);
    ctx.globalAlpha = alpha;
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(this.canvas, 0, 0);
    ctx.restore();
  }
}

// A grid in a moving frame (the local costmap in odom, placed by tf) is rendered at the screen's scale and
// rotation into its own canvas only when its cells, the view or its placement changed, and each frame copies
// it at a whole-pixel offset (a plain copy is ~10 times cheaper than a rotated, scaled image). The placement
// counts as unchanged while the cached copy stays within SUBPIXEL device px of where the grid belongs.
const SUBPIXEL = 0.5;
export class MovingGrid {
  constructor() { this.canvas = makeCanvas(1, 1); this.key = null; this.renders = 0; }

  draw(ctx, view, layer, tf, alpha) {
    const g = layer.geo;
    const T = g && layer.canvas && tf[g.frame];
    if (!T) return;
    const P = compose(T, [g.ox, g.oy, g.oyaw]);
    const d = view.d, k = view.scale * d;
    const [sx0, sy0] = view.toScreen(P[0], P[1]);
    const sx = sx0 * d, sy = sy0 * d, ext = Math.hypot(g.w, g.h) * g.res * k;
    const c = this.key;
    let dx = 0, dy = 0, stale = !c || c.layer !== layer || c.version !== layer.version || c.k !== k;
    if (!stale) {
      dx = Math.round(sx - c.sx); dy = Math.round(sy - c.sy);
      stale = Math.abs(sx - c.sx - dx) > SUBPIXEL || Math.abs(sy - c.sy - dy) > SUBPIXEL
        || Math.abs(P[2] - c.yaw) * ext > SUBPIXEL || (c.clipped && (dx !== 0 || dy !== 0)); // a cut copy cannot move
    }
    if (stale) {
      this.render(layer, P, sx, sy, k, ctx.canvas.width, ctx.canvas.height);
      dx = dy = 0;
    }
    ctx.save();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.globalAlpha = alpha;
    ctx.drawImage(this.canvas, this.key.x0 + dx, this.key.y0 + dy);
    ctx.restore();
  }

  // the grid's bounding box on screen, cut to the view (a zoomed-in map would need a huge canvas)
  render(layer, P, sx, sy, k, viewW, viewH) {
    const g = layer.geo, W = g.w * g.res, H = g.h * g.res;
    const a = k * Math.cos(P[2]), b = -k * Math.sin(P[2]); // metres in the grid's frame -> device px (y down)
    const xs = [0, a * W, b * H, a * W + b * H], ys = [0, b * W, -a * H, b * W - a * H];
    const bx0 = Math.floor(sx + Math.min(...xs)) - 1, by0 = Math.floor(sy + Math.min(...ys)) - 1;
    const bx1 = Math.ceil(sx + Math.max(...xs)) + 1, by1 = Math.ceil(sy + Math.max(...ys)) + 1;
    const x0 = Math.max(bx0, 0), y0 = Math.max(by0, 0);
    const w = Math.max(1, Math.min(bx1, viewW) - x0), h = Math.max(1, Math.min(by1, viewH) - y0);
    const clipped = x0 !== bx0 || y0 !== by0 || bx1 > viewW || by1 > viewH;
    const cv = this.canvas;
    if (cv.width !== w || cv.height !== h) { cv.width = w; cv.height = h; }
    const c = cv.getContext("2d");
    c.setTransform(1, 0, 0, 1, 0, 0);
    c.clearRect(0, 0, w, h);
    c.setTransform(a, b, b, -a, sx - x0, sy - y0);
    c.transform(g.res, 0, 0, -g.res, 0, g.h * g.res);
    c.imageSmoothingEnabled = false;
    c.drawImage(layer.canvas, 0, 0);
    this.key = { layer, version: layer.version, k, sx, sy, yaw: P[2], x0, y0, clipped };
    this.renders++;
  }
}

// A trace (odometry, ground truth) only grows: it is stroked into a transparent canvas of the view's size, its
// new segments only, and each frame copies the part of that canvas it covers (a copy is several times cheaper
// than stroking hundreds of segments). It is stroked anew when the view changed, the trace was replaced (a
// replay's seek, the oldest points dropped) or its frame's pose in the fixed frame (localization corrects
// odom's) moved it by more than SUBPIXEL device px.
export class Trace {
  constructor() { this.canvas = makeCanvas(1, 1); this.key = ""; this.was = null; this.box = null; this.renders = 0; }

  draw(ctx, view, T, f, color) {
    if (!T || f.n < 2) return;
    const k = view.scale * view.d, cv = this.canvas, data = f.data, key = [ctx.canvas.width, ctx.canvas.height, view.cx, view.cy, view.scale].join();
    const was = this.was, n = was ? was.n : 0;
    const fresh = key !== this.key || !was || f.n < n || data[0] !== was.first[0] || data[1] !== was.first[1]
      || data[2 * n - 2] !== was.last[0] || data[2 * n - 1] !== was.last[1]
      || Math.hypot(T[0] - was.T[0], T[1] - was.T[1]) * k + Math.abs(T[2] - was.T[2]) * was.reach * k > SUBPIXEL;
    const c = cv.getContext("2d");
    if (fresh) {
      if (cv.width !== ctx.canvas.width || cv.height !== ctx.canvas.height) { cv.width = ctx.canvas.width; cv.height = ctx.canvas.height; }
      c.setTransform(1, 0, 0, 1, 0, 0);
      c.clearRect(0, 0, cv.width, cv.height);
      this.key = key; this.was = null; this.box = null; this.renders++;
    }
    const from = this.was ? n - 1 : 0;
    if (from < f.n - 1) {
      const P = this.was ? this.was.T : T, pts = data.subarray(2 * from, 2 * f.n);
      drawPolyline(c, view, P, pts, color, 1.5);
      let reach2 = this.was ? this.was.reach ** 2 : 0, x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
      for (let i = 0; i < pts.length; i += 2) {
        const x = pts[i], y = pts[i + 1];
        if (x < x0) x0 = x; if (x > x1) x1 = x; if (y < y0) y0 = y; if (y > y1) y1 = y;
        if (x * x + y * y > reach2) reach2 = x * x + y * y;
      }
      const cs = Math.cos(P[2]), sn = Math.sin(P[2]);
      for (const [u, v] of [[x0, y0], [x1, y0], [x0, y1], [x1, y1]]) { // the new points' box, on screen
        const [x, y] = view.toScreen(P[0] + cs * u - sn * v, P[1] + sn * u + cs * v);
        this.grow(x * view.d, y * view.d);
      }
      this.was = { n: f.n, T: P, reach: Math.sqrt(reach2), first: [data[0], data[1]], last: [data[2 * f.n - 2], data[2 * f.n - 1]] };
    }
    const b = this.box;
    if (!b) return;
    const x0 = Math.max(0, Math.floor(b[0]) - 3), y0 = Math.max(0, Math.floor(b[1]) - 3);
    const x1 = Math.min(cv.width, Math.ceil(b[2]) + 3), y1 = Math.min(cv.height, Math.ceil(b[3]) + 3);
    if (x1 > x0 && y1 > y0) ctx.drawImage(cv, x0, y0, x1 - x0, y1 - y0, x0, y0, x1 - x0, y1 - y0);
  }

  grow(x, y) {
    const b = this.box;
    if (!b) this.box = [x, y, x, y];
    else { if (x < b[0]) b[0] = x; if (y < b[1]) b[1] = y; if (x > b[2]) b[2] = x; if (y > b[3]) b[3] = y; }
  }
}

export function place(ctx, [x, y, yaw]) {
  const c = Math.cos(yaw), s = Math.sin(yaw);
  ctx.transform(c, s, -s, c, x, y);
}

// one world-space stroke: the context is in metres, so line widths are given in pixels / scale
function strokeIn(ctx, view, T, color, px, fn) {
  ctx.save();
  view.apply(ctx);
  place(ctx, T);
  ctx.strokeStyle = color; ctx.fillStyle = color;
  ctx.lineWidth = px / view.scale;
  ctx.beginPath();
  fn();
  ctx.restore();
}

export function drawPolyline(ctx, view, T, data, color, px, closed = false) {
  if (!T || data.length < 4) return;
  strokeIn(ctx, view, T, color, px, () => {
    ctx.moveTo(data[0], data[1]);
    for (let i = 2; i < data.length; i += 2) ctx.lineTo(data[i], data[i + 1]);
    if (closed) ctx.closePath();
    ctx.stroke();
  });
}

// Each return is a 3 or 4 px square placed in screen space on whole device pixels: one path of axis-aligned,
// pixel-aligned rectangles rasterizes several times faster than the same squares in the scan's frame.
export function drawScan(ctx, view, T, f, color) {
  if (!T) return;
  const d = view.d, k = view.scale * d;
  const size = Math.round((view.scale < 40 ? 3 : 4) * d), h = size / 2;
  const c = Math.cos(T[2]), s = Math.sin(T[2]);
  const ox = ctx.canvas.width / 2 + (T[0] - view.cx) * k - h, oy = ctx.canvas.height / 2 - (T[1] - view.cy) * k - h;
  const data = f.data;
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = color;
  ctx.beginPath();
  for (let i = 0; i < data.length; i++) {
    const r = data[i];
    if (!(r >= f.rmin && r < f.rmax)) continue;
    const a = f.a0 + i * f.da, lx = r * Math.cos(a), ly = r * Math.sin(a);
    ctx.rect(Math.round(ox + (c * lx - s * ly) * k), Math.round(oy - (s * lx + c * ly) * k), size, size);
  }
  ctx.fill();
  ctx.restore();
}

export function drawArrows(ctx, view, T, data, color, lengthPx) {
  if (!T) return;
  strokeIn(ctx, view, T, color, 1, () => {
    const L = lengthPx / view.scale;
    for (let i = 0; i + 2 < data.length; i += 3) {
      const x = data[i], y = data[i + 1], a = data[i + 2];
      ctx.moveTo(x, y); ctx.lineTo(x + L * Math.cos(a), y + L * Math.sin(a));
    }
    ctx.stroke();
  });
}

export function drawArrow(ctx, view, pose, color, lengthM) {
  const [x, y, a] = pose;
  strokeIn(ctx, view, [x, y, a], color, 3, () => {
    const h = lengthM * 0.3;
    ctx.moveTo(0, 0); ctx.lineTo(lengthM, 0);
    ctx.moveTo(lengthM - h, h * 0.6); ctx.lineTo(lengthM, 0); ctx.lineTo(lengthM - h, -h * 0.6);
    ctx.stroke();
  });
}

export function drawRobot(ctx, view, T, color, radius) {
  if (!T) return;
  strokeIn(ctx, view, T, color, 2, () => {
    ctx.arc(0, 0, radius, 0, 2 * Math.PI);
    ctx.moveTo(0, 0); ctx.lineTo(radius * 1.4, 0);
    ctx.stroke();
  });
}

export function drawAxes(ctx, view, T, name, labels) {
  const L = 0.15;
  strokeIn(ctx, view, T, "#f33", 2, () => { ctx.moveTo(0, 0); ctx.lineTo(L, 0); ctx.stroke(); });
  strokeIn(ctx, view, T, "#3f3", 2, () => { ctx.moveTo(0, 0); ctx.lineTo(0, L); ctx.stroke(); });
  if (labels) {
    const [sx, sy] = view.toScreen(T[0], T[1]);
    ctx.fillStyle = "#ccc"; ctx.font = "10px sans-serif"; ctx.fillText(name, sx + 4, sy - 4);
  }
}

// tf frame names: frames within a few pixels of each other (chassis, imu, laser on one robot) share one label
// ("chassis, imu, laser") instead of printing over each other; labels of nearby groups are stacked downwards
export function drawFrameLabels(ctx, view, tf) {
  const groups = [];
  for (const [name, T] of Object.entries(tf)) {
    if (!T) continue;
    const [sx, sy] = view.toScreen(T[0], T[1]);
    const g = groups.find((q) => Math.hypot(q.sx - sx, q.sy - sy) < 8);
    if (g) g.names.push(name); else groups.push({ sx, sy, names: [name] });
  }
  ctx.fillStyle = "#ccc"; ctx.font = "10px sans-serif";
  const used = [];
  for (const g of groups.sort((a, b) => a.sy - b.sy || a.sx - b.sx)) {
    const text = g.names.sort().join(", ");
    const w = ctx.measureText(text).width;
    let y = g.sy - 4;
    while (used.some((u) => Math.abs(u.y - y) < 11 && g.sx + 4 < u.x + u.w && u.x < g.sx + 4 + w)) y += 11;
    used.push({ x: g.sx + 4, y, w });
    ctx.fillText(text, g.sx + 4, y);
  }
}

// simulated time, the real-time factor and the pace, in the canvas's bottom-left corner
export function drawClock(ctx, view, s) {
  const text = `t = ${s.t.toFixed(1)} s   ` + (s.replay ? `replay ${s.speed}x` : `RTF ${s.rtf.toFixed(2)} (${s.speed > 0 ? s.speed + "x" : "max"})`);
  const d = view.d;
  ctx.save();
  ctx.setTransform(d, 0, 0, d, 0, 0);
  ctx.font = "13px system-ui, sans-serif";
  const w = ctx.measureText(text).width;
  ctx.fillStyle = "rgba(37, 37, 37, 0.85)";
  ctx.fillRect(0, view.H - 22, w + 16, 22);
  ctx.fillStyle = "#ddd";
  ctx.fillText(text, 8, view.H - 7);
  ctx.restore();
}

export function drawObstacle(ctx, view, o, color) {
  strokeIn(ctx, view, [o.x, o.y, o.yaw || 0], color, 2, () => {
    if (o.kind === "cylinder") ctx.arc(0, 0, o.dims[0], 0, 2 * Math.PI);
    else ctx.rect(-o.dims[0] / 2, -o.dims[1] / 2, o.dims[0], o.dims[1]);
    ctx.stroke();
  });
}

export function compose(a, b) {
  const c = Math.cos(a[2]), s = Math.sin(a[2]);
  return [a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]];
}

// A point cloud seen from above (points in frame T = [x, y, yaw]), coloured by height: blue low, red high.
export function drawCloud(ctx, view, T, f) {
  if (!T) return;
  const d = view.d, k = view.scale * d, size = Math.max(2, Math.round(2 * d));
  const c = Math.cos(T[2]), s = Math.sin(T[2]), data = f.data;
  const ox = ctx.canvas.width / 2 + (T[0] - view.cx) * k, oy = ctx.canvas.height / 2 - (T[1] - view.cy) * k;
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  const bins = [[], [], [], []]; // z < 0.05, < 0.3, < 1, above (m): one fill per colour
  for (let i = 0; i + 2 < data.length; i += 3) {
    const z = data[i + 2];
    bins[z < 0.05 ? 0 : z < 0.3 ? 1 : z < 1.0 ? 2 : 3].push(i);
  }
  const colours = ["#36c", "#2c8", "#fc3", "#f43"];
  for (let b = 0; b < 4; b++) {
    ctx.fillStyle = colours[b];
    ctx.beginPath();
    for (const i of bins[b]) {
      const x = data[i], y = data[i + 1];
      ctx.rect(Math.round(ox + (c * x - s * y) * k), Math.round(oy - (s * x + c * y) * k), size, size);
    }
    ctx.fill();
  }
  ctx.restore();
}

// An image frame (RGBA cells, w x h) as a small canvas to draw
export function imageCanvas(m) {
  const canvas = makeCanvas(m.w, m.h);
  const img = new ImageData(new Uint8ClampedArray(m.cells), m.w, m.h); // a copy: the frame's buffer is reused
  canvas.getContext("2d").putImageData(img, 0, 0);
  canvas.topic = m.topic;
  return canvas;
}

// The camera images in the top-right corner, one under the other, with their topics
export function drawImages(ctx, view, images) {
  const d = view.d;
  let y = 8 * d;
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.font = `${11 * d}px sans-serif`;
  for (const [topic, canvas] of images) {
    const w = canvas.width * d, h = canvas.height * d, x = ctx.canvas.width - w - 8 * d;
    ctx.drawImage(canvas, x, y, w, h);
    ctx.strokeStyle = "#fff"; ctx.strokeRect(x, y, w, h);
    ctx.fillStyle = "#fff"; ctx.fillText(topic, x, y + h + 12 * d);
    y += h + 20 * d;
  }
  ctx.restore();
}
