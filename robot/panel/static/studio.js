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

// A show take with a soundtrack: the browser plays the sound (the robot's computer needs no
// audio stack). Every live frame carries the show's time on the robot (the engine's, 0 at
// its first tick after the ramp in) and the server's wall time when it was read. The page
// dates each frame by that wall time, less the smallest delivery delay seen (so a frame that
// arrives late does not shift the clock), and the audio element follows: started at the
// audio's offset, steered by its playback rate (within +-10 %), re-seeked for a large drift.
(() => {
  const P = window.panel;
  const $ = (id) => document.getElementById(id);
  const TOKEN = new URLSearchParams(location.search).get("token");
  const SEEK_S = 0.15;      // drift [s] beyond which it seeks
  const GAIN = 1.5, INTEGRAL = 0.6;   // rate change per s of drift, per s*s of it held
  let show = null;          // the playing show's fields, or null
  let heard = null;         // {t, at}: show time t [s] at performance.now() at [ms]
  let delay = Infinity;     // smallest (arrival - server wall time) seen [ms]: clock offset
  let lead = 0.05;          // a seek lands this late [s] (learnt from the last one)
  let seeked = false;       // the last step was a seek: the next drift says how late
  let held = 0, last = null;   // integral of the drift [s*s], when it was last updated
  let cue = 0;
  let wasPlaying = null;    // the take playing at the last frame

  function showTime() {     // the robot's show time now [s], by the page's clock
    return heard ? heard.t + (performance.now() - heard.at) / 1000 : null;
  }

  function hear(t, wall) {  // a frame: show time t [s] read at server wall time [s]
    const now = performance.now();
    const arrival = performance.timeOrigin + now;
    delay = Math.min(delay, arrival - 1000 * wall);
    heard = { t, at: now - (arrival - 1000 * wall - delay) };   // when it was read, here
  }

  function follow() {
    const audio = $("show-audio");
    if (!show || !show.audio || heard === null) return;
    const want = showTime() - show.audio_offset_s;    // where the audio should be [s]
    if (want < 0) return;
    if (audio.paused) {
      audio.currentTime = want + lead;
      seeked = true;
      audio.play().catch((e) => P.say("audio: " + e.message + " (tap the page once)", true));
      return;
    }
    const drift = audio.currentTime - want;
    if (seeked) { lead = Math.min(0.3, Math.max(0, lead - drift)); seeked = false; }
    const now = performance.now();
    held = Math.min(0.05, Math.max(-0.05, held + drift * (last ? (now - last) / 1000 : 0)));
    last = now;
    if (Math.abs(drift) > SEEK_S) {
      audio.currentTime = want + lead; audio.playbackRate = 1; seeked = true; held = 0;
    } else {
      audio.playbackRate = Math.min(1.1, Math.max(0.9, 1 - GAIN * drift - INTEGRAL * held));
    }
  }

  function stop(why) {
    const audio = $("show-audio");
    audio.pause();
    audio.removeAttribute("src");
    $("show-line").hidden = true;
    if (why) P.say(why);
    show = null; heard = null; cue = 0; delay = Infinity; held = 0; last = null;
  }

  P.listeners.push((s) => {
    const now = s.studio && s.studio.show;
    const badge = $("rec-badge");
    badge.hidden = !(s.studio && (s.studio.recording || s.studio.playing));
    badge.textContent = s.studio && s.studio.recording ? "● REC " + s.studio.recording
      : (s.studio && s.studio.playing ? "▶ " + s.studio.playing : "");
    const playing = s.studio ? s.studio.playing : null;
    if (wasPlaying && playing !== wasPlaying) P.say("take " + wasPlaying + " finished");
    wasPlaying = playing;
    if (!now || s.state !== "walking") {
      if (show) stop(null);
      return;
    }
    if (!show || show.take !== now.take) {
      show = now; cue = 0;
      const audio = $("show-audio");
      if (now.audio) {
        audio.src = now.audio + (TOKEN ? "&token=" + encodeURIComponent(TOKEN) : "");
        audio.load();
      }
    }
    hear(now.t, s.wall_time);
    while (cue < now.cues.length && now.cues[cue].t <= now.t) {
      const line = $("show-line");
      line.hidden = false;
      line.textContent = "cue " + now.cues[cue].t.toFixed(2) + " s: " + now.cues[cue].name;
      cue++;
    }
    follow();
  });
  setInterval(follow, 50);
  // For the tests and the curious: the audio's clock and the show time it follows [s].
  window.showClock = () => ({ audio: $("show-audio").currentTime, playing: !$("show-audio").paused,
                              show: showTime(), offset: show ? show.audio_offset_s : null });
})();
