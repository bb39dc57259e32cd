// When the canvas is drawn (docs/studio.md, "The page"): at most one frame is asked of the
// picture worker per animation frame and one is on its way at a time, so a burst of pictures or
// pointer moves makes one frame of the newest state. Whatever changes what the canvas shows
// calls `schedule`; `pictures.js` draws.
import { timed } from './timing.js';

let frameRequested = false, frameInFlight = false, dirty = false;
let drawer = null; // { ready, draw }: whether there is a canvas yet, and the asking of a frame

// The canvas shows something out of date: a frame is asked for at the next animation frame.
export function schedule() {
  dirty = true;
  if (!frameRequested && !frameInFlight) { frameRequested = true; requestAnimationFrame(askFrame); }
}

// `draw()` asks the worker for a frame (answered by `frameDone`) once `ready()`.
export function drawWith(ready, draw) {
  drawer = { ready, draw };
}

const askFrame = timed('draw', () => {
  frameRequested = false;
  if (!drawer || !drawer.ready()) return;
  dirty = false;
  frameInFlight = true;
  drawer.draw();
});

// The frame asked for has arrived: the next one may be asked (now, if the state moved on).
export function frameDone() {
  frameInFlight = false;
  if (dirty) schedule();
}
