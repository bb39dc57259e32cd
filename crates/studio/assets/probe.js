// The browser test's read-out of the page (tests/studio_page/), loaded only when the page is
// opened with `probe` in its query string (timing.js): `window.studio` gives what the parts of
// the page hold (through their exported functions) and what happened — the connection's log,
// the pictures that came, what each frame shows, errors, long tasks and the handlers' times. The
// test's draw hook (`afterDraw`) runs after every frame, its time left out of the handlers'.
import { listen } from './connection.js';
import * as connection from './connection.js';
import { handlerTimes, untimed, watch } from './timing.js';
import * as cameras from './cameras.js';
import * as paint from './paint.js';
import * as pictures from './pictures.js';
import * as final from './final.js';

const probe = {
  state: null, drawn: null, afterDraw: null, socket: null, reconnects: 0,
  savedDir: null, finalExr: null, loadedAt: null,
  connLog: [], thumbLog: [], previewLog: [], errors: [], longTasks: [],
  get W() { return paint.width(); },
  get H() { return paint.height(); },
  get labels() { return paint.labelMap(); },
  get selected() { return cameras.selectedCamera(); },
  get cameraEdits() { return cameras.pendingEdits(); },
  get seq() { return connection.seq(); },
  get previewSeq() { return pictures.shownPreviewSeq(); },
  get sources() { return pictures.cameraSources(); },
  get finalBytes() { return final.shownBytes(); },
  get handlers() { return handlerTimes().handlers; },
  get slowHandlers() { return handlerTimes().slow; },
};
window.studio = probe;

// A script error is an error of the page: kept with the server's.
window.addEventListener('error', (e) => probe.errors.push(`script: ${e.message}`));
// Long tasks: anything blocking the page over 50 ms.
try {
  new PerformanceObserver((list) => {
    for (const e of list.getEntries()) probe.longTasks.push({ start: Math.round(e.startTime), ms: Math.round(e.duration) });
  }).observe({ type: 'longtask', buffered: true });
} catch (_) { /* not supported: nothing to record */ }

listen('state', (st) => { probe.state = st; });
listen('error', (m) => probe.errors.push(m.message));
listen('saved', (m) => { probe.savedDir = m.dir; });
listen('final', (m) => { if (!m.cancelled && m.exr) probe.finalExr = m.exr; });
watch('error', (text) => probe.errors.push(text));
watch('socket', (socket) => { probe.socket = socket; });
watch('reconnect', () => { probe.reconnects += 1; });
watch('connection', (text) => probe.connLog.push(text));
watch('picture', ({ h, w, hgt }) => {
  if (probe.loadedAt === null) probe.loadedAt = performance.now();
  if (h.kind === 'preview') probe.previewLog.push({ seq: h.seq, spp: h.spp, w, h: hgt, t: performance.now() });
  else if (h.kind === 'thumb') probe.thumbLog.push({ camera: h.camera, w, h: hgt, spp: h.spp });
});
watch('drawn', (shown) => {
  probe.drawn = shown;
  if (probe.afterDraw) untimed(probe.afterDraw);
});
