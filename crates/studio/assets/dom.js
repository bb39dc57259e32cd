// The page's small shared helpers (docs/studio.md, "The page"): element lookup, the URL of an
// asset (every request carries the page's token) and the status line's message.
export const $ = (id) => document.getElementById(id);

const token = new URLSearchParams(location.search).get('token') || '';

// The page's token, for the socket's URL.
export const pageToken = () => token;

// The URL of asset `name`, with the token the server asks of every request.
export const assetUrl = (name) => `assets/${name}?token=${encodeURIComponent(token)}`;

// Shows `text` in the status line (red when `error`).
export function note(text, error = false) {
  const m = $('message');
  m.textContent = text;
  m.classList.toggle('error', error);
}
