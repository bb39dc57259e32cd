// The final render (docs/studio.md, "The page"): its size, spp and shutter, the Render and Cancel buttons,
// the progress bar, and the render itself, shown from the server's own PNG bytes (never
// re-encoded) with a link to download it.
import { $, note } from './dom.js';
import { listen, send } from './connection.js';
import { on } from './timing.js';

let finalId = null; // the id of the `render_final` message of the render under way
let finalBytes = null;
let finalUrl = null;

// The PNG bytes of the render shown (null before the first).
export const shownBytes = () => finalBytes;

on($('render-final'), 'click', () => {
  const w = parseInt($('final-w').value, 10), h = parseInt($('final-h').value, 10), spp = parseInt($('final-spp').value, 10);
  if (!(w > 0 && h > 0 && spp > 0)) { note('render final: size and spp must be positive whole numbers', true); return; }
  const text = $('final-shutter').value.trim();
  const request = { type: 'render_final', res: [w, h], spp };
  if (text !== '') {
    const m = /^([0-9.]+)\s*\.\.=?\s*([0-9.]+)$/.exec(text);
    if (!m) { note(`render final: shutter '${text}' is not OPEN..CLOSE (like 0..0.5)`, true); return; }
    request.shutter = [parseFloat(m[1]), parseFloat(m[2])];
  }
  $('final-progress').value = 0;
  $('render-final').disabled = true;
  $('cancel-final').disabled = false;
  finalId = send(request);
});
on($('cancel-final'), 'click', () => send({ type: 'cancel_final' }));

listen('progress', (m) => {
  if (m.job !== 'final') return;
  const bar = $('final-progress');
  bar.max = Math.max(1, m.total);
  bar.value = m.done;
});

// The final render's end: where it was written, or that it was cancelled.
listen('final', (m) => {
  $('render-final').disabled = false;
  $('cancel-final').disabled = true;
  if (m.cancelled) note('final render cancelled');
  else if (m.exr) note(`final render written to ${m.exr}`);
});

// Message `id` was refused: if it asked for the render, the buttons are back.
export function refused(id) {
  if (id === finalId) { $('render-final').disabled = false; $('cancel-final').disabled = true; }
}

// The render's picture (header `h`, PNG bytes `buf`). The same render again (`hello` re-sends
// the latest) changes nothing, nor hides a newer message.
export function show(h, buf) {
  const bytes = new Uint8Array(buf);
  const old = finalBytes;
  if (old && old.length === bytes.length && old.every((v, i) => v === bytes[i])) return;
  finalBytes = bytes;
  if (finalUrl) URL.revokeObjectURL(finalUrl);
  finalUrl = URL.createObjectURL(new Blob([buf], { type: 'image/png' }));
  $('final-img').src = finalUrl;
  $('final-link').href = finalUrl;
  $('final-link').hidden = false;
  note(`final render ${h.w}×${h.h}, ${h.spp} spp done`);
}
