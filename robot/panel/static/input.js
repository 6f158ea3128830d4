// Gamepad (the browser's Gamepad API, standard mapping) and keyboard for the panel.
// Left stick: speed (up = forward) and side step; right stick: turn; A (button 0):
// start / stop; B (button 1): emergency stop. A gamepad that disconnects stops the walk.
// Keys: arrows / WASD change speed and turn, Space stops, Esc is the emergency stop.
"use strict";

(() => {
  const P = window.panel;
  const DEAD = 0.15;          // stick dead zone
  const PERIOD_MS = 50;       // gamepad polling (and at most this often a parameter send)
  const STEP = { speed: 0.1, turn: 0.05 };
  let pad = null;             // index of the connected gamepad
  let sent = {};              // last values sent from the sticks
  let pressed = {};           // button -> was down at the last poll

  const spec = (n) => P.inputs[n] && P.inputs[n].spec;
  const clamp = (n, v) => Math.min(spec(n).hi, Math.max(spec(n).lo, v));
  const stick = (v) => (Math.abs(v) < DEAD ? 0 : (v - Math.sign(v) * DEAD) / (1 - DEAD));
  const running = () => { const s = P.state(); return !!(s && s.running); };
  const current = (n) => { const s = P.state(); return s && s.params ? s.params[n] : spec(n).default; };

  function show(text) { document.getElementById("pad").textContent = text; }

  function fromSticks(gp) {
    // Up on a stick is -1. Speed spans [0, hi] forward and [lo, 0] back; + turn is left.
    const fwd = -stick(gp.axes[1] || 0), side = -stick(gp.axes[0] || 0);
    const turn = -stick(gp.axes[2] || 0);
    const scale = (n, v) => clamp(n, v >= 0 ? v * spec(n).hi : -v * spec(n).lo);
    return { speed: +scale("speed", fwd).toFixed(3), side_step: +scale("side_step", side).toFixed(4),
             turn: +scale("turn", turn).toFixed(3) };
  }

  function pollPad() {
    if (pad === null || !spec("speed")) return;
    const gp = (navigator.getGamepads ? navigator.getGamepads() : [])[pad];
    if (!gp || !gp.connected) return;
    const want = fromSticks(gp);
    const changes = {};
    for (const [k, v] of Object.entries(want)) if (sent[k] !== v) changes[k] = v;
    if (Object.keys(changes).length) { sent = want; P.sendParams(changes); }
    const down = (i) => !!(gp.buttons[i] && gp.buttons[i].pressed);
    if (down(1) && !pressed[1]) P.run("gamepad", "/api/estop");
    else if (down(0) && !pressed[0]) P.run("gamepad", running() ? "/api/stop" : "/api/start");
    pressed = { 0: down(0), 1: down(1) };
  }

  window.addEventListener("gamepadconnected", (e) => {
    pad = e.gamepad.index;
    sent = {};
    pressed = { 0: true, 1: true };  // the press that woke it is not a command
    show("Gamepad connected: " + e.gamepad.id);
    P.say("gamepad connected");
  });
  window.addEventListener("gamepaddisconnected", (e) => {
    if (pad === null || e.gamepad.index !== pad) return;
    pad = null;
    show("Gamepad disconnected: the walk was stopped.");
    if (running()) P.run("gamepad disconnected", "/api/stop");
  });
  setInterval(pollPad, PERIOD_MS);

  function nudge(name, by) {
    P.sendParams({ [name]: +clamp(name, current(name) + by).toFixed(3) });
  }

  const KEYS = {
    ArrowUp: () => nudge("speed", STEP.speed), w: () => nudge("speed", STEP.speed),
    ArrowDown: () => nudge("speed", -STEP.speed), s: () => nudge("speed", -STEP.speed),
    ArrowLeft: () => nudge("turn", STEP.turn), a: () => nudge("turn", STEP.turn),
    ArrowRight: () => nudge("turn", -STEP.turn), d: () => nudge("turn", -STEP.turn),
    " ": () => P.run("keyboard", "/api/stop"),
  };

  document.addEventListener("keydown", (e) => {
    if (e.key === "Escape") { e.preventDefault(); P.run("keyboard", "/api/estop"); return; }
    const t = e.target;
    // A focused slider does not eat the arrows: they steer by the documented steps.
    const typing = t && (t.tagName === "INPUT" && t.type !== "checkbox" && t.type !== "range"
                         || t.tagName === "SELECT" || t.tagName === "TEXTAREA");
    const key = e.key.length === 1 ? e.key.toLowerCase() : e.key;
    if (typing || e.ctrlKey || e.metaKey || e.altKey || !KEYS[key] || !spec("speed")) return;
    e.preventDefault();
    KEYS[key]();
  });
})();
