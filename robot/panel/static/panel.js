// biped panel: a slider and number box for every gait parameter (labels in words, the
// paper's symbol beside them), presets, start/stop/estop, a live stick figure and telemetry
// pushed over a WebSocket (/api/live; polling /api/state only if the socket cannot open).
// input.js adds the gamepad and keyboard, studio.js recording, replay and keyframes.
"use strict";

const TOKEN = new URLSearchParams(location.search).get("token");
const $ = (id) => document.getElementById(id);
const inputs = {};      // name -> {range, number, row, spec}
let busy = false;       // one parameter request in flight at a time
let queued = null;      // latest changes waiting for it
let last = null;        // the last state pushed
const listeners = [];   // called with every state

async function api(method, path, body) {
  const headers = { "Content-Type": "application/json" };
  if (TOKEN) headers.Authorization = "Bearer " + TOKEN;
  const r = await fetch(path, { method, headers, body: body ? JSON.stringify(body) : undefined });
  const data = await r.json().catch(() => ({ error: "bad response " + r.status }));
  if (!r.ok) throw new Error(data.error || ("HTTP " + r.status));
  return data;
}

function say(text, error) {
  const m = $("message");
  m.textContent = text;
  m.className = error ? "error" : "";
}

function fmt(v, d = 3) { return v === null || v === undefined ? "–" : Number(v).toFixed(d); }

function showParams(params, force) {
  // Inputs being edited keep their text unless forced (after a refused value).
  for (const [name, v] of Object.entries(params)) {
    const w = inputs[name];
    if (!w) continue;
    if (force || document.activeElement !== w.number) w.number.value = +v.toPrecision(6);
    if (force || document.activeElement !== w.range) w.range.value = v;
    if (!force) w.row.classList.remove("bad");
  }
}

async function sendParams(changes) {
  if (busy) { queued = Object.assign(queued || {}, changes); return; }
  busy = true;
  try {
    const r = await api("POST", "/api/params", changes);
    showParams(r.params);
    say("applied " + Object.keys(changes).join(", "));
  } catch (e) {
    for (const n of Object.keys(changes)) if (inputs[n]) inputs[n].row.classList.add("bad");
    say(e.message, true);
    const cur = await api("GET", "/api/params");
    showParams(cur.params, true);
  } finally {
    busy = false;
    if (queued) { const q = queued; queued = null; sendParams(q); }
  }
}

function el(tag, props, ...children) {
  const e = Object.assign(document.createElement(tag), props || {});
  e.append(...children);
  return e;
}

function buildParams(desc) {
  const box = $("params");
  box.textContent = "";
  for (const group of desc.groups) {
    const title = group.name.charAt(0).toUpperCase() + group.name.slice(1);
    const fs = el("fieldset", {}, el("legend", { textContent: title }));
    fs.dataset.group = group.name;
    for (const s of group.params) {
      const row = el("div", { className: "param" + (s.simple ? " simple" : "") });
      if (s.simple) fs.classList.add("has-simple");
      const label = el("label", { htmlFor: "num-" + s.name }, s.label + " ",
                       el("code", { textContent: s.name }));
      const range = el("input", { type: "range", min: s.lo, max: s.hi, step: (s.hi - s.lo) / 1000,
                                  value: s.value, id: "range-" + s.name });
      range.setAttribute("aria-label", s.label);
      const number = el("input", { type: "number", min: s.lo, max: s.hi, step: "any",
                                   value: s.value, id: "num-" + s.name });
      const unit = s.unit && s.unit !== "-" ? " " + s.unit : "";
      const doc = el("div", { className: "doc",
                              textContent: s.doc + " [" + s.lo + ", " + s.hi + "]" + unit });
      range.addEventListener("input", () => {
        number.value = +(+range.value).toPrecision(6);
        sendParams({ [s.name]: +range.value });
      });
      number.addEventListener("change", () => {
        const v = number.value.trim() === "" ? number.value : Number(number.value);
        sendParams({ [s.name]: Number.isNaN(v) ? number.value : v });
      });
      row.append(label, number, range, doc);
      fs.appendChild(row);
      inputs[s.name] = { range, number, row, spec: s };
    }
    box.appendChild(fs);
  }
}

async function loadPresets(select) {
  const r = await api("GET", "/api/presets");
  const sel = $("preset");
  sel.textContent = "";
  for (const n of r.presets) sel.add(new Option(n, n, false, n === select));
}

const COLORS = { r_leg: "#ff7a59", r_arm: "#ff7a59", l_leg: "#4fd1a5", l_arm: "#4fd1a5",
                 torso: "#c9d1dd", head: "#c9d1dd" };

function drawView(canvas, cmd, present, horizontal) {
  const g = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height;
  g.clearRect(0, 0, W, H);
  const scale = H * 0.85 / 0.55;            // pixels per metre (fits a ~0.5 m robot)
  const ox = W / 2, oy = H - 24;            // ground line and centre
  g.strokeStyle = "#3b4658"; g.lineWidth = 1;
  g.beginPath(); g.moveTo(0, oy); g.lineTo(W, oy); g.stroke();
  g.fillStyle = "#8b95a7"; g.font = "16px sans-serif";
  g.fillText(horizontal, W - 150, oy + 18);
  const draw = (fig, dashed, alpha) => {
    if (!fig) return;
    g.globalAlpha = alpha;
    g.setLineDash(dashed ? [3, 4] : []);
    for (const [name, pts] of Object.entries(fig)) {
      g.strokeStyle = COLORS[name] || "#fff";
      g.lineWidth = name === "torso" ? 5 : 4;
      g.beginPath();
      pts.forEach(([x, z], i) => {
        const px = ox + x * scale, py = oy - z * scale;
        if (i) g.lineTo(px, py); else g.moveTo(px, py);
      });
      g.stroke();
    }
    g.globalAlpha = 1; g.setLineDash([]);
  };
  draw(present, !!cmd, cmd ? 0.6 : 1);   // idle: the read-back pose alone, drawn solid
  draw(cmd, false, 1);
}

function row(k, v) { return "<tr><td>" + k + "</td><td>" + v + "</td></tr>"; }
function esc(t) { const d = document.createElement("div"); d.textContent = t; return d.innerHTML; }

function showState(s) {
  last = s;
  const st = $("state");
  st.textContent = (s.doing || s.state) + (s.running ? "" : " (not running)");
  st.className = "state " + s.state;
  const f = s.figure || {};
  drawView($("side"), f.cmd && f.cmd.side, f.present && f.present.side, "x forward →");
  drawView($("front"), f.cmd && f.cmd.front, f.present && f.present.front, "← right  left →");
  let html = row("loop rate", fmt(s.loop_hz, 1) + " / " + s.rate_hz + " Hz") +
    row("period error", fmt(s.period_error_ms, 3) + " ms") + row("overruns", s.overruns) +
    row("amplitude", fmt(s.amplitude, 2)) + row("time", fmt(s.t, 2) + " s");
  if (s.sim) {
    html += row("fell", s.sim.fell ? "<b style='color:#ff4d4d'>YES</b>" : "no") +
      row("torso height", fmt(s.sim.torso_height_m, 3) + " m") +
      row("tilt", fmt(s.sim.tilt_deg, 1) + "°") + row("distance", fmt(s.sim.distance_m, 3) + " m");
  }
  if (s.stop_reason) html += row("stop reason", esc(s.stop_reason));
  if (s.fault) html += row("fault", "<b style='color:#ff4d4d'>" + esc(s.fault) + "</b>");
  $("loop").innerHTML = html;
  $("servos").tBodies[0].innerHTML = s.servos.map((v) => "<tr><td>" + v.id + "</td><td>" +
    v.joint + (v.model_joint && v.model_joint !== v.joint ?
      " <small title='its name in the model file'>" + esc(v.model_joint) + "</small>" : "") +
    "</td><td>" + fmt(v.temperature, 1) + "</td><td>" + fmt(v.load, 1) + "</td><td>" +
    v.errors.join(" ") + "</td></tr>").join("");
  if (s.params && !busy && !queued) showParams(s.params);
  for (const f2 of listeners) f2(s);
}

async function poll() {
  try { showState(await api("GET", "/api/state")); } catch (e) { say(e.message, true); }
  setTimeout(poll, 500);
}

function live(failures = 0) {
  // The server pushes the state; reconnect after a drop, fall back to polling if it
  // cannot open at all (e.g. a proxy without WebSockets).
  const scheme = location.protocol === "https:" ? "wss://" : "ws://";
  const ws = new WebSocket(scheme + location.host + "/api/live" +
                           (TOKEN ? "?token=" + encodeURIComponent(TOKEN) : ""));
  let opened = false;
  ws.onopen = () => { opened = true; failures = 0; };
  ws.onmessage = (ev) => showState(JSON.parse(ev.data));
  ws.onclose = () => {
    if (!opened && failures >= 2) { say("live updates unavailable: polling", true); poll(); return; }
    setTimeout(() => live(opened ? 0 : failures + 1), 1000);
  };
}

function action(id, path, body, after) {
  $(id).addEventListener("click", () => run(id, path, body ? body() : undefined, after));
}

// What an action did, in words: the state it answers is the state at that instant (a
// stopping walk still reads "walking" while it ramps out).
const DONE = { "/api/start": "started", "/api/stop": "stop requested: ramping out to rest",
               "/api/estop": "emergency stop: torque off", "/api/reset": "simulation reset" };

async function run(id, path, body, after) {
  try {
    const r = await api("POST", path, body);
    const what = DONE[path] || r.saved || r.preset || (r.take && "playing take " + r.take) ||
      (r.sequence && "playing sequence " + r.sequence) || "ok";
    say((id === path.split("/").pop() ? "" : id + ": ") + what);   // "keyboard: ...": who
    if (after) await after(r);
    return r;
  } catch (e) { say(e.message, true); return null; }
}

function setView(view) {
  document.body.classList.toggle("simple", view === "simple");
  $("view-simple").classList.toggle("on", view === "simple");
  $("view-full").classList.toggle("on", view !== "simple");
  try { localStorage.setItem("biped-view", view); } catch (e) { /* private mode */ }
}

async function main() {
  let view = null;
  try { view = localStorage.getItem("biped-view"); } catch (e) { /* private mode */ }
  setView(view || (window.innerWidth < 720 ? "simple" : "full"));
  $("view-simple").addEventListener("click", () => setView("simple"));
  $("view-full").addEventListener("click", () => setView("full"));
  const desc = await api("GET", "/api/params");
  buildParams(desc);
  await loadPresets(desc.preset);
  action("start", "/api/start");
  action("stop", "/api/stop");
  action("estop", "/api/estop");
  action("reset", "/api/reset");
  action("load", "/api/preset", () => ({ name: $("preset").value }), (r) => showParams(r.params));
  action("save", "/api/save", () => ({ name: $("save-name").value, overwrite: $("overwrite").checked }),
         () => loadPresets($("save-name").value));
  live();
  document.dispatchEvent(new Event("panel-ready"));
}

window.panel = { api, say, run, sendParams, inputs, listeners, state: () => last };
main().catch((e) => say(e.message, true));
