// The studio page (docs/studio.md): the collage canvas, its tools and the camera controls.
// Every tool is rasterised here into `paint` patches (whole pixels, no antialiasing: each pixel is
// one camera or the background), so the server needs no brush code. Pictures arrive as a JSON
// header and one binary PNG, which goes straight on to the picture worker (compose.js): it
// decodes, drops what a newer `seq` has made stale, and draws each frame of the canvas off the
// main thread; here a frame is only copied onto the canvas (docs/studio.md, "The page").
'use strict';
(() => {
  const $ = (id) => document.getElementById(id);
  const token = new URLSearchParams(location.search).get('token') || '';
  const canvas = $('canvas');
  const overlay = $('overlay');
  const ctx = canvas.getContext('2d');
  const octx = overlay.getContext('2d');

  // What the page knows; `window.studio` lets the browser test read it.
  const S = {
    state: null, W: 0, H: 0, labels: null, regions: null,
    selected: 1, mode: 'final', tool: 'brush',
    seq: 0, imageSeq: new Map(), // newest seq per image kind and camera
    previewSpp: 0, previewSeq: -1, previews: 0, previewLog: [],
    savedDir: null, finalBytes: null, finalExr: null, loadedAt: null, paintPending: false, paints: 0,
    sources: [], // per camera index: { seq, full } of the picture the worker keeps of its view
    finalUrl: null,
    selection: null, clipboard: null, paintIds: new Set(), cameraIds: new Set(),
    // Replies go to every tab: ids start at random so one tab never takes another's as its own.
    nextId: 1 + Math.floor(Math.random() * 1e9),
    longTasks: [], errors: [], thumbLog: [],
  };
  window.studio = S;
  // A script error is an error of the page: kept with the server's, for the browser test.
  window.addEventListener('error', (e) => S.errors.push(`script: ${e.message}`));

  // Long tasks (anything blocking the page over 50 ms) are kept for the test and the status line.
  try {
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) S.longTasks.push({ start: Math.round(e.startTime), ms: Math.round(e.duration) });
    }).observe({ type: 'longtask', buffered: true });
  } catch (_) { /* not supported: nothing to record */ }

  // The page's own handlers, timed: per handler its calls, total and longest; a call over 16 ms
  // also as a `performance.measure` (it shows in a DevTools trace) and in `slowHandlers`.
  // The browser test's draw hook is its code, not the page's: its time is left out.
  S.handlers = {};
  S.slowHandlers = [];
  let hookMs = 0;
  function timed(name, fn) {
    return function timedHandler(...args) {
      const t0 = performance.now();
      const hook0 = hookMs;
      try {
        return fn.apply(this, args);
      } finally {
        const ms = performance.now() - t0 - (hookMs - hook0);
        const h = S.handlers[name] || (S.handlers[name] = { calls: 0, ms: 0, max: 0 });
        h.calls += 1;
        h.ms += ms;
        h.max = Math.max(h.max, ms);
        if (ms > 16 && S.slowHandlers.length < 1000) {
          performance.measure(name, { start: t0, duration: ms });
          S.slowHandlers.push({ name, start: Math.round(t0), ms: Math.round(ms) });
        }
      }
    };
  }
  // `target.addEventListener(type, …)` with the handler timed under `name` (default: the type).
  const on = (target, type, fn, opts, name = type) => target.addEventListener(type, timed(name, fn), opts);

  // ---- the connection -------------------------------------------------------------------------
  let ws = null;
  let pendingImage = null;
  let retries = 0;
  S.reconnects = 0;
  function connect() {
    const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
    const socket = new WebSocket(`${scheme}//${location.host}/ws?token=${encodeURIComponent(token)}`);
    ws = socket;
    S.socket = socket;
    socket.binaryType = 'arraybuffer';
    socket.onopen = timed('socket open', () => {
      retries = 0;
      setConnection('connected', false);
      send({ type: 'hello' });
    });
    // A lost connection is shown and tried again, waiting longer each time (½ s up to 8 s);
    // `hello` then brings back the session as the server holds it. Strokes whose replies were
    // lost are settled by the maps that come with it.
    socket.onclose = timed('socket close', () => {
      if (ws !== socket) return;
      const wait = Math.min(8000, 500 * 2 ** retries);
      retries += 1;
      setConnection(`disconnected: trying again in ${(wait / 1000).toFixed(1)} s…`, true);
      pendingImage = null;
      S.paintIds.clear();
      S.paintPending = false;
      for (const layer of Object.keys(waitingLabels)) delete waitingLabels[layer];
      setTimeout(timed('reconnect', () => { S.reconnects += 1; connect(); }), wait);
    });
    socket.onmessage = timed('socket message', (ev) => {
      if (typeof ev.data === 'string') onMessage(JSON.parse(ev.data));
      else onImageBytesTimed(ev.data);
    });
  }
  S.connLog = [];
  function setConnection(text, error) {
    S.connLog.push(text);
    $('conn').textContent = text;
    $('conn').classList.toggle('error', error);
  }
  // Sends a message with a fresh id; while disconnected it is lost, and the user is told.
  function send(msg) {
    msg.id = S.nextId++;
    if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(msg));
    else note(`not connected: ${msg.type} was not sent`, true);
    return msg.id;
  }

  // Each kind of message is timed on its own too (`socket state`, `socket labels`, …), so a slow
  // `socket message` in the record says which kind it was.
  const byType = new Map();
  function onMessage(m) {
    const type = ['state', 'labels', 'progress', 'saved', 'error', 'final', 'image', 'autosave'].includes(m.type) ? m.type : 'other';
    if (!byType.has(type)) byType.set(type, timed(`socket ${type}`, dispatch));
    byType.get(type)(m);
  }
  function dispatch(m) {
    switch (m.type) {
      case 'state': applyState(m); break;
      case 'labels': onLabels(m); break;
      case 'progress': onProgress(m); break;
      case 'saved': S.savedDir = m.dir; note(`saved to ${m.dir}`); break;
      case 'error': onError(m); break;
      case 'final': onFinalDone(m); break;
      case 'image': pendingImage = m; break;
      case 'autosave': onAutosave(m); break;
      default: break;
    }
  }

  // An earlier session stopped with unsaved changes: offer them (every tab; gone once answered).
  function onAutosave(m) {
    S.autosave = m.dir;
    const age = Number.isFinite(m.age_seconds) ? ` ${Math.round(m.age_seconds / 60)} min ago` : '';
    $('autosave-text').textContent = m.dir ? `Unsaved changes of an earlier session (stopped${age}) were kept in ${m.dir}.` : '';
    $('autosave').hidden = !m.dir;
  }
  on($('autosave-restore'), 'click', () => send({ type: 'autosave', restore: true }));
  on($('autosave-discard'), 'click', () => send({ type: 'autosave', restore: false }));

  function onError(m) {
    S.errors.push(m.message);
    note(m.message, true);
    if (m.id === S.finalId) { $('render-final').disabled = false; $('cancel-final').disabled = true; }
    // A refused stroke or camera edit leaves the page's optimistic copy wrong: ask for the
    // server's maps and cameras again.
    if (S.paintIds.has(m.id)) { paintDone(m.id); send({ type: 'hello' }); }
    if (S.cameraIds.delete(m.id)) send({ type: 'hello' });
  }

  // Every tab's maps as the server holds them (strokes of other tabs too). While this tab's own
  // strokes are on their way the newest map waits: it would hide them; the reply to the last
  // one brings it in, with everything up to that stroke.
  const waitingLabels = {};
  function onLabels(m) {
    if (S.paintIds.size) waitingLabels[m.layer] = m;
    else setLayer(m.layer, paint.decodeBase64(m.data));
  }
  function paintDone(id) {
    if (!S.paintIds.delete(id) || S.paintIds.size) return;
    for (const [layer, m] of Object.entries(waitingLabels)) {
      setLayer(layer, paint.decodeBase64(m.data));
      delete waitingLabels[layer];
    }
  }

  function onProgress(m) {
    if (m.job !== 'final') return;
    const bar = $('final-progress');
    bar.max = Math.max(1, m.total);
    bar.value = m.done;
  }

  // ---- pictures ---------------------------------------------------------------------------------
  // The worker gets each picture's bytes (moved, not copied) with the mode it was asked in, and
  // answers with what it accepted; the page keeps only what it shows in text.
  const worker = new Worker(`assets/compose.js?token=${encodeURIComponent(token)}`);
  worker.onerror = (e) => { S.errors.push(`picture worker: ${e.message}`); note('the picture worker failed: reload the page', true); };
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
    if (h.kind === 'preview') return h.seq < S.seq;
    return h.seq < (S.imageSeq.get(imageKey(h)) ?? -1);
  }
  const onImageBytesTimed = timed('socket picture bytes', (buf) => onImageBytes(buf));
  function onImageBytes(buf) {
    const h = pendingImage;
    pendingImage = null;
    if (!h) return;
    S.seq = Math.max(S.seq, h.seq ?? 0);
    if (stale(h)) return;
    S.imageSeq.set(imageKey(h), h.seq);
    if (h.kind === 'final') { showFinal(h, buf); return; }
    worker.postMessage({ type: 'picture', h, buf, mode: S.mode, seq: S.seq }, [buf]);
  }

  // A picture the worker decoded and kept.
  function onPicture({ h, w, hgt, full, bmp, mode }) {
    if (S.loadedAt === null) S.loadedAt = performance.now();
    if (h.kind === 'preview') {
      const p = S.paintPending;
      if (p && (p.seq !== null ? h.seq >= p.seq : h.seq > p.after)) S.paintPending = false;
      S.previewSpp = h.spp;
      S.previewSeq = h.seq;
      S.previews += 1;
      S.previewLog.push({ seq: h.seq, spp: h.spp, w, h: hgt, t: performance.now() });
      $('preview-info').textContent = `preview ${w}×${hgt}, ${h.spp} spp`;
    } else if (h.kind === 'thumb') {
      S.thumbLog.push({ camera: h.camera, w, h: hgt, spp: h.spp });
      drawThumb(h.camera, bmp);
      bmp.close();
      const src = S.sources[h.camera];
      if (!src || !src.full || src.seq < h.seq) S.sources[h.camera] = { seq: h.seq, full };
    } else if (h.kind === 'view' && h.camera && mode === 'source') {
      S.sources[h.camera] = { seq: h.seq, full };
    }
    schedule();
  }

  function drawThumb(index, bmp) {
    const c = document.querySelector(`#camera-list li[data-index="${index}"] canvas`);
    if (!c) return;
    c.width = bmp.width;
    c.height = bmp.height;
    c.getContext('2d').drawImage(bmp, 0, 0);
  }

  // The final render is shown from the server's own PNG bytes, never re-encoded. The same
  // render again (`hello` re-sends the latest) changes nothing, nor hides a newer message.
  function showFinal(h, buf) {
    const bytes = new Uint8Array(buf);
    const old = S.finalBytes;
    if (old && old.length === bytes.length && old.every((v, i) => v === bytes[i])) return;
    S.finalBytes = bytes;
    if (S.finalUrl) URL.revokeObjectURL(S.finalUrl);
    S.finalUrl = URL.createObjectURL(new Blob([buf], { type: 'image/png' }));
    $('final-img').src = S.finalUrl;
    $('final-link').href = S.finalUrl;
    $('final-link').hidden = false;
    note(`final render ${h.w}×${h.h}, ${h.spp} spp done`);
  }

  // The final render's end: where it was written, or that it was cancelled.
  function onFinalDone(m) {
    $('render-final').disabled = false;
    $('cancel-final').disabled = true;
    if (m.cancelled) note('final render cancelled');
    else if (m.exr) { S.finalExr = m.exr; note(`final render written to ${m.exr}`); }
  }

  // ---- state ------------------------------------------------------------------------------------
  function applyState(st) {
    S.state = st;
    if (Number.isFinite(st.seq) && st.seq > S.seq) {
      S.seq = st.seq;
      worker.postMessage({ type: 'seq', seq: S.seq });
    }
    if (S.paintPending && S.paintPending.id === st.id && Number.isFinite(st.seq)) S.paintPending.seq = st.seq;
    if (S.paintIds.has(st.id)) paintDone(st.id);
    S.cameraIds.delete(st.id);
    const [w, h] = st.res;
    if (w !== S.W || h !== S.H) resize(w, h);
    if (!st.cameras.some((c) => c.index === S.selected) && st.cameras.length) S.selected = st.cameras[0].index;
    renderCameraList();
    fillCameraForm();
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
  }

  function resize(w, h) {
    S.W = w;
    S.H = h;
    S.labels = new Uint8Array(w * h);
    S.regions = new Uint8Array(w * h);
    S.sources = [];
    worker.postMessage({ type: 'size', w, h });
    for (const c of [canvas, overlay]) { c.width = w; c.height = h; }
    fitCanvas();
  }

  function fitCanvas() {
    if (!S.W) return;
    const box = $('canvas-box');
    const scale = Math.max(1, Math.floor(Math.min(box.clientWidth / S.W, (box.clientHeight || 1e9) / S.H)));
    for (const c of [canvas, overlay]) {
      c.style.width = `${S.W * scale}px`;
      c.style.height = `${S.H * scale}px`;
    }
  }
  on(window, 'resize', fitCanvas);

  function camera(index) { return S.state && S.state.cameras.find((c) => c.index === index); }

  function renderCameraList() {
    const list = $('camera-list');
    const keep = new Map([...list.children].map((li) => [Number(li.dataset.index), li]));
    const items = S.state.cameras.map((c) => {
      let li = keep.get(c.index);
      if (!li) {
        li = document.createElement('li');
        li.dataset.index = c.index;
        li.innerHTML = '<span class="swatch"></span><span class="name"></span>'
          + '<button class="dup" title="Duplicate this camera">duplicate</button><canvas width="96" height="54"></canvas>';
        on(li, 'click', (e) => {
          if (e.target.classList.contains('dup')) send({ type: 'camera_duplicate', index: c.index });
          else selectCamera(c.index);
        });
      }
      li.querySelector('.swatch').style.background = c.color;
      li.querySelector('.name').textContent = `${c.index} ${c.name}`;
      li.classList.toggle('on', c.index === S.selected);
      return li;
    });
    list.replaceChildren(...items);
  }

  function selectCamera(index) {
    S.selected = index;
    renderCameraList();
    fillCameraForm();
    if (S.mode === 'source' || S.mode === 'weights') setView(S.mode);
    schedule();
  }

  // ---- the camera form and mouse controls ----------------------------------------------------
  const form = $('camera-form');
  function fillCameraForm() {
    const c = camera(S.selected);
    if (!c || drag) return;
    for (let i = 0; i < 3; i++) {
      form[`eye${i}`].value = round(c.eye[i]);
      form[`target${i}`].value = round(c.target[i]);
    }
    form.fov.value = round(c.fov_deg);
  }
  const round = (v) => Math.round(v * 1e4) / 1e4;
  on(form, 'change', () => {
    const c = camera(S.selected);
    if (!c) return;
    // The server's `state` brings the edit back; until then (or if it refuses) the camera is
    // as it held it.
    const num = (n, old) => (Number.isFinite(parseFloat(form[n].value)) ? parseFloat(form[n].value) : old);
    sendCamera({ ...c, eye: c.eye.map((v, i) => num(`eye${i}`, v)), target: c.target.map((v, i) => num(`target${i}`, v)), fov_deg: num('fov', c.fov_deg) });
  });
  on(form, 'submit', (e) => e.preventDefault());

  // Every edit of one drag (or one burst of wheel turns) carries the same gesture number: the
  // server makes them one undo step.
  let gesture = 0, wheelAt = -Infinity;
  function sendCamera(c, g) {
    S.cameraIds.add(send({ type: 'camera_edit', index: c.index, eye: c.eye, target: c.target, up: c.up, fov_deg: c.fov_deg, gesture: g }));
  }

  const sub = (a, b) => a.map((v, i) => v - b[i]);
  const add = (a, b) => a.map((v, i) => v + b[i]);
  const mul = (a, s) => a.map((v) => v * s);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => mul(a, 1 / Math.hypot(...a));
  // Rodrigues' rotation of v about the unit axis k by angle t.
  const rotate = (v, k, t) => add(add(mul(v, Math.cos(t)), mul(cross(k, v), Math.sin(t))), mul(k, dot(k, v) * (1 - Math.cos(t))));

  let camTimer = 0;
  function moveCamera(c, kind, dx, dy, g) {
    const up = norm(c.up);
    const back = sub(c.eye, c.target);
    if (kind === 'orbit') {
      let b = rotate(back, up, -dx * 0.01);
      const right = norm(cross(up, b));
      const b2 = rotate(b, right, -dy * 0.01);
      // Stop short of the poles, where the up vector would flip the view.
      if (Math.abs(dot(norm(b2), up)) < 0.98) b = b2;
      c.eye = add(c.target, b);
    } else if (kind === 'pan') {
      const dist = Math.hypot(...back);
      const perPixel = (2 * dist * Math.tan((c.fov_deg * Math.PI) / 360)) / S.H;
      const right = norm(cross(back, up));
      const camUp = norm(cross(right, back));
      const shift = add(mul(right, dx * perPixel), mul(camUp, dy * perPixel));
      c.eye = add(c.eye, shift);
      c.target = add(c.target, shift);
    } else {
      c.eye = add(c.target, mul(back, Math.exp(dy * 0.002)));
    }
    fillCameraFormFrom(c);
    // At most one edit per 40 ms while dragging; the last one is always sent.
    if (!camTimer) camTimer = setTimeout(timed('camera edit', () => { camTimer = 0; sendCamera(c, g); }), 40);
  }
  function fillCameraFormFrom(c) {
    for (let i = 0; i < 3; i++) { form[`eye${i}`].value = round(c.eye[i]); form[`target${i}`].value = round(c.target[i]); }
  }

  // ---- views ------------------------------------------------------------------------------------
  function setView(mode) {
    S.mode = mode;
    worker.postMessage({ type: 'view' });
    for (const b of document.querySelectorAll('#views button')) b.classList.toggle('on', b.dataset.view === mode);
    const msg = { type: 'view', mode };
    if (mode === 'source' || mode === 'weights') msg.camera = S.selected;
    send(msg);
    overlay.style.cursor = mode === 'source' ? 'grab' : 'crosshair';
    schedule();
  }
  for (const b of document.querySelectorAll('#views button')) on(b, 'click', () => setView(b.dataset.view));

  // ---- drawing the canvas -----------------------------------------------------------------------
  // At most one frame is asked of the worker per animation frame and one is on its way at a
  // time: a burst of pictures or pointer moves makes one frame of the newest state. The maps go
  // as copies, so the tools can keep changing the page's own while the worker draws.
  let frameRequested = false, frameInFlight = false, dirty = false;
  function schedule() {
    dirty = true;
    if (!frameRequested && !frameInFlight) { frameRequested = true; requestAnimationFrame(askFrame); }
  }
  const askFrame = timed('draw', () => {
    frameRequested = false;
    if (!S.W) return;
    dirty = false;
    frameInFlight = true;
    const colors = [];
    for (const c of S.state ? S.state.cameras : []) colors[c.index] = c.color;
    const labels = S.labels.slice();
    const regions = S.mode === 'regions' ? S.regions.slice() : null;
    const msg = { type: 'compose', mode: S.mode, selected: S.selected, pending: !!S.paintPending, paints: S.paints, colors, labels, regions };
    worker.postMessage(msg, regions ? [labels.buffer, regions.buffer] : [labels.buffer]);
  });

  // A frame from the worker: copied onto the canvas (one drawImage of a bitmap).
  function onFrame({ bmp, shown }) {
    frameInFlight = false;
    if (bmp) {
      ctx.drawImage(bmp, 0, 0);
      bmp.close();
      drawOverlay();
      // What the canvas now shows, for the browser test's hook (`afterDraw`).
      S.drawn = shown;
      showHint(shown);
      if (S.afterDraw) {
        const t = performance.now();
        S.afterDraw();
        hookMs += performance.now() - t;
      }
    }
    if (dirty) schedule();
  }

  // Over a canvas with nothing painted: what it shows and what to do (changed only when it
  // changes: no layout work per frame).
  function showHint(shown) {
    const empty = !!(shown && shown.empty && S.mode === 'final');
    const c = empty && shown.camera ? camera(shown.camera) : null;
    const text = !empty ? '' : `Nothing painted yet${c ? `: this is camera ${c.index} “${c.name}”` : ''}. `
      + 'Pick a camera on the left (or press 1–9), then paint with the Brush where it should be seen; '
      + 'the canvas then shows the collage as rendered.';
    const hint = $('hint');
    if (hint.textContent !== text) hint.textContent = text;
    if (hint.hidden !== !empty) hint.hidden = !empty;
  }

  function drawOverlay() {
    octx.clearRect(0, 0, S.W, S.H);
    const sel = S.selection;
    if (sel && S.mode !== 'source') {
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

  // ---- strokes and patches ----------------------------------------------------------------------
  function setLayer(layer, bytes) {
    if (bytes.length !== S.W * S.H) return;
    (layer === 'regions' ? S.regions : S.labels).set(bytes);
    schedule();
  }

  const paint = window.studioPaint(S, send, schedule);
  const { beginStroke, strokeTo, endStroke, copySelection, cut, paste, moveSelection, placePatch, clipRect } = paint;

  on($('cut'), 'click', cut);
  on($('copy'), 'click', copySelection);
  on($('paste'), 'click', paste);

  // ---- pointer input ----------------------------------------------------------------------------
  function pixelAt(e) {
    const r = overlay.getBoundingClientRect();
    return { x: ((e.clientX - r.left) * S.W) / r.width, y: ((e.clientY - r.top) * S.H) / r.height };
  }
  let drag = null;
  on(overlay, 'contextmenu', (e) => e.preventDefault());
  on(overlay, 'pointerdown', (e) => {
    if (!S.W || drag) return;
    overlay.setPointerCapture(e.pointerId);
    const p = pixelAt(e);
    if (S.mode === 'source') {
      const c = camera(S.selected);
      if (c) drag = { kind: e.shiftKey || e.button !== 0 ? 'pan' : 'orbit', last: e, camera: c, gesture: ++gesture };
    } else if (S.tool === 'select') {
      const s = S.selection;
      const inside = s && p.x >= s.x && p.y >= s.y && p.x < s.x + s.w && p.y < s.y + s.h;
      drag = { kind: inside ? 'move' : 'select', start: p };
    } else {
      const layer = S.tool === 'region' ? 'regions' : 'labels';
      const value = S.tool === 'brush' ? S.selected : S.tool === 'region' ? Math.min(254, Number($('region').value) | 0) : 0;
      beginStroke(layer, value);
      strokeTo(p);
      drag = { kind: 'paint' };
    }
  });
  on(overlay, 'pointermove', (e) => {
    if (!drag) return;
    // Coalesced events keep every pixel a fast stroke crossed.
    const events = e.getCoalescedEvents ? e.getCoalescedEvents() : [e];
    if (drag.kind === 'paint') for (const ev of events.length ? events : [e]) strokeTo(pixelAt(ev));
    else if (drag.kind === 'orbit' || drag.kind === 'pan') {
      moveCamera(drag.camera, drag.kind, e.clientX - drag.last.clientX, e.clientY - drag.last.clientY, drag.gesture);
      drag.last = e;
    } else {
      const p = pixelAt(e);
      const a = drag.start;
      if (drag.kind === 'select') {
        S.selection = clipRect({ x: Math.floor(Math.min(a.x, p.x)), y: Math.floor(Math.min(a.y, p.y)),
          w: Math.abs(Math.floor(p.x) - Math.floor(a.x)) + 1, h: Math.abs(Math.floor(p.y) - Math.floor(a.y)) + 1 });
      } else {
        drag.dx = Math.round(p.x - a.x);
        drag.dy = Math.round(p.y - a.y);
        const s = S.selection;
        octx.clearRect(0, 0, S.W, S.H);
        octx.strokeStyle = '#fff';
        octx.strokeRect(s.x + drag.dx + 0.5, s.y + drag.dy + 0.5, s.w - 1, s.h - 1);
        return;
      }
      schedule();
    }
  });
  function endDrag() {
    if (!drag) return;
    const d = drag;
    drag = null;
    if (d.kind === 'paint') endStroke();
    else if (d.kind === 'move' && (d.dx || d.dy)) moveSelection(d.dx, d.dy);
    else if (d.kind === 'orbit' || d.kind === 'pan') { clearTimeout(camTimer); camTimer = 0; sendCamera(d.camera, d.gesture); }
    schedule();
  }
  on(overlay, 'pointerup', endDrag);
  on(overlay, 'pointercancel', endDrag);
  on(overlay, 'wheel', (e) => {
    const c = camera(S.selected);
    if (S.mode !== 'source' || !c) return;
    e.preventDefault();
    if (e.timeStamp - wheelAt > 400) ++gesture;
    wheelAt = e.timeStamp;
    moveCamera(c, 'dolly', 0, e.deltaY, gesture);
  }, { passive: false });

  // ---- tools, buttons, keys -------------------------------------------------------------------
  function setTool(tool) {
    S.tool = tool;
    for (const b of document.querySelectorAll('#tools button')) b.classList.toggle('on', b.dataset.tool === tool);
  }
  for (const b of document.querySelectorAll('#tools button')) on(b, 'click', () => setTool(b.dataset.tool));
  on($('undo'), 'click', () => send({ type: 'undo' }));
  on($('redo'), 'click', () => send({ type: 'redo' }));
  on($('seamless'), 'change', () => send({ type: 'settings', seamless: $('seamless').checked }));
  on($('denoise'), 'change', () => send({ type: 'denoise', on: $('denoise').checked }));
  on($('frame'), 'change', () => {
    const f = parseInt($('frame').value, 10);
    if (Number.isFinite(f) && f >= 0) send({ type: 'frame', frame: f });
  });
  on($('save'), 'click', () => { note('saving…'); send({ type: 'save' }); });
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
    S.finalId = send(request);
  });
  on($('cancel-final'), 'click', () => send({ type: 'cancel_final' }));
  on(document, 'keydown', (e) => {
    if (e.target.tagName === 'INPUT') return;
    const k = e.key.toLowerCase();
    if (e.ctrlKey || e.metaKey) {
      if (k === 'z') send({ type: e.shiftKey ? 'redo' : 'undo' });
      else if (k === 'y') send({ type: 'redo' });
      else if (k === 'x') cut();
      else if (k === 'c') copySelection();
      else if (k === 'v') paste();
      else return;
    } else if (k === 'delete' || k === 'backspace') {
      if (S.selection) placePatch(S.selection, S.selection, null, 0, 0);
    } else if (k === 'escape') { S.selection = null; schedule(); }
    else if ({ b: 1, e: 1, r: 1, s: 1 }[k]) setTool({ b: 'brush', e: 'eraser', r: 'region', s: 'select' }[k]);
    else if (k >= '1' && k <= '9' && camera(Number(k))) selectCamera(Number(k));
    else return;
    e.preventDefault();
  });

  // ---- helpers ------------------------------------------------------------------------------------
  function note(text, error = false) {
    const m = $('message');
    m.textContent = text;
    m.classList.toggle('error', error);
  }
  setTool('brush');
  for (const b of document.querySelectorAll('#views button')) b.classList.toggle('on', b.dataset.view === 'final');
  connect();
})();
