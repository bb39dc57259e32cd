// The studio page's picture worker (docs/studio.md, "The page"): decodes the server's PNGs, keeps
// every picture's pixels and draws each frame of the canvas on an OffscreenCanvas, so no decode,
// pixel read-back or per-pixel loop runs on the page's main thread. The page posts it pictures,
// the label maps and what to draw; it answers with an ImageBitmap per frame, which the page only
// copies onto its canvas.
'use strict';
let W = 0, H = 0;
let seqNow = 0; // the newest state `seq` the page knows
const newest = new Map(); // newest seq per picture kind and camera
let preview = null; // { bmp, seq, spp, px }: the newest preview, its pixels read on demand
let sources = []; // per camera index: { px: RGBA at the collage size, seq, full }
let view = null; // { bmp, mode }: the `view` picture and the mode it was asked in
let frame = null, fctx = null, scratch = null, sctx = null, out = null;

function resize(w, h) {
  W = w;
  H = h;
  preview = null;
  sources = [];
  view = null;
  frame = new OffscreenCanvas(w, h);
  fctx = frame.getContext('2d');
  scratch = new OffscreenCanvas(w, h);
  sctx = scratch.getContext('2d', { willReadFrequently: true });
  out = new ImageData(w, h);
}

// A bitmap's pixels at the collage size (scaled if it is a coarse or thumbnail picture).
function pixelsAtCollageSize(bmp) {
  sctx.imageSmoothingEnabled = true;
  sctx.drawImage(bmp, 0, 0, W, H);
  return sctx.getImageData(0, 0, W, H).data;
}

const key = (h) => `${h.kind}:${h.camera ?? ''}`;
// A preview is stale after any newer stroke or camera change; a camera's thumb or view only after
// a newer one of that camera.
function stale(h) {
  if (h.kind === 'preview') return h.seq < seqNow;
  return h.seq < (newest.get(key(h)) ?? -1);
}

async function picture(h, buf, mode) {
  seqNow = Math.max(seqNow, h.seq ?? 0);
  if (stale(h)) return;
  newest.set(key(h), h.seq);
  let bmp;
  try {
    bmp = await createImageBitmap(new Blob([buf], { type: 'image/png' }));
  } catch (_) {
    postMessage({ type: 'error', message: `could not decode a ${h.kind} picture` });
    return;
  }
  if (stale(h) || !W) { bmp.close(); return; }
  const full = bmp.width === W && bmp.height === H;
  const reply = { type: 'picture', h, w: bmp.width, hgt: bmp.height, full, mode };
  if (h.kind === 'preview') {
    if (preview) preview.bmp.close();
    preview = { bmp, seq: h.seq, spp: h.spp, px: null };
    postMessage(reply);
  } else if (h.kind === 'thumb') {
    const src = sources[h.camera];
    if (!src || !src.full || src.seq < h.seq) sources[h.camera] = { px: pixelsAtCollageSize(bmp), seq: h.seq, full };
    // The bitmap itself goes to the page for the camera list's thumbnail.
    postMessage({ ...reply, bmp }, [bmp]);
  } else if (h.kind === 'view') {
    if (view) view.bmp.close();
    view = { bmp, mode };
    if (h.camera && mode === 'source') sources[h.camera] = { px: pixelsAtCollageSize(bmp), seq: h.seq, full };
    postMessage(reply);
  } else {
    bmp.close();
  }
}

function hexColor(hex) { const v = parseInt(hex.slice(1), 16); return [v >> 16, (v >> 8) & 255, v & 255]; }
function regionColor(r) { return r ? [(r * 97) % 256, (r * 57 + 80) % 256, (r * 151 + 40) % 256] : [0, 0, 0]; }

// One frame of the canvas, as the page's state `d` says: the mode, the maps, whether a stroke waits
// for its preview. The frame says what it shows, for the browser test.
function compose(d) {
  const n = W * H;
  const o = out.data;
  const shown = { mode: d.mode, seq: -1, spp: 0, pending: !!d.pending, paints: d.paints };
  if (d.mode === 'final' && d.labels.every((l) => l === 0)) {
    // Nothing painted yet (the server makes no preview of an empty collage): the selected
    // camera's view, so a first page shows the scene rather than a black canvas; the page says
    // what to do.
    shown.empty = true;
    fctx.fillStyle = '#000';
    fctx.fillRect(0, 0, W, H);
    const src = sources[d.selected];
    if (src) fctx.putImageData(new ImageData(new Uint8ClampedArray(src.px), W, H), 0, 0);
    shown.camera = src ? d.selected : 0;
    return shown;
  }
  if (d.mode === 'final') {
    // The server's preview is the composite (docs/studio.md, "Engine"), shown as it came. Only
    // while a stroke waits for its preview do painted pixels take their camera's view (or
    // thumbnail) here, so the paint shows at once.
    const src = sources.map((s) => s && (d.pending || !preview) && s.px);
    if (preview) { shown.seq = preview.seq; shown.spp = preview.spp; }
    if (preview && !src.some(Boolean)) {
      fctx.fillStyle = '#000';
      fctx.fillRect(0, 0, W, H);
      fctx.imageSmoothingEnabled = true;
      fctx.drawImage(preview.bmp, 0, 0, W, H);
      return shown;
    }
    if (preview && !preview.px) preview.px = pixelsAtCollageSize(preview.bmp);
    const prev = preview && preview.px;
    const labels = d.labels;
    for (let i = 0, p = 0; i < n; i++, p += 4) {
      const s = src[labels[i]] || prev;
      if (s) { o[p] = s[p]; o[p + 1] = s[p + 1]; o[p + 2] = s[p + 2]; } else { o[p] = o[p + 1] = o[p + 2] = 0; }
      o[p + 3] = 255;
    }
  } else if (d.mode === 'labels' || d.mode === 'regions') {
    const map = d.mode === 'labels' ? d.labels : d.regions;
    const table = [];
    for (let v = 0; v < 256; v++) table.push(d.mode === 'labels' ? (d.colors[v] ? hexColor(d.colors[v]) : [0, 0, 0]) : regionColor(v));
    for (let i = 0, p = 0; i < n; i++, p += 4) {
      const c = table[map[i]];
      o[p] = c[0]; o[p + 1] = c[1]; o[p + 2] = c[2]; o[p + 3] = 255;
    }
  } else {
    fctx.fillStyle = '#000';
    fctx.fillRect(0, 0, W, H);
    const src = sources[d.selected];
    if (view && view.mode === d.mode) {
      fctx.imageSmoothingEnabled = true;
      fctx.drawImage(view.bmp, 0, 0, W, H);
    } else if (d.mode === 'source' && src) {
      fctx.putImageData(new ImageData(new Uint8ClampedArray(src.px), W, H), 0, 0);
    }
    return shown;
  }
  fctx.putImageData(out, 0, 0);
  return shown;
}

onmessage = (e) => {
  const m = e.data;
  switch (m.type) {
    case 'size': resize(m.w, m.h); break;
    case 'seq': seqNow = Math.max(seqNow, m.seq); break;
    case 'view': view = null; break;
    case 'picture': picture(m.h, m.buf, m.mode); break;
    case 'compose': {
      if (!W) { postMessage({ type: 'frame', gen: m.gen, bmp: null, shown: null }); break; }
      const shown = compose(m);
      const bmp = frame.transferToImageBitmap();
      postMessage({ type: 'frame', gen: m.gen, bmp, shown }, [bmp]);
      break;
    }
    default: break;
  }
};
