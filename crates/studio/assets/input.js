// The user's input (docs/studio.md, "The page"): pointer drags on the canvas (paint, select,
// move the selection, or orbit and pan the selected camera in the source view), the wheel, the
// tools and the keys. Every tool is rasterised in paint.js into `paint` patches (whole pixels,
// no antialiasing), so the server needs no brush code.
import { $ } from './dom.js';
import { send } from './connection.js';
import { on } from './timing.js';
import { schedule } from './redraw.js';
import * as cameras from './cameras.js';
import * as paint from './paint.js';
import { outlineMove, viewMode } from './pictures.js';

const overlay = $('overlay');
let tool = 'brush';
let drag = null; // the drag under way: { kind: 'paint' | 'select' | 'move' | 'orbit' | 'pan', … }

function setDrag(d) {
  drag = d;
  cameras.holdForm(!!d);
}

function pixelAt(e) {
  const r = overlay.getBoundingClientRect();
  return { x: ((e.clientX - r.left) * paint.width()) / r.width, y: ((e.clientY - r.top) * paint.height()) / r.height };
}
on(overlay, 'contextmenu', (e) => e.preventDefault());
on(overlay, 'pointerdown', (e) => {
  if (!paint.width() || drag) return;
  overlay.setPointerCapture(e.pointerId);
  const p = pixelAt(e);
  if (viewMode() === 'source') {
    const d = cameras.startDrag(e.shiftKey || e.button !== 0 ? 'pan' : 'orbit');
    if (d) setDrag({ ...d, last: e });
  } else if (tool === 'select') {
    const s = paint.currentSelection();
    const inside = s && p.x >= s.x && p.y >= s.y && p.x < s.x + s.w && p.y < s.y + s.h;
    setDrag({ kind: inside ? 'move' : 'select', start: p });
  } else {
    const layer = tool === 'region' ? 'regions' : 'labels';
    const value = tool === 'brush' ? cameras.selectedCamera() : tool === 'region' ? Math.min(254, Number($('region').value) | 0) : 0;
    paint.beginStroke(layer, value);
    paint.strokeTo(p);
    setDrag({ kind: 'paint' });
  }
});
on(overlay, 'pointermove', (e) => {
  if (!drag) return;
  // Coalesced events keep every pixel a fast stroke crossed.
  const events = e.getCoalescedEvents ? e.getCoalescedEvents() : [e];
  if (drag.kind === 'paint') for (const ev of events.length ? events : [e]) paint.strokeTo(pixelAt(ev));
  else if (drag.kind === 'orbit' || drag.kind === 'pan') {
    cameras.dragBy(drag, e.clientX - drag.last.clientX, e.clientY - drag.last.clientY, paint.height());
    drag.last = e;
  } else {
    const p = pixelAt(e);
    const a = drag.start;
    if (drag.kind === 'select') {
      paint.setSelection(paint.clipRect({ x: Math.floor(Math.min(a.x, p.x)), y: Math.floor(Math.min(a.y, p.y)),
        w: Math.abs(Math.floor(p.x) - Math.floor(a.x)) + 1, h: Math.abs(Math.floor(p.y) - Math.floor(a.y)) + 1 }));
    } else {
      drag.dx = Math.round(p.x - a.x);
      drag.dy = Math.round(p.y - a.y);
      outlineMove(drag.dx, drag.dy);
      return;
    }
    schedule();
  }
});
function endDrag() {
  if (!drag) return;
  const d = drag;
  setDrag(null);
  if (d.kind === 'paint') paint.endStroke();
  else if (d.kind === 'move' && (d.dx || d.dy)) paint.moveSelection(d.dx, d.dy);
  else if (d.kind === 'orbit' || d.kind === 'pan') cameras.endDrag(d);
  schedule();
}
on(overlay, 'pointerup', endDrag);
on(overlay, 'pointercancel', endDrag);
on(overlay, 'wheel', (e) => {
  if (viewMode() !== 'source' || !cameras.camera(cameras.selectedCamera())) return;
  e.preventDefault();
  cameras.wheel(e, paint.height());
}, { passive: false });

// ---- tools, edits, keys -----------------------------------------------------------------------
function setTool(t) {
  tool = t;
  for (const b of document.querySelectorAll('#tools button')) b.classList.toggle('on', b.dataset.tool === t);
}
for (const b of document.querySelectorAll('#tools button')) on(b, 'click', () => setTool(b.dataset.tool));
on($('cut'), 'click', paint.cut);
on($('copy'), 'click', paint.copySelection);
on($('paste'), 'click', paint.paste);
on($('undo'), 'click', () => send({ type: 'undo' }));
on($('redo'), 'click', () => send({ type: 'redo' }));
on(document, 'keydown', (e) => {
  if (e.target.tagName === 'INPUT') return;
  const k = e.key.toLowerCase();
  if (e.ctrlKey || e.metaKey) {
    if (k === 'z') send({ type: e.shiftKey ? 'redo' : 'undo' });
    else if (k === 'y') send({ type: 'redo' });
    else if (k === 'x') paint.cut();
    else if (k === 'c') paint.copySelection();
    else if (k === 'v') paint.paste();
    else return;
  } else if (k === 'delete' || k === 'backspace') {
    paint.clearSelection();
  } else if (k === 'escape') { paint.setSelection(null); schedule(); }
  else if ({ b: 1, e: 1, r: 1, s: 1 }[k]) setTool({ b: 'brush', e: 'eraser', r: 'region', s: 'select' }[k]);
  else if (k >= '1' && k <= '9' && cameras.camera(Number(k))) cameras.select(Number(k));
  else return;
  e.preventDefault();
});
setTool('brush');
