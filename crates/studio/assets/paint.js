// The studio page's tools as `paint` patches (docs/studio.md, "Protocol"): the brush, eraser and
// region pen stamp hard-edged discs (a pixel is painted when its centre is inside, so every pixel
// is one camera or the background), and move / cut / paste lift and put down whole labels.
// Each finished stroke or edit is one message, so one undo step. Loaded before studio.js, which
// calls `studioPaint` with the page's state, its `send` and its redraw.
'use strict';
window.studioPaint = (S, send, schedule) => {
  // Sends one `paint` message (one undo step): `values` covers rect, 255 = leave as is.
  function sendPatch(layer, rect, values) {
    const id = send({ type: 'paint', layer, rect: [rect.x, rect.y, rect.w, rect.h], data: encodeBase64(values) });
    // Until a preview of this stroke arrives: newer than the seq the page knew when it was sent,
    // or, once the server's state reply tells it, at least the stroke's own seq.
    S.paintPending = { id, after: S.seq, seq: null };
    S.paints += 1;
    S.paintIds.add(id);
    const map = layer === 'regions' ? S.regions : S.labels;
    for (let y = 0; y < rect.h; y++) {
      for (let x = 0; x < rect.w; x++) {
        const v = values[y * rect.w + x];
        if (v !== 255) map[(rect.y + y) * S.W + rect.x + x] = v;
      }
    }
    schedule();
  }

  let stroke = null;
  function beginStroke(layer, value) {
    stroke = { layer, value, mask: new Uint8Array(S.W * S.H), x0: S.W, y0: S.H, x1: -1, y1: -1, last: null };
  }
  // A hard-edged disc: pixel (x, y) is painted when its centre is within the brush radius.
  function stamp(cx, cy) {
    const r = Math.max(0.5, Number(document.getElementById('size').value) / 2);
    const map = stroke.layer === 'regions' ? S.regions : S.labels;
    const xa = Math.max(0, Math.floor(cx - r)), xb = Math.min(S.W - 1, Math.ceil(cx + r));
    const ya = Math.max(0, Math.floor(cy - r)), yb = Math.min(S.H - 1, Math.ceil(cy + r));
    for (let y = ya; y <= yb; y++) {
      for (let x = xa; x <= xb; x++) {
        const inside = (x + 0.5 - cx) ** 2 + (y + 0.5 - cy) ** 2 <= r * r
          || (x === Math.floor(cx) && y === Math.floor(cy));
        if (!inside) continue;
        const i = y * S.W + x;
        stroke.mask[i] = 1;
        map[i] = stroke.value;
        if (x < stroke.x0) stroke.x0 = x;
        if (x > stroke.x1) stroke.x1 = x;
        if (y < stroke.y0) stroke.y0 = y;
        if (y > stroke.y1) stroke.y1 = y;
      }
    }
  }
  function strokeTo(p) {
    const last = stroke.last || p;
    const steps = Math.max(1, Math.ceil(Math.hypot(p.x - last.x, p.y - last.y) * 2));
    for (let s = 1; s <= steps; s++) stamp(last.x + ((p.x - last.x) * s) / steps, last.y + ((p.y - last.y) * s) / steps);
    stroke.last = p;
    schedule();
  }
  function endStroke() {
    const st = stroke;
    stroke = null;
    if (st.x1 < 0) return;
    const rect = { x: st.x0, y: st.y0, w: st.x1 - st.x0 + 1, h: st.y1 - st.y0 + 1 };
    const values = new Uint8Array(rect.w * rect.h).fill(255);
    for (let y = 0; y < rect.h; y++) {
      for (let x = 0; x < rect.w; x++) {
        if (st.mask[(rect.y + y) * S.W + rect.x + x]) values[y * rect.w + x] = st.value;
      }
    }
    sendPatch(st.layer, rect, values);
  }

  // ---- selection: move, cut, copy, paste --------------------------------------------------------
  function clipRect(r) {
    const x0 = Math.max(0, r.x), y0 = Math.max(0, r.y);
    const x1 = Math.min(S.W, r.x + r.w), y1 = Math.min(S.H, r.y + r.h);
    return x1 > x0 && y1 > y0 ? { x: x0, y: y0, w: x1 - x0, h: y1 - y0 } : null;
  }
  function copySelection() {
    const r = S.selection;
    if (!r) return null;
    const data = new Uint8Array(r.w * r.h);
    for (let y = 0; y < r.h; y++) for (let x = 0; x < r.w; x++) data[y * r.w + x] = S.labels[(r.y + y) * S.W + r.x + x];
    S.clipboard = { w: r.w, h: r.h, data };
    return S.clipboard;
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
          if (S.labels[y * S.W + x] && x >= r.x && y >= r.y && x < r.x + r.w && y < r.y + r.h) values[(y - r.y) * r.w + x - r.x] = 0;
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
  function cut() { if (copySelection()) placePatch(S.selection, S.selection, null, 0, 0); }
  function paste() {
    const c = S.clipboard;
    if (!c) return;
    const at = S.selection || { x: 0, y: 0 };
    placePatch({ x: at.x, y: at.y, w: c.w, h: c.h }, null, c, at.x, at.y);
    S.selection = clipRect({ x: at.x, y: at.y, w: c.w, h: c.h });
    schedule();
  }
  function moveSelection(dx, dy) {
    const from = S.selection;
    const clip = copySelection();
    const to = { x: from.x + dx, y: from.y + dy, w: from.w, h: from.h };
    placePatch(union(from, to), from, clip, to.x, to.y);
    S.selection = clipRect(to);
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


  return { sendPatch, beginStroke, strokeTo, endStroke, copySelection, cut, paste, moveSelection, placePatch, clipRect, decodeBase64 };
};
