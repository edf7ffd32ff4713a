// The WebSocket to navlab's viewer server: binary frames ([u32 n][JSON header][pad to 4][payload]) and JSON.

export function decodeFrame(buf) {
  const dv = new DataView(buf);
  const n = dv.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 4, n)));
  const start = 4 + n + ((4 - ((4 + n) % 4)) % 4);
  const k = header.k;
  if (k === "grid" || k === "tiles") header.cells = new Uint8Array(buf, start);
  else header.data = new Float32Array(buf, start, (buf.byteLength - start) / 4);
  return header;
}

export class Link {
  constructor(onMessage, onStatus) {
    this.onMessage = onMessage;
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
        this.onMessage(decodeFrame(ev.data));
      }
    };
  }

  send(obj) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(obj));
  }
}
