// The player: shows the current frame (an image swapped in only once fully loaded), plays at
// the spec's fps, scrubs, and follows the server's state through Server-Sent Events.
"use strict";
const $ = (id) => document.getElementById(id);
const img = $("frame"), scrub = $("scrub"), cells = $("cells");
let state = null, current = 0, playing = false, timer = null, shownKey = "", loadingKey = "";

function frameCount() { return state ? state.frames.length : 0; }

function show(i) {
  const n = frameCount();
  if (n === 0) return;
  current = ((i % n) + n) % n;
  scrub.value = String(current);
  const fps = state.fps || 24;
  $("position").textContent = `frame ${current} / ${n - 1} · ${(current / fps).toFixed(2)} s`;
  const f = state.frames[current];
  if (f.state === "none") return;
  const key = `${current}:${f.v}`;
  if (key === shownKey || key === loadingKey) return;
  loadingKey = key;
  // Decoded off screen first, so the page never shows a half-loaded image.
  const next = new Image();
  next.onload = () => {
    if (loadingKey !== key) return;
    img.src = next.src;
    img.dataset.frame = String(current);
    img.dataset.version = String(f.v);
    img.dataset.quality = f.state;
    shownKey = key;
    loadingKey = "";
  };
  next.onerror = () => { if (loadingKey === key) loadingKey = ""; };
  next.src = `/frame/${current}.png?v=${f.v}`;
}

let focusTimer = null;
function focus(i) {
  clearTimeout(focusTimer);
  focusTimer = setTimeout(() => fetch(`/api/focus?frame=${i}`, { method: "POST" }), 80);
}

function setPlaying(on) {
  playing = on;
  $("play").textContent = on ? "❚❚" : "▶︎";
  clearInterval(timer);
  const fps = (state && state.fps) || 24;
  // While playing, the server renders ahead of the playhead: it hears where it is each second.
  const tick = () => { show(current + 1); if (current % Math.max(1, Math.round(fps)) === 0) focus(current); };
  if (on) timer = setInterval(tick, 1000 / fps);
  else focus(current);
}

function drawTimeline() {
  const n = frameCount();
  scrub.max = String(Math.max(0, n - 1));
  while (cells.children.length > n) cells.lastChild.remove();
  while (cells.children.length < n) cells.appendChild(document.createElement("div"));
  let small = 0, full = 0;
  state.frames.forEach((f, i) => {
    const cell = cells.children[i];
    if (cell.className !== f.state) cell.className = f.state;
    cell.title = `frame ${i}: ${f.state}${f.error ? "\n" + f.error : ""}`;
    if (f.state === "small" || f.state === "full") small++;
    if (f.state === "full") full++;
  });
  $("bar-small").style.width = `${n ? (100 * small) / n : 0}%`;
  $("bar-full").style.width = `${n ? (100 * full) / n : 0}%`;
  $("status").textContent = n ? `${small} of ${n} frames drawn, ${full} at full quality` : "building…";
  document.body.dataset.small = String(small);
  document.body.dataset.full = String(full);
  const duration = n / (state.fps || 24);
  const keys = $("keys");
  keys.replaceChildren(...state.keys.map((t) => {
    const mark = document.createElement("span");
    mark.style.left = `${Math.min(100, (100 * t) / Math.max(duration, 1e-9))}%`;
    mark.title = `key at ${t} s`;
    return mark;
  }));
}

function update(next) {
  state = next;
  drawTimeline();
  // A build that failed, else the frames that did not render (each error once).
  const frameErrors = [...new Set(state.frames.map((f) => f.error).filter((e) => e))];
  const shownErrors = state.diagnostics.length ? state.diagnostics : frameErrors;
  $("diagnostics").hidden = shownErrors.length === 0;
  $("diag-text").textContent = shownErrors.join("\n\n");
  $("diag-title").textContent = state.diagnostics.length
    ? "The last edit does not build; the frames shown are from the last good one"
    : "Some frames do not render";
  $("warnings").hidden = state.warnings.length === 0;
  $("warn-text").textContent = state.warnings.join("\n\n");
  document.body.dataset.version = String(state.version);
  exportProgress();
  show(current);
}

function connect() {
  const events = new EventSource("/events");
  events.onmessage = (e) => update(JSON.parse(e.data));
  // After the first state, only what changed: the frames by index, the notes when they did.
  events.addEventListener("delta", (e) => {
    const d = JSON.parse(e.data);
    if (!state || state.frames.length !== d.n) return;
    const frames = state.frames.slice();
    for (const [i, f] of Object.entries(d.changed)) frames[Number(i)] = f;
    delete d.changed;
    delete d.n;
    update(Object.assign({}, state, d, { frames }));
  });
  events.onerror = () => { $("status").textContent = "connection lost; retrying…"; };
}

scrub.addEventListener("input", () => { setPlaying(false); show(Number(scrub.value)); focus(current); });
$("play").addEventListener("click", () => setPlaying(!playing));
$("prev").addEventListener("click", () => step(-1));
$("next").addEventListener("click", () => step(1));
// The page's keys, caught before any control sees them (capture on window) and kept from
// it: a focused timeline would step a second time on an arrow, a focused button would click
// on a space.
const KEYS = { " ": () => setPlaying(!playing), ArrowLeft: () => step(-1), ArrowRight: () => step(1) };
window.addEventListener("keydown", (e) => {
  const act = KEYS[e.key];
  if (!act || e.altKey || e.ctrlKey || e.metaKey) return;
  e.preventDefault();
  e.stopPropagation();
  if (!e.repeat || e.key !== " ") act();
}, true);
window.addEventListener("keyup", (e) => { if (e.key === " ") e.preventDefault(); }, true);
function step(by) { setPlaying(false); show(current + by); focus(current); }

// Export: the server waits for every frame at full quality before it encodes; meanwhile
// the page counts them down from the state it streams.
let exporting = false;
function exportProgress() {
  if (!exporting || !state) return;
  const n = frameCount(), full = state.frames.filter((f) => f.state === "full").length;
  $("export-status").textContent = full < n
    ? `export: waiting for full quality, ${full} of ${n} frames drawn…`
    : `export: encoding ${n} frames at full quality…`;
}
$("export").addEventListener("click", async () => {
  const out = $("export-status");
  out.dataset.done = "";
  exporting = true;
  exportProgress();
  let answer;
  try {
    answer = await (await fetch("/api/export", { method: "POST" })).json();
  } catch (e) {
    answer = { ok: false, error: `export failed: ${e}` };
  }
  exporting = false;
  if (answer.ok) {
    out.textContent = `exported ${answer.note}: `;
    const link = document.createElement("a");
    link.href = answer.url;
    link.textContent = "download preview.mp4";
    out.appendChild(link);
  } else {
    out.textContent = answer.error;
  }
  out.dataset.done = "1";
});
connect();
