// The studio page (docs/studio.md, "The page"): the entry module. It brings in the page's parts —
// connection.js (the socket), cameras.js (the list, the form, orbit and pan), paint.js (the maps
// and the tools that change them), pictures.js (the worker and the canvas), final.js (the final
// render), input.js (pointer, tools, keys) — and settles each message that concerns several of
// them in one place, in order: the server's state, its errors, the header bar's settings.
import { $, note } from './dom.js';
import { connect, listen, send } from './connection.js';
import { on, probing } from './timing.js';
import { schedule } from './redraw.js';
import * as cameras from './cameras.js';
import * as paint from './paint.js';
import * as pictures from './pictures.js';
import * as final from './final.js';
import './input.js';

// The server's state, after every change (this tab's or another's).
listen('state', (st) => {
  pictures.stateArrived();
  paint.settle(st);
  cameras.settle(st.id);
  const [w, h] = st.res;
  if (w !== paint.width() || h !== paint.height()) {
    paint.resize(w, h);
    pictures.resize(w, h);
  }
  cameras.apply(st);
  $('seamless').checked = !!st.seamless;
  // Without the denoiser installed the toggle is off and disabled; its tooltip says why.
  $('denoise').checked = !!st.denoise && !!st.denoiser;
  $('denoise').disabled = !st.denoiser;
  $('denoise-label').title = st.denoiser
    ? 'Show the preview and thumbnails denoised (Intel Open Image Denoise ' + st.denoiser + '); off: the raw samples. Painted pixels always show the camera\'s own view.'
    : 'Denoising needs Intel Open Image Denoise (README, "Denoising"): the preview shows raw samples.';
  if (document.activeElement !== $('frame')) $('frame').value = st.frame;
  $('frames').replaceChildren(...(st.frames || []).map((f) => new Option(String(f), String(f))));
  $('undo').disabled = !st.can_undo;
  $('redo').disabled = !st.can_redo;
  schedule();
});

// A refused message: shown; a refused stroke or camera edit leaves the page's optimistic copy
// wrong, so the server's maps and cameras are asked for again.
listen('error', (m) => {
  note(m.message, true);
  final.refused(m.id);
  if (paint.refused(m.id)) send({ type: 'hello' });
  if (cameras.refused(m.id)) send({ type: 'hello' });
});

listen('saved', (m) => note(`saved to ${m.dir}`));

// An earlier session stopped with unsaved changes: offer them (every tab; gone once answered).
listen('autosave', (m) => {
  const age = Number.isFinite(m.age_seconds) ? ` ${Math.round(m.age_seconds / 60)} min ago` : '';
  $('autosave-text').textContent = m.dir ? `Unsaved changes of an earlier session (stopped${age}) were kept in ${m.dir}.` : '';
  $('autosave').hidden = !m.dir;
});
on($('autosave-restore'), 'click', () => send({ type: 'autosave', restore: true }));
on($('autosave-discard'), 'click', () => send({ type: 'autosave', restore: false }));

// ---- the header bar's settings ------------------------------------------------------------------
on($('seamless'), 'change', () => send({ type: 'settings', seamless: $('seamless').checked }));
on($('denoise'), 'change', () => send({ type: 'denoise', on: $('denoise').checked }));
on($('frame'), 'change', () => {
  const f = parseInt($('frame').value, 10);
  if (Number.isFinite(f) && f >= 0) send({ type: 'frame', frame: f });
});
on($('save'), 'click', () => { note('saving…'); send({ type: 'save' }); });

// The browser test's read-out, only when it asked for it (timing.js); before the first message.
if (probing) await import('./probe.js');
connect();
