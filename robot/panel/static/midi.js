// biped panel: MIDI learn (docs/show-control.md). With the panel started with --midi,
// "MIDI learn" arms it: touch a slider, then move a fader or knob; the panel binds that
// control to the slider's parameter over its whole range and saves the mapping file.
"use strict";

(function () {
  const button = $("midi-learn");
  let armed = false;     // waiting for a slider to be touched
  let watching = null;   // the poll while the panel waits for the fader

  async function showctl() { return api("GET", "/api/showctl"); }

  function disarm() {
    armed = false;
    button.classList.remove("armed");
  }

  async function learn(name) {
    disarm();
    const label = (inputs[name] && inputs[name].spec.label) || name;
    try {
      await api("POST", "/api/midi/learn", { param: name });
    } catch (e) { say(e.message, true); return; }
    say("MIDI learn: move a fader or knob for " + label);
    clearInterval(watching);
    watching = setInterval(async () => {
      const s = await showctl().catch(() => null);
      if (!s || !s.midi || s.midi.learning) return;
      clearInterval(watching);
      const cc = s.midi.cc.find((c) => c.param === name);
      say(cc ? "MIDI: channel " + cc.channel + " CC " + cc.cc + " → " + label +
               " (saved to " + s.midi.mapping + ")" : "MIDI learn cancelled");
    }, 300);
  }

  button.addEventListener("click", async () => {
    if (armed) { disarm(); await api("POST", "/api/midi/learn", { param: null }); say(""); return; }
    armed = true;
    button.classList.add("armed");
    say("MIDI learn: touch the slider to bind");
  });
  // Touching a slider while armed picks its parameter (the pointer, or focus by keyboard).
  document.addEventListener("pointerdown", (ev) => {
    const t = ev.target;
    if (armed && t instanceof HTMLInputElement && t.id.startsWith("range-")) learn(t.id.slice(6));
  }, true);
  document.addEventListener("focusin", (ev) => {
    const t = ev.target;
    if (armed && t instanceof HTMLInputElement && /^(range|num)-/.test(t.id)) {
      learn(t.id.replace(/^(range|num)-/, ""));
    }
  });
  showctl().then((s) => { button.hidden = !s.midi; }).catch(() => { button.hidden = true; });
})();
