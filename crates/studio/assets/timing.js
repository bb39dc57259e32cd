// How the page registers its handlers (`on`, `timed`), and the browser test's probe behind them
// (docs/studio.md, "The page"). Opened with `probe` in its query string (`?token=…&probe`, as
// the browser test does) the page times each handler — per handler its calls, total and longest;
// a call over 16 ms also as a `performance.measure`, which shows in a DevTools trace — and tells
// `probe.js` what happens (`emit`). Without the flag `timed` returns the handler itself and
// `emit` does nothing: the product page carries no instrumentation.

// Whether the page was opened for the browser test.
export const probing = new URLSearchParams(location.search).has('probe');

// Per handler name: { calls, ms, max }; and the calls over 16 ms.
const handlers = {};
const slowHandlers = [];
// Time spent in the test's own hooks (its draw hook), left out of the handlers' times.
let hookMs = 0;
// What `emit` tells, per kind: the probe's listeners.
const watchers = new Map();

// `fn`, timed under `name` when probing.
export function timed(name, fn) {
  if (!probing) return fn;
  return function timedHandler(...args) {
    const t0 = performance.now();
    const hook0 = hookMs;
    try {
      return fn.apply(this, args);
    } finally {
      const ms = performance.now() - t0 - (hookMs - hook0);
      const h = handlers[name] || (handlers[name] = { calls: 0, ms: 0, max: 0 });
      h.calls += 1;
      h.ms += ms;
      h.max = Math.max(h.max, ms);
      if (ms > 16 && slowHandlers.length < 1000) {
        performance.measure(name, { start: t0, duration: ms });
        slowHandlers.push({ name, start: Math.round(t0), ms: Math.round(ms) });
      }
    }
  };
}

// `target.addEventListener(type, …)` with the handler timed under `name` (default: the type).
export const on = (target, type, fn, opts, name = type) => target.addEventListener(type, timed(name, fn), opts);

// Tells the probe (if any) that `kind` happened, with `detail`.
export function emit(kind, detail) {
  if (!probing) return;
  for (const fn of watchers.get(kind) || []) fn(detail);
}

// The probe's side: `fn(detail)` for every `emit(kind, …)`.
export function watch(kind, fn) {
  if (!watchers.has(kind)) watchers.set(kind, []);
  watchers.get(kind).push(fn);
}

// Runs the test's `hook`, its time left out of the handler that runs it.
export function untimed(hook) {
  const t = performance.now();
  try {
    hook();
  } finally {
    hookMs += performance.now() - t;
  }
}

// The handlers' times so far (empty unless probing).
export const handlerTimes = () => ({ handlers, slow: slowHandlers });
