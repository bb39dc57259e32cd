// The pictures (docs/studio.md, "The page"): the server's previews, views and thumbnails go
// straight on to the picture worker (compose.js), which decodes them, drops what a newer `seq`
// has made stale, and draws each frame of the canvas off the main thread; here a frame is only
// copied onto the canvas. Also the view the canvas shows (final, labels, source, …), the
// selection's outline over it, and the hint on an empty canvas.
import { $, assetUrl, note } from './dom.js';
import { listen, send, seq } from './connection.js';
import { emit, on, timed } from './timing.js';
import { drawWith, frameDone, schedule } from './redraw.js';
import * as cameras from './cameras.js';
import * as paint from './paint.js';
import * as final from './final.js';

const canvas = $('canvas');
const overlay = $('overlay');
const ctx = canvas.getContext('2d');
const octx = overlay.getContext('2d');

let mode = 'final'; // the view the canvas shows
const imageSeq = new Map(); // newest seq per picture kind and camera
let seqSeen = 0; // the seq the worker was last told of (or saw in a picture)
let previewSeq = -1;
let sources = []; // per camera index: { seq, full } of the picture the worker keeps of its view

// The view the canvas shows.
export const viewMode = () => mode;
// The seq of the newest preview shown.
export const shownPreviewSeq = () => previewSeq;
// Per camera index, what the worker keeps of its view: { seq, full }.
export const cameraSources = () => sources;

// The worker gets each picture's bytes (moved, not copied) with the mode it was asked in, and
// answers with what it accepted; the page keeps only what it shows in text.
const worker = new Worker(assetUrl('compose.js'));
worker.onerror = (e) => { emit('error', `picture worker: ${e.message}`); note('the picture worker failed: reload the page', true); };
worker.onmessage = timed('worker message', (e) => {
  const m = e.data;
  if (m.type === 'picture') onPicture(m);
  else if (m.type === 'frame') onFrame(m);
  else if (m.type === 'error') note(m.message, true);
});

function imageKey(h) { return `${h.kind}:${h.camera ?? ''}`; }
function stale(h) {
  // A preview is stale after any newer stroke or camera change; a camera's thumb or view only
  // after a newer one of that camera (the worker checks again once it has decoded it).
  if (h.kind === 'preview') return h.seq < seq();
  return h.seq < (imageSeq.get(imageKey(h)) ?? -1);
}
listen('image', (h, buf) => {
  seqSeen = seq();
  if (stale(h)) return;
  imageSeq.set(imageKey(h), h.seq);
  if (h.kind === 'final') { final.show(h, buf); return; }
  worker.postMessage({ type: 'picture', h, buf, mode, seq: seq() }, [buf]);
});

// The server's state has come: the worker learns a newer seq.
export function stateArrived() {
  if (seq() > seqSeen) {
    seqSeen = seq();
    worker.postMessage({ type: 'seq', seq: seqSeen });
  }
}

// A picture the worker decoded and kept.
function onPicture({ h, w, hgt, full, bmp, mode: asked }) {
  emit('picture', { h, w, hgt });
  if (h.kind === 'preview') {
    paint.previewArrived(h.seq);
    previewSeq = h.seq;
    $('preview-info').textContent = `preview ${w}×${hgt}, ${h.spp} spp`;
  } else if (h.kind === 'thumb') {
    cameras.drawThumb(h.camera, bmp);
    bmp.close();
    const src = sources[h.camera];
    if (!src || !src.full || src.seq < h.seq) sources[h.camera] = { seq: h.seq, full };
  } else if (h.kind === 'view' && h.camera && asked === 'source') {
    sources[h.camera] = { seq: h.seq, full };
  }
  schedule();
}

// The canvas for a `w × h` collage (the maps are paint.js's).
export function resize(w, h) {
  sources = [];
  worker.postMessage({ type: 'size', w, h });
  for (const c of [canvas, overlay]) { c.width = w; c.height = h; }
  fitCanvas();
}

function fitCanvas() {
  const [W, H] = [paint.width(), paint.height()];
  if (!W) return;
  const box = $('canvas-box');
  const scale = Math.max(1, Math.floor(Math.min(box.clientWidth / W, (box.clientHeight || 1e9) / H)));
  for (const c of [canvas, overlay]) {
    c.style.width = `${W * scale}px`;
    c.style.height = `${H * scale}px`;
  }
}
on(window, 'resize', fitCanvas);

// ---- views ------------------------------------------------------------------------------------
export function setView(m) {
  mode = m;
  worker.postMessage({ type: 'view' });
  for (const b of document.querySelectorAll('#views button')) b.classList.toggle('on', b.dataset.view === m);
  const msg = { type: 'view', mode: m };
  if (m === 'source' || m === 'weights') msg.camera = cameras.selectedCamera();
  send(msg);
  overlay.style.cursor = m === 'source' ? 'grab' : 'crosshair';
  schedule();
}
for (const b of document.querySelectorAll('#views button')) on(b, 'click', () => setView(b.dataset.view));
for (const b of document.querySelectorAll('#views button')) b.classList.toggle('on', b.dataset.view === 'final');
// The source and weights views show the selected camera.
cameras.whenSelected(() => {
  if (mode === 'source' || mode === 'weights') setView(mode);
  schedule();
});

// ---- drawing the canvas -----------------------------------------------------------------------
// The maps go as copies, so the tools can keep changing the page's own while the worker draws.
drawWith(() => paint.width() > 0, () => {
  const labels = paint.labelMap().slice();
  const regions = mode === 'regions' ? paint.regionMap().slice() : null;
  const msg = { type: 'compose', mode, selected: cameras.selectedCamera(), pending: paint.pending(), paints: paint.paintCount(), colors: cameras.colors(), labels, regions };
  worker.postMessage(msg, regions ? [labels.buffer, regions.buffer] : [labels.buffer]);
});

// A frame from the worker: copied onto the canvas (one drawImage of a bitmap).
function onFrame({ bmp, shown }) {
  if (bmp) {
    ctx.drawImage(bmp, 0, 0);
    bmp.close();
    drawOverlay();
    showHint(shown);
    // What the canvas now shows, for the browser test.
    emit('drawn', shown);
  }
  frameDone();
}

// Over a canvas with nothing painted: what it shows and what to do (changed only when it
// changes: no layout work per frame).
function showHint(shown) {
  const empty = !!(shown && shown.empty && mode === 'final');
  const c = empty && shown.camera ? cameras.camera(shown.camera) : null;
  const text = !empty ? '' : `Nothing painted yet${c ? `: this is camera ${c.index} “${c.name}”` : ''}. `
    + 'Pick a camera on the left (or press 1–9), then paint with the Brush where it should be seen; '
    + 'the canvas then shows the collage as rendered.';
  const hint = $('hint');
  if (hint.textContent !== text) hint.textContent = text;
  if (hint.hidden !== !empty) hint.hidden = !empty;
}

function drawOverlay() {
  octx.clearRect(0, 0, paint.width(), paint.height());
  const sel = paint.currentSelection();
  if (sel && mode !== 'source') {
    octx.save();
    octx.lineWidth = 1;
    octx.setLineDash([3, 3]);
    octx.strokeStyle = '#fff';
    octx.strokeRect(sel.x + 0.5, sel.y + 0.5, sel.w - 1, sel.h - 1);
    octx.strokeStyle = '#000';
    octx.lineDashOffset = 3;
    octx.strokeRect(sel.x + 0.5, sel.y + 0.5, sel.w - 1, sel.h - 1);
    octx.restore();
  }
}

// While the selection is dragged: its outline at the offset (dx, dy), alone on the overlay.
export function outlineMove(dx, dy) {
  const s = paint.currentSelection();
  octx.clearRect(0, 0, paint.width(), paint.height());
  octx.strokeStyle = '#fff';
  octx.strokeRect(s.x + dx + 0.5, s.y + dy + 0.5, s.w - 1, s.h - 1);
}
