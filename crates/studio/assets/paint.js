// The collage's maps as the page holds them, and the tools that change them (docs/studio.md,
// "Protocol"): the brush, eraser and region pen stamp hard-edged discs (a pixel is painted when
// its centre is inside, so every pixel is one camera or the background), and move / cut / paste
// lift and put down whole labels. Each finished stroke or edit is one `paint` message, so one
// undo step; the page's maps change at once (optimistically) and the server's replies settle
// them.
import { $ } from './dom.js';
import { listen, send, seq } from './connection.js';
import { schedule } from './redraw.js';

let W = 0, H = 0;
let labels = new Uint8Array(0); // camera index per pixel, 0 background
let regions = new Uint8Array(0); // region number per pixel, 0 none
let selection = null; // { x, y, w, h } or null
let clipboard = null; // { w, h, data }
// The stroke waiting for its preview (`{ id, after, seq }`, or false), the count of strokes
// sent, and the ids of those whose replies have not come.
let paintPending = false;
let paints = 0;
const paintIds = new Set();
// The newest map of each layer, held while this tab's own strokes are on their way.
const waitingLabels = {};

export const width = () => W;
export const height = () => H;
export const labelMap = () => labels;
export const regionMap = () => regions;
export const currentSelection = () => selection;
// Whether a stroke waits for its preview, and how many were sent (the worker's frame says so).
export const pending = () => !!paintPending;
export const paintCount = () => paints;

// New, empty maps of a `w × h` collage.
export function resize(w, h) {
  W = w;
  H = h;
  labels = new Uint8Array(w * h);
  regions = new Uint8Array(w * h);
}

export function setSelection(r) {
  selection = r;
}

// Every tab's maps as the server holds them (strokes of other tabs too). While this tab's own
// strokes are on their way the newest map waits: it would hide them; the reply to the last one
// brings it in, with everything up to that stroke.
listen('labels', (m) => {
  if (paintIds.size) waitingLabels[m.layer] = m;
  else setLayer(m.layer, decodeBase64(m.data));
});
listen('lost', () => {
  paintIds.clear();
  paintPending = false;
  for (const layer of Object.keys(waitingLabels)) delete waitingLabels[layer];
});

function setLayer(layer, bytes) {
  if (bytes.length !== W * H) return;
  (layer === 'regions' ? regions : labels).set(bytes);
  schedule();
}
function paintDone(id) {
  if (!paintIds.delete(id) || paintIds.size) return;
  for (const [layer, m] of Object.entries(waitingLabels)) {
    setLayer(layer, decodeBase64(m.data));
    delete waitingLabels[layer];
  }
}

// The server's state replying to message `st.id`: a stroke's reply says its seq and settles it.
export function settle(st) {
  if (paintPending && paintPending.id === st.id && Number.isFinite(st.seq)) paintPending.seq = st.seq;
  if (paintIds.has(st.id)) paintDone(st.id);
}

// Message `id` was refused: if it was a stroke, the page's optimistic copy is wrong (true: ask
// for the server's maps again).
export function refused(id) {
  if (!paintIds.has(id)) return false;
  paintDone(id);
  return true;
}

// A preview of state `seq` arrived: the stroke that waited for it is shown.
export function previewArrived(previewSeq) {
  const p = paintPending;
  if (p && (p.seq !== null ? previewSeq >= p.seq : previewSeq > p.after)) paintPending = false;
}

// Sends one `paint` message (one undo step): `values` covers rect, 255 = leave as is.
function sendPatch(layer, rect, values) {
  const id = send({ type: 'paint', layer, rect: [rect.x, rect.y, rect.w, rect.h], data: encodeBase64(values) });
  // Until a preview of this stroke arrives: newer than the seq the page knew when it was sent,
  // or, once the server's state reply tells it, at least the stroke's own seq.
  paintPending = { id, after: seq(), seq: null };
  paints += 1;
  paintIds.add(id);
  const map = layer === 'regions' ? regions : labels;
  for (let y = 0; y < rect.h; y++) {
    for (let x = 0; x < rect.w; x++) {
      const v = values[y * rect.w + x];
      if (v !== 255) map[(rect.y + y) * W + rect.x + x] = v;
    }
  }
  schedule();
}

// ---- strokes ----------------------------------------------------------------------------------
let stroke = null;
export function beginStroke(layer, value) {
  stroke = { layer, value, mask: new Uint8Array(W * H), x0: W, y0: H, x1: -1, y1: -1, last: null };
}
// A hard-edged disc: pixel (x, y) is painted when its centre is within the brush radius.
function stamp(cx, cy) {
  const r = Math.max(0.5, Number($('size').value) / 2);
  const map = stroke.layer === 'regions' ? regions : labels;
  const xa = Math.max(0, Math.floor(cx - r)), xb = Math.min(W - 1, Math.ceil(cx + r));
  const ya = Math.max(0, Math.floor(cy - r)), yb = Math.min(H - 1, Math.ceil(cy + r));
  for (let y = ya; y <= yb; y++) {
    for (let x = xa; x <= xb; x++) {
      const inside = (x + 0.5 - cx) ** 2 + (y + 0.5 - cy) ** 2 <= r * r
        || (x === Math.floor(cx) && y === Math.floor(cy));
      if (!inside) continue;
      const i = y * W + x;
      stroke.mask[i] = 1;
      map[i] = stroke.value;
      if (x < stroke.x0) stroke.x0 = x;
      if (x > stroke.x1) stroke.x1 = x;
      if (y < stroke.y0) stroke.y0 = y;
      if (y > stroke.y1) stroke.y1 = y;
    }
  }
}
export function strokeTo(p) {
  const last = stroke.last || p;
  const steps = Math.max(1, Math.ceil(Math.hypot(p.x - last.x, p.y - last.y) * 2));
  for (let s = 1; s <= steps; s++) stamp(last.x + ((p.x - last.x) * s) / steps, last.y + ((p.y - last.y) * s) / steps);
  stroke.last = p;
  schedule();
}
export function endStroke() {
  const st = stroke;
  stroke = null;
  if (st.x1 < 0) return;
  const rect = { x: st.x0, y: st.y0, w: st.x1 - st.x0 + 1, h: st.y1 - st.y0 + 1 };
  const values = new Uint8Array(rect.w * rect.h).fill(255);
  for (let y = 0; y < rect.h; y++) {
    for (let x = 0; x < rect.w; x++) {
      if (st.mask[(rect.y + y) * W + rect.x + x]) values[y * rect.w + x] = st.value;
    }
  }
  sendPatch(st.layer, rect, values);
}

// ---- selection: move, cut, copy, paste --------------------------------------------------------
export function clipRect(r) {
  const x0 = Math.max(0, r.x), y0 = Math.max(0, r.y);
  const x1 = Math.min(W, r.x + r.w), y1 = Math.min(H, r.y + r.h);
  return x1 > x0 && y1 > y0 ? { x: x0, y: y0, w: x1 - x0, h: y1 - y0 } : null;
}
export function copySelection() {
  const r = selection;
  if (!r) return null;
  const data = new Uint8Array(r.w * r.h);
  for (let y = 0; y < r.h; y++) for (let x = 0; x < r.w; x++) data[y * r.w + x] = labels[(r.y + y) * W + r.x + x];
  clipboard = { w: r.w, h: r.h, data };
  return clipboard;
}
// One patch over `area`: `lift` pixels (painted ones of the old place) cleared, then the clip
// put down at (px, py), its unpainted pixels leaving what is under them.
function placePatch(area, lift, clip, px, py) {
  const r = clipRect(area);
  if (!r) return;
  const values = new Uint8Array(r.w * r.h).fill(255);
  if (lift) {
    for (let y = lift.y; y < lift.y + lift.h; y++) {
      for (let x = lift.x; x < lift.x + lift.w; x++) {
        if (labels[y * W + x] && x >= r.x && y >= r.y && x < r.x + r.w && y < r.y + r.h) values[(y - r.y) * r.w + x - r.x] = 0;
      }
    }
  }
  if (clip) {
    for (let y = 0; y < clip.h; y++) {
      for (let x = 0; x < clip.w; x++) {
        const v = clip.data[y * clip.w + x];
        const gx = px + x, gy = py + y;
        if (v && gx >= r.x && gy >= r.y && gx < r.x + r.w && gy < r.y + r.h) values[(gy - r.y) * r.w + gx - r.x] = v;
      }
    }
  }
  sendPatch('labels', r, values);
}
function union(a, b) {
  const x = Math.min(a.x, b.x), y = Math.min(a.y, b.y);
  return { x, y, w: Math.max(a.x + a.w, b.x + b.w) - x, h: Math.max(a.y + a.h, b.y + b.h) - y };
}
// Clears the selection's painted pixels (the Delete key).
export function clearSelection() {
  if (selection) placePatch(selection, selection, null, 0, 0);
}
export function cut() { if (copySelection()) placePatch(selection, selection, null, 0, 0); }
export function paste() {
  const c = clipboard;
  if (!c) return;
  const at = selection || { x: 0, y: 0 };
  placePatch({ x: at.x, y: at.y, w: c.w, h: c.h }, null, c, at.x, at.y);
  selection = clipRect({ x: at.x, y: at.y, w: c.w, h: c.h });
  schedule();
}
export function moveSelection(dx, dy) {
  const from = selection;
  const clip = copySelection();
  const to = { x: from.x + dx, y: from.y + dy, w: from.w, h: from.h };
  placePatch(union(from, to), from, clip, to.x, to.y);
  selection = clipRect(to);
  schedule();
}

// Label maps travel as base64: the browser's own codec where it has one (Chromium 140 on), as a
// loop per byte over a whole map is the page's longest handler at 480×270 (docs/performance.md §1.6).
function encodeBase64(bytes) {
  if (typeof bytes.toBase64 === 'function') return bytes.toBase64();
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(s);
}
function decodeBase64(text) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text);
  const s = atob(text);
  const out = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
  return out;
}
