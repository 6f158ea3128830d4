// biped panel: sliders and number boxes for every gait parameter, presets, start/stop/estop,
// a live stick figure (side and front views, points computed by the server) and telemetry.
"use strict";

const TOKEN = new URLSearchParams(location.search).get("token");
const $ = (id) => document.getElementById(id);
const inputs = {};      // name -> {range, number, row, spec}
let busy = false;       // one parameter request in flight at a time
let queued = null;      // latest changes waiting for it

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

function buildParams(desc) {
  const box = $("params");
  box.textContent = "";
  for (const group of desc.groups) {
    const fs = document.createElement("fieldset");
    const lg = document.createElement("legend");
    lg.textContent = group.name;
    fs.appendChild(lg);
    for (const s of group.params) {
      const row = document.createElement("div");
      row.className = "param";
      row.title = s.doc + " [" + s.lo + ", " + s.hi + "] " + s.unit;
      const label = document.createElement("label");
      label.textContent = s.name;
      label.htmlFor = "num-" + s.name;
      const range = document.createElement("input");
      Object.assign(range, { type: "range", min: s.lo, max: s.hi, step: (s.hi - s.lo) / 1000,
                             value: s.value, id: "range-" + s.name });
      range.dataset.param = s.name;
      const number = document.createElement("input");
      Object.assign(number, { type: "number", min: s.lo, max: s.hi, step: "any",
                              value: s.value, id: "num-" + s.name });
      number.dataset.param = s.name;
      const unit = document.createElement("span");
      unit.className = "unit";
      unit.textContent = s.unit;
      range.addEventListener("input", () => {
        number.value = +(+range.value).toPrecision(6);
        sendParams({ [s.name]: +range.value });
      });
      number.addEventListener("change", () => {
        const v = number.value.trim() === "" ? number.value : Number(number.value);
        sendParams({ [s.name]: Number.isNaN(v) ? number.value : v });
      });
      row.append(label, range, number, unit);
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
  g.fillStyle = "#8b95a7"; g.font = "11px sans-serif";
  g.fillText(horizontal, W - 90, oy + 16);
  const draw = (fig, dashed, alpha) => {
    if (!fig) return;
    g.globalAlpha = alpha;
    g.setLineDash(dashed ? [3, 4] : []);
    for (const [name, pts] of Object.entries(fig)) {
      g.strokeStyle = COLORS[name] || "#fff";
      g.lineWidth = name === "torso" ? 4 : 3;
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

function showState(s) {
  const st = $("state");
  st.textContent = s.state + (s.running ? "" : " (not running)");
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
  if (s.stop_reason) html += row("stop reason", s.stop_reason);
  $("loop").innerHTML = html;
  $("servos").tBodies[0].innerHTML = s.servos.map((v) => "<tr><td>" + v.id + "</td><td>" +
    v.joint + "</td><td>" + fmt(v.temperature, 1) + "</td><td>" + fmt(v.load, 1) + "</td><td>" +
    v.errors.join(" ") + "</td></tr>").join("");
}

async function poll() {
  try { showState(await api("GET", "/api/state")); } catch (e) { say(e.message, true); }
  setTimeout(poll, 100);
}

function action(id, path, body, after) {
  $(id).addEventListener("click", async () => {
    try {
      const r = await api("POST", path, body ? body() : undefined);
      say(id + ": " + (r.state || r.saved || r.preset || "ok"));
      if (after) await after(r);
    } catch (e) { say(e.message, true); }
  });
}

async function main() {
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
  poll();
}

main().catch((e) => say(e.message, true));
