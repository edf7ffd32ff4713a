// Drawing: rviz's map and costmap palettes, grids as offscreen canvases, scans, paths, poses, robot, tf.
// Everything is drawn in the fixed frame: a layer in frame F is placed with F's pose from tf (state.tf[F]).

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
      this.canvas = document.createElement("canvas");
      this.canvas.width = f.w; this.canvas.height = f.h;
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
  const d = devicePixelRatio, k = view.scale * d;
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
