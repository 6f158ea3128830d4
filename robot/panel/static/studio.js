// Record and replay takes, pose by hand and keyframes (robot/panel/studio.py).
"use strict";

(() => {
  const P = window.panel;
  const $ = (id) => document.getElementById(id);

  function fill(select, names, keep) {
    const was = keep || select.value;
    select.textContent = "";
    if (!names.length) select.add(new Option("(none yet)", ""));
    for (const n of names) select.add(new Option(n, n, false, n === was));
  }

  async function refresh(selectTake, selectSeq) {
    try {
      const t = await P.api("GET", "/api/takes");
      fill($("takes"), t.takes, selectTake);
      const s = await P.api("GET", "/api/sequences");
      fill($("sequences"), s.sequences, selectSeq);
      if (!$("limb").options.length) fill($("limb"), s.limbs, "arms");
      status(s);
    } catch (e) { P.say(e.message, true); }
  }

  function status(st) {
    if (!st) return;
    $("keycount").textContent = st.keyframes + " keyframe" + (st.keyframes === 1 ? "" : "s") +
      (st.released ? " · " + st.released + " released" : "");
    const rec = $("record");
    rec.textContent = st.recording ? "● Recording " + st.recording : "● Record";
    rec.disabled = !!st.recording;
  }

  let wasRecording = null;
  P.listeners.push((s) => {
    if (!s.studio) return;
    status(s.studio);
    if (wasRecording && !s.studio.recording) refresh(wasRecording);  // a take just ended
    wasRecording = s.studio.recording;
  });

  const on = (id, path, body, after) => $(id).addEventListener("click", async () => {
    const r = await P.run(id, path, body ? body() : undefined);
    if (r && after) await after(r);
    if (r && r.studio) status(r.studio);
  });
  document.addEventListener("panel-ready", () => {
    refresh();
    on("record", "/api/record", null);
    on("play", "/api/play", () => ({ name: $("takes").value }));
    on("release", "/api/pose/release", () => ({ limb: $("limb").value }));
    on("capture", "/api/pose/capture", null);
    on("seq-clear", "/api/pose/clear", null);
    on("seq-save", "/api/pose/save", () => ({ name: $("seq-name").value }),
       () => refresh(null, $("seq-name").value));
    on("seq-play", "/api/sequence/play", () => ({ name: $("sequences").value, layer: false }));
    on("seq-layer", "/api/sequence/play", () => ({ name: $("sequences").value, layer: true }));
  });
})();
