// The canvas's own thread: the page hands over its canvas (an OffscreenCanvas) and copies of the server's
// batches, the view, the displays and the tool's drag; the scene draws here, so a frame costs the page's
// thread nothing (no frame of the page's own: the canvas's frames go straight to the browser's compositor).
import { decodeBatch } from "./net.js";
import { Scene } from "./scene.js";

let scene = null, reported = 0, timer = 0;

// frames drawn, told to the page at most 5 times a second (a message per frame would wake the page's thread)
function onFrame(n) {
  if (timer) return;
  timer = setTimeout(() => { timer = 0; if (scene.frames !== reported) { reported = scene.frames; postMessage({ frames: reported }); } }, 200);
}

onmessage = (ev) => {
  const m = ev.data;
  if (m.canvas) { scene = new Scene(m.canvas, onFrame); scene.set(m.set); return; }
  if (!scene) return;
  if (m.batch) decodeBatch(m.batch, (f) => scene.receive(f));
  else if (m.set) scene.set(m.set);
  else if (m.pixel) postMessage({ pixel: m.pixel.id, rgba: scene.pixel(m.pixel.x, m.pixel.y) });
  else if (m.renders) postMessage({ renders: m.renders.id, value: scene.renders() });
};
