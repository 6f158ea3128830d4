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
  function prepare(now) {   // a new show: load its audio
    if (show && show.take === now.take) return;
    show = now; cue = 0;
    const audio = $("show-audio");
    if (now.audio) {
      audio.src = now.audio + (TOKEN ? "&token=" + encodeURIComponent(TOKEN) : "");
      audio.load();
    }
  }

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
// audio stack). Every live frame carries the show's time t on the robot (the engine's, 0 at
// its first tick after the ramp in), the robot's wall time `at` of that very tick, and the
// rate at which show time runs (below 1 when the loop falls behind). The page maps the
// robot's wall clock onto its own by the smallest (arrival - at) seen, so a frame that
// arrives late, or was read from a cache, still says what the show time was when; the show
// time now is t + rate * (now - at). The audio element follows: started at the audio's
// offset, steered by its playback rate, re-seeked only for a large drift. The steering is
// proportional, with the show's rate fed forward: rate = show rate - drift / TAU, so the
// drift decays as exp(-t / TAU) and never overshoots (no integral term to wind up); a
// playback rate is set only when it changes by more than RATE_STEP (each change costs the
// audio renderer a re-buffer).
(() => {
  const P = window.panel;
  const $ = (id) => document.getElementById(id);
  const TOKEN = new URLSearchParams(location.search).get("token");
  const SEEK_S = 0.15;      // drift [s] beyond which it seeks
  const TAU = 0.5;          // [s] time constant of the steering
  const MAX_DEV = 0.1;      // largest playback-rate change from the show's rate
  const RATE_STEP = 0.005;  // smallest playback-rate change made
  let show = null;          // the playing show's fields, or null
  let heard = null;         // {t, at, rate}: show time t [s] at page time at [ms]
  let offset = Infinity;    // smallest (arrival - robot wall time) seen [ms]: the clocks' offset
  let lead = 0.05;          // a seek lands this late [s] (learnt from the last one)
  let seeked = false;       // the last step was a seek: the next drift says how late
  let cue = 0;
  let seeks = 0;            // seeks made (for the tests: a seek is a jump in the sound)
  let wasPlaying = null;    // the take playing at the last frame

  const pageNow = () => performance.timeOrigin + performance.now();   // [ms]

  function showTime(at) {   // the robot's show time [s] at page time at [ms]
    return heard ? heard.t + heard.rate * (at - heard.at) / 1000 : null;
  }

  function hear(now) {      // a frame: show time now.t [s] at robot wall time now.at [s]
    if (now.at === null || now.at === undefined) return;
    offset = Math.min(offset, pageNow() - 1000 * now.at);
    heard = { t: now.t, at: 1000 * now.at + offset, rate: now.rate || 1 };
  }

  function follow() {
    const audio = $("show-audio");
    if (!show || !show.audio || heard === null) return;
    const at = pageNow();
    const want = showTime(at) - show.audio_offset_s;   // where the audio should be [s]
    if (want < 0) return;
    if (audio.paused) {
      audio.currentTime = want + lead;
      seeked = true; seeks++;
      audio.play().catch((e) => P.say("audio: " + e.message + " (tap the page once)", true));
      return;
    }
    const drift = audio.currentTime - want;
    if (seeked) { lead = Math.min(0.3, Math.max(0, lead - drift)); seeked = false; }
    if (Math.abs(drift) > SEEK_S) {
      audio.currentTime = want + lead; audio.playbackRate = heard.rate; seeked = true;
      seeks++;
      return;
    }
    const rate = heard.rate * Math.min(1 + MAX_DEV, Math.max(1 - MAX_DEV, 1 - drift / TAU));
    if (Math.abs(rate - audio.playbackRate) > RATE_STEP) audio.playbackRate = rate;
  }

  function stop(why) {
    const audio = $("show-audio");
    audio.pause();
    audio.removeAttribute("src");
    $("show-line").hidden = true;
    if (why) P.say(why);
    show = null; heard = null; cue = 0; offset = Infinity;
  }

  function prepare(now) {   // a new show: load its audio
    if (show && show.take === now.take) return;
    show = now; cue = 0;
    const audio = $("show-audio");
    if (now.audio) {
      audio.src = now.audio + (TOKEN ? "&token=" + encodeURIComponent(TOKEN) : "");
      audio.load();
    }
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
    if (!now || !s.running) {
      if (show) stop(null);
      return;
    }
    if (!now.playing) {
      if (heard) stop(null);                 // played to its end: ramping out
      else if (now.at === null) prepare(now);   // ramping in: the audio loads
      return;
    }
    prepare(now);
    hear(now);
    while (cue < now.cues.length && now.cues[cue].t <= now.t) {
      const line = $("show-line");
      line.hidden = false;
      line.textContent = "cue " + now.cues[cue].t.toFixed(2) + " s: " + now.cues[cue].name;
      cue++;
    }
    follow();
  });
  setInterval(follow, 50);
  // For the tests and the curious: the audio's clock [s] and the page's wall time of that
  // read [ms], and the show time the page follows then [s].
  window.showClock = () => {
    const audio = $("show-audio"), at = pageNow();
    return { audio: audio.currentTime, at, playing: !audio.paused, show: showTime(at),
             offset: show ? show.audio_offset_s : null, clockOffset: offset, seeks,
             rate: audio.playbackRate };
  };
})();
