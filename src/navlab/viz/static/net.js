// The WebSocket to navlab's viewer server: batches of frames ([u32 n][JSON header][pad to 4][payload]), and
// JSON text (replies to inputs).

const UTF8 = new TextDecoder();

// One frame at byte `off` (a multiple of 4) of `buf`, `len` bytes long: its header, and its payload as a view
// (no copy): `cells` (uint8) for grids and images (RGBA), `data` (float32) for the others. A JSON message is a frame of header only.
export function decodeFrame(buf, off = 0, len = buf.byteLength - off) {
  const dv = new DataView(buf, off, len);
  const n = dv.getUint32(0, true);
  const header = JSON.parse(UTF8.decode(new Uint8Array(buf, off + 4, n)));
  const start = off + 4 + n + ((4 - ((4 + n) % 4)) % 4), end = off + len;
  const k = header.k;
  const at = Math.min(start, buf.byteLength), size = Math.max(0, end - start);
  if (k === "grid" || k === "tiles" || k === "image") header.cells = new Uint8Array(buf, at, size);
  else if (k !== "state" && k !== "graph") header.data = new Float32Array(buf, at, size / 4);
  return header;
}

// The frames of one message (a batch): [u32 m][m bytes: a frame][padding to 4] repeated.
export function decodeBatch(buf, onFrame) {
  const dv = new DataView(buf);
  for (let off = 0; off + 4 <= buf.byteLength;) {
    const m = dv.getUint32(off, true);
    onFrame(decodeFrame(buf, off + 4, m));
    off += 4 + m + ((4 - (m % 4)) % 4);
  }
}

export class Link {
  // onBatch(buffer), if given, gets each binary message after its frames were handed to onMessage
  constructor(onMessage, onStatus, onBatch = null) {
    this.onMessage = onMessage;
    this.onBatch = onBatch;
    this.onStatus = onStatus;
    this.bytes = 0;
    this.ws = null;
    this.connect();
  }

  connect() {
    const url = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws";
    const ws = new WebSocket(url);
    ws.binaryType = "arraybuffer";
    this.ws = ws;
    ws.onopen = () => this.onStatus("connected");
    ws.onclose = () => { this.onStatus("disconnected"); setTimeout(() => this.connect(), 1000); };
    ws.onmessage = (ev) => {
      if (typeof ev.data === "string") {
        this.bytes += ev.data.length;
        this.onMessage(JSON.parse(ev.data));
      } else {
        this.bytes += ev.data.byteLength;
        decodeBatch(ev.data, this.onMessage);
        if (this.onBatch) this.onBatch(ev.data);
      }
    };
  }

  send(obj) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(obj));
  }
}
