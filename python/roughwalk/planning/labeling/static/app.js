// roughwalk labelling page: shows two footholds, sends the expert's judgement, draws the next pair.
"use strict";

const KEYS = {
  ArrowLeft: "left", a: "left", A: "left", 1: "left",
  ArrowRight: "right", d: "right", D: "right", 2: "right",
  ArrowDown: "equal", e: "equal", E: "equal", "=": "equal", 0: "equal",
  " ": "skip", s: "skip", S: "skip",
};
const RELIEF_EXAGGERATION = 2.0;
const SCALE_BAR = 0.02; // [m]

let state = null;
let busy = false;

function $(id) { return document.getElementById(id); }

function setStatus(text, isError) {
  const el = $("status");
  el.textContent = text;
  el.className = isError ? "error" : "";
}

async function call(method, path, body) {
  const options = { method, headers: {} };
  if (body !== undefined) {
    options.headers["Content-Type"] = "application/json";
    options.body = JSON.stringify(body);
  }
  const response = await fetch(path, options);
  let data = null;
  try { data = await response.json(); } catch (e) { data = { error: `bad answer (${response.status})` }; }
  return { ok: response.ok, status: response.status, data };
}

function setBusy(value) {
  busy = value;
  for (const b of document.querySelectorAll("button")) b.disabled = value;
  if (!value && state) $("undo").disabled = !state.can_undo;
}

async function refresh() {
  const r = await call("GET", "/api/state");
  if (!r.ok) { setStatus(r.data.error || "cannot reach the server", true); return; }
  show(r.data);
}

async function choose(choice) {
  if (busy || !state) return;
  setBusy(true);
  const side = choice === "left" || choice === "right" ? $(`side-${choice}`) : null;
  if (side) side.classList.add("chosen");
  try {
    const r = await call("POST", "/api/label", { token: state.pair.token, choice });
    if (r.ok) {
      setStatus(choice === "skip" ? "skipped (not recorded)" : `saved: ${choice === "equal" ? "equally good" : choice + " is better"}`);
      show(r.data);
    } else if (r.status === 409) {
      setStatus(r.data.error, true);
      show(r.data.state);
    } else {
      setStatus(r.data.error || `error ${r.status}`, true);
    }
  } catch (e) {
    setStatus(`not saved: cannot reach the server (${e})`, true);
  } finally {
    if (side) side.classList.remove("chosen");
    setBusy(false);
  }
}

async function undo() {
  if (busy || !state) return;
  setBusy(true);
  try {
    const r = await call("POST", "/api/undo", {});
    if (r.ok) { setStatus("undone: the last judgement was deleted; judge that pair again"); show(r.data); }
    else setStatus(r.data.error || `error ${r.status}`, true);
  } catch (e) {
    setStatus(`cannot reach the server (${e})`, true);
  } finally {
    setBusy(false);
  }
}

function pct(x) { return `${(100 * x).toFixed(0)}%`; }

function show(s) {
  state = s;
  $("count").textContent = s.count;
  $("session-count").textContent = s.session_count;
  $("leg").textContent = s.pair.leg;
  $("store").textContent = `store: ${s.store}`;
  const m = s.model || {};
  let text = "no model yet (it learns from the first strict judgement)";
  if (m.n_used > 0) {
    text = `the model ranks ${pct(m.train_agreement)} of ${m.n_used} strict judgements your way`;
    if (m.cv_agreement !== null && m.cv_agreement !== undefined) {
      text += `, ${pct(m.cv_agreement)} of held-out ones (${m.cv_folds}-fold)`;
    }
  }
  if (m.learning) text += " · learning…";
  $("agreement").textContent = text;
  $("undo").disabled = !s.can_undo || busy;
  const range = commonRange(s.pair.left, s.pair.right);
  for (const side of ["left", "right"]) {
    const patch = s.pair[side];
    drawRelief($(`relief-${side}`), patch, range, s.foot_radius);
    drawProfile($(`profile-${side}`), patch, s.foot_radius);
    $(`where-${side}`).textContent =
      `${patch.terrain} · x ${patch.x.toFixed(3)} m, y ${patch.y.toFixed(3)} m, z ${patch.z.toFixed(3)} m`;
  }
}

function commonRange(a, b) {
  let r = 0.01;
  for (const p of [a, b]) for (const row of p.heights) for (const h of row) r = Math.max(r, Math.abs(h));
  return r;
}

// Colour of a height relative to the foothold: blue below, pale at the foot's level, brown above.
function colour(t) {
  const low = [40, 90, 170], mid = [236, 236, 220], high = [150, 85, 30];
  const u = Math.max(-1, Math.min(1, t));
  const [c0, c1, f] = u < 0 ? [mid, low, -u] : [mid, high, u];
  return c0.map((c, i) => c + (c1[i] - c) * Math.sqrt(f));
}

// Bilinear sample of the patch at forward offset u and leftward offset v [m].
function sample(patch, u, v) {
  const n = patch.heights.length;
  const h = patch.half_size;
  const fi = Math.max(0, Math.min(n - 1, ((u + h) / (2 * h)) * (n - 1)));
  const fj = Math.max(0, Math.min(n - 1, ((v + h) / (2 * h)) * (n - 1)));
  const i0 = Math.min(Math.floor(fi), n - 2), j0 = Math.min(Math.floor(fj), n - 2);
  const di = fi - i0, dj = fj - j0;
  const H = patch.heights;
  return (H[i0][j0] * (1 - di) + H[i0 + 1][j0] * di) * (1 - dj) +
         (H[i0][j0 + 1] * (1 - di) + H[i0 + 1][j0 + 1] * di) * dj;
}

function drawRelief(canvas, patch, range, footRadius) {
  const ctx = canvas.getContext("2d");
  const W = canvas.width, Hc = canvas.height, half = patch.half_size;
  const img = ctx.createImageData(W, Hc);
  const metresPerPixel = (2 * half) / W;
  // Light from the upper left of the screen.
  const light = [-0.5, 0.5, 0.7071];
  for (let py = 0; py < Hc; py++) {
    const u = half - (py + 0.5) * metresPerPixel; // forward is up
    for (let px = 0; px < W; px++) {
      const v = half - (px + 0.5) * metresPerPixel; // left is left
      const z = sample(patch, u, v);
      const e = metresPerPixel;
      const dzdx = -(sample(patch, u, v - e) - sample(patch, u, v + e)) / (2 * e) * RELIEF_EXAGGERATION;
      const dzdy = (sample(patch, u + e, v) - sample(patch, u - e, v)) / (2 * e) * RELIEF_EXAGGERATION;
      const norm = Math.hypot(dzdx, dzdy, 1);
      const shade = Math.max(0, (-dzdx * light[0] - dzdy * light[1] + light[2]) / norm);
      const c = colour(z / range);
      const k = 0.35 + 0.65 * shade;
      const o = 4 * (py * W + px);
      img.data[o] = c[0] * k; img.data[o + 1] = c[1] * k; img.data[o + 2] = c[2] * k; img.data[o + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
  // Unknown ground: grey cells.
  const n = patch.known.length, cell = W / (n - 1);
  ctx.fillStyle = "rgba(120,120,120,0.85)";
  for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) {
    if (!patch.known[i][j]) ctx.fillRect(W - (j + 0.5) * cell, Hc - (i + 0.5) * cell, cell, cell);
  }
  // The foot, to scale, at the centre.
  const r = footRadius / metresPerPixel;
  ctx.beginPath(); ctx.arc(W / 2, Hc / 2, r, 0, 2 * Math.PI);
  ctx.fillStyle = "rgba(255,255,255,0.35)"; ctx.fill();
  ctx.lineWidth = 2; ctx.strokeStyle = "#000"; ctx.stroke();
  ctx.beginPath(); ctx.moveTo(W / 2 - 3, Hc / 2); ctx.lineTo(W / 2 + 3, Hc / 2);
  ctx.moveTo(W / 2, Hc / 2 - 3); ctx.lineTo(W / 2, Hc / 2 + 3); ctx.stroke();
  // Walking direction.
  ctx.fillStyle = "#000"; ctx.beginPath();
  ctx.moveTo(W / 2, 6); ctx.lineTo(W / 2 - 8, 20); ctx.lineTo(W / 2 + 8, 20); ctx.fill();
  // Scale bar.
  const bar = SCALE_BAR / metresPerPixel;
  ctx.fillStyle = "#fff"; ctx.fillRect(10, Hc - 20, bar + 4, 10);
  ctx.fillStyle = "#000"; ctx.fillRect(12, Hc - 18, bar, 6);
  ctx.font = "12px system-ui"; ctx.fillText("2 cm", 14 + bar + 4, Hc - 11);
}

function drawProfile(canvas, patch, footRadius) {
  const ctx = canvas.getContext("2d");
  const W = canvas.width, Hc = canvas.height, half = patch.half_size;
  const metresPerPixel = (2 * half) / W; // true scale: same in both directions
  const z0px = Hc * 0.55;
  ctx.clearRect(0, 0, W, Hc);
  ctx.strokeStyle = "#bbb"; ctx.lineWidth = 1; ctx.setLineDash([]);
  ctx.beginPath(); ctx.moveTo(0, z0px); ctx.lineTo(W, z0px); ctx.stroke();
  const line = (f, dash, colourName) => {
    ctx.strokeStyle = colourName; ctx.lineWidth = 2; ctx.setLineDash(dash);
    ctx.beginPath();
    for (let px = 0; px <= W; px++) {
      const s = -half + px * metresPerPixel;
      const y = z0px - f(s) / metresPerPixel;
      if (px === 0) ctx.moveTo(px, y); else ctx.lineTo(px, y);
    }
    ctx.stroke();
  };
  // Along the walking direction (forward to the right), then across it (left to the left).
  line((s) => sample(patch, s, 0), [], "#5a3a1a");
  line((s) => sample(patch, 0, -s), [5, 4], "#3060a0");
  ctx.setLineDash([]);
  const r = footRadius / metresPerPixel;
  ctx.beginPath(); ctx.arc(W / 2, z0px - r, r, 0, 2 * Math.PI);
  ctx.strokeStyle = "#000"; ctx.lineWidth = 1.5; ctx.stroke();
}

document.addEventListener("keydown", (event) => {
  if (event.repeat || event.altKey) return;
  if ((event.ctrlKey || event.metaKey) && (event.key === "z" || event.key === "Z")) {
    event.preventDefault(); undo(); return;
  }
  if (event.ctrlKey || event.metaKey) return;
  if (event.key === "u" || event.key === "U" || event.key === "Backspace") {
    event.preventDefault(); undo(); return;
  }
  const choice = KEYS[event.key];
  if (choice) { event.preventDefault(); choose(choice); }
});
for (const b of document.querySelectorAll("button[data-choice]")) {
  b.addEventListener("click", () => choose(b.dataset.choice));
}
$("undo").addEventListener("click", undo);
refresh();
