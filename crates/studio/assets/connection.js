// The page's one WebSocket (docs/studio.md, "Protocol"): connecting and reconnecting, sending
// with fresh ids, and handing each kind of message to the modules that listen for it. Pictures
// arrive as a JSON header (`image`) and then the PNG's bytes; listeners of `image` get both.
import { $, note, pageToken } from './dom.js';
import { emit, timed } from './timing.js';

let ws = null;
let pendingImage = null; // the header of the picture whose bytes come next
let retries = 0;
// Replies go to every tab: ids start at random so one tab never takes another's as its own.
let nextId = 1 + Math.floor(Math.random() * 1e9);
// The newest state `seq` the server has told this page (in a state or a picture's header).
let seqNow = 0;
// Per message kind (and `lost`, the socket's closing): the listeners, in the order they came.
const listeners = new Map();

// Calls `fn(message)` for every message of kind `type`; `image` gives (header, bytes), `lost`
// no argument (the connection dropped: what waited for a reply will get none).
export function listen(type, fn) {
  if (!listeners.has(type)) listeners.set(type, []);
  listeners.get(type).push(fn);
}
function tell(type, ...args) {
  for (const fn of listeners.get(type) || []) fn(...args);
}

// The newest state `seq` the page knows.
export const seq = () => seqNow;

export function connect() {
  const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
  const socket = new WebSocket(`${scheme}//${location.host}/ws?token=${encodeURIComponent(pageToken())}`);
  ws = socket;
  emit('socket', socket);
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
    tell('lost');
    setTimeout(timed('reconnect', () => { emit('reconnect'); connect(); }), wait);
  });
  socket.onmessage = timed('socket message', (ev) => {
    if (typeof ev.data === 'string') onMessage(JSON.parse(ev.data));
    else onImageBytes(ev.data);
  });
}

function setConnection(text, error) {
  emit('connection', text);
  $('conn').textContent = text;
  $('conn').classList.toggle('error', error);
}

// Sends a message with a fresh id (returned); while disconnected it is lost, and the user is
// told.
export function send(msg) {
  msg.id = nextId++;
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(msg));
  else note(`not connected: ${msg.type} was not sent`, true);
  return msg.id;
}

// Each kind of message is timed on its own too (`socket state`, `socket labels`, …), so a slow
// `socket message` in the record says which kind it was.
const KINDS = ['state', 'labels', 'progress', 'saved', 'error', 'final', 'image', 'autosave'];
const byType = new Map();
function onMessage(m) {
  const type = KINDS.includes(m.type) ? m.type : 'other';
  if (!byType.has(type)) byType.set(type, timed(`socket ${type}`, dispatch));
  byType.get(type)(m);
}
function dispatch(m) {
  if (m.type === 'image') { pendingImage = m; return; }
  if (m.type === 'state' && Number.isFinite(m.seq) && m.seq > seqNow) seqNow = m.seq;
  if (KINDS.includes(m.type)) tell(m.type, m);
}

const onImageBytes = timed('socket picture bytes', (buf) => {
  const h = pendingImage;
  pendingImage = null;
  if (!h) return;
  seqNow = Math.max(seqNow, h.seq ?? 0);
  tell('image', h, buf);
});
