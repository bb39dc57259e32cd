// The cameras (docs/studio.md, "The page"): the list with its thumbnails, the selected camera,
// its form, and the mouse's orbit, pan and dolly in the source view. Edits go to the server as
// `camera_edit`; its `state` brings them back (until then, or if it refuses, the camera is as it
// held it).
import { $ } from './dom.js';
import { send } from './connection.js';
import { on, timed } from './timing.js';

let cameras = []; // the server's, as its newest state lists them
let selected = 1;
let formHeld = false; // a drag is on: the form is not refilled from the server's state
const editIds = new Set(); // camera edits whose replies have not come
const selectedListeners = [];

export const selectedCamera = () => selected;
export function camera(index) { return cameras.find((c) => c.index === index); }
// Colours by camera index (for the labels view).
export function colors() {
  const out = [];
  for (const c of cameras) out[c.index] = c.color;
  return out;
}
// How many camera edits wait for the server's reply.
export const pendingEdits = () => editIds.size;

// Calls `fn()` after the user selects another camera.
export function whenSelected(fn) { selectedListeners.push(fn); }

// The cameras of the server's state `st` (a reply to this page's edit settles it).
export function apply(st) {
  cameras = st.cameras;
  if (!cameras.some((c) => c.index === selected) && cameras.length) selected = cameras[0].index;
  renderCameraList();
  fillCameraForm();
}

// The server's state replying to message `id`.
export function settle(id) { editIds.delete(id); }

// Message `id` was refused: true if it was a camera edit (ask for the server's cameras again).
export function refused(id) { return editIds.delete(id); }

function renderCameraList() {
  const list = $('camera-list');
  const keep = new Map([...list.children].map((li) => [Number(li.dataset.index), li]));
  const items = cameras.map((c) => {
    let li = keep.get(c.index);
    if (!li) {
      li = document.createElement('li');
      li.dataset.index = c.index;
      li.innerHTML = '<span class="swatch"></span><span class="name"></span>'
        + '<button class="dup" title="Duplicate this camera">duplicate</button><canvas width="96" height="54"></canvas>';
      on(li, 'click', (e) => {
        if (e.target.classList.contains('dup')) send({ type: 'camera_duplicate', index: c.index });
        else select(c.index);
      });
    }
    li.querySelector('.swatch').style.background = c.color;
    li.querySelector('.name').textContent = `${c.index} ${c.name}`;
    li.classList.toggle('on', c.index === selected);
    return li;
  });
  list.replaceChildren(...items);
}

// Camera `index`'s thumbnail in the list.
export function drawThumb(index, bmp) {
  const c = document.querySelector(`#camera-list li[data-index="${index}"] canvas`);
  if (!c) return;
  c.width = bmp.width;
  c.height = bmp.height;
  c.getContext('2d').drawImage(bmp, 0, 0);
}

export function select(index) {
  selected = index;
  renderCameraList();
  fillCameraForm();
  for (const fn of selectedListeners) fn();
}

// ---- the form ---------------------------------------------------------------------------------
const form = $('camera-form');
const round = (v) => Math.round(v * 1e4) / 1e4;
function fillCameraForm() {
  const c = camera(selected);
  if (!c || formHeld) return;
  for (let i = 0; i < 3; i++) {
    form[`eye${i}`].value = round(c.eye[i]);
    form[`target${i}`].value = round(c.target[i]);
  }
  form.fov.value = round(c.fov_deg);
}
function fillCameraFormFrom(c) {
  for (let i = 0; i < 3; i++) { form[`eye${i}`].value = round(c.eye[i]); form[`target${i}`].value = round(c.target[i]); }
}
// While a drag is on (`held`), the server's state does not refill the form.
export function holdForm(held) { formHeld = held; }

on(form, 'change', () => {
  const c = camera(selected);
  if (!c) return;
  const num = (n, old) => (Number.isFinite(parseFloat(form[n].value)) ? parseFloat(form[n].value) : old);
  sendCamera({ ...c, eye: c.eye.map((v, i) => num(`eye${i}`, v)), target: c.target.map((v, i) => num(`target${i}`, v)), fov_deg: num('fov', c.fov_deg) });
});
on(form, 'submit', (e) => e.preventDefault());

// ---- orbit, pan, dolly ------------------------------------------------------------------------
// Every edit of one drag (or one burst of wheel turns) carries the same gesture number: the
// server makes them one undo step.
let gesture = 0, wheelAt = -Infinity;
function sendCamera(c, g) {
  editIds.add(send({ type: 'camera_edit', index: c.index, eye: c.eye, target: c.target, up: c.up, fov_deg: c.fov_deg, gesture: g }));
}

const sub = (a, b) => a.map((v, i) => v - b[i]);
const add = (a, b) => a.map((v, i) => v + b[i]);
const mul = (a, s) => a.map((v) => v * s);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => mul(a, 1 / Math.hypot(...a));
// Rodrigues' rotation of v about the unit axis k by angle t.
const rotate = (v, k, t) => add(add(mul(v, Math.cos(t)), mul(cross(k, v), Math.sin(t))), mul(k, dot(k, v) * (1 - Math.cos(t))));

// A drag of the selected camera (`pan` or `orbit`), one undo step: null without a camera.
export function startDrag(kind) {
  const c = camera(selected);
  return c ? { kind, camera: c, gesture: ++gesture } : null;
}

let camTimer = 0;
// Moves `drag`'s camera by a pointer step of (dx, dy) pixels of a view `viewHeight` pixels high.
export function dragBy(drag, dx, dy, viewHeight) {
  moveCamera(drag.camera, drag.kind, dx, dy, drag.gesture, viewHeight);
}
// The drag's end: its last edit is sent now.
export function endDrag(drag) {
  clearTimeout(camTimer);
  camTimer = 0;
  sendCamera(drag.camera, drag.gesture);
}
// A wheel turn over the source view dollies the selected camera (turns within 400 ms are one
// undo step). False without a camera.
export function wheel(e, viewHeight) {
  const c = camera(selected);
  if (!c) return false;
  if (e.timeStamp - wheelAt > 400) ++gesture;
  wheelAt = e.timeStamp;
  moveCamera(c, 'dolly', 0, e.deltaY, gesture, viewHeight);
  return true;
}

function moveCamera(c, kind, dx, dy, g, viewHeight) {
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
    const perPixel = (2 * dist * Math.tan((c.fov_deg * Math.PI) / 360)) / viewHeight;
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
