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
// audio stack). Every live frame carries the show's time t on the robot (the engine's, 0 at
// its first tick after the ramp in), the robot's wall time `at` of that very tick, and the
// rate at which show time runs (below 1 when the loop falls behind). The page maps the
// robot's wall clock onto its own by the smallest (arrival - at) seen, so a frame that
// arrives late, or was read from a cache, still says what the show time was when; the show
// time now is t + rate * (now - at). The audio element follows: started at the audio's
// offset, steered by its playback rate, re-seeked only for a large drift that holds.
// Starting is not instant: after a seek (or the first play) the element's clock stalls
// before it runs, and runs as if it had started that lead later (headless Chromium:
// 105-130 ms; a play without a seek, 7 ms). So while the robot ramps in, the page
// rehearses the start silently (seek, play, fit a line to the clock's run, pause) and
// measures that lead; the real start is then sent the lead early and ahead, so the clock
// runs on the show's time from its first frame. Later seeks learn the lead again from the
// drift once the audio has settled after the seek, by halves, within 0..0.3 s.
// The audio's clock moves in the renderer's chunks and stalls when the machine is busy, so
// one read of the drift is noisy by tens of ms: the steering acts on the median of the
// last tune.window reads (a stall or a jump of one chunk does not move it). And the audio
// clock need not run at the playback rate asked: in headless Chromium on a loaded machine
// it ran 3 % slow, so a proportional steering alone sat tens of ms behind. The page learns
// that gain g (audio seconds per second of asked rate, over the last tune.gainS seconds,
// counted once the audio has settled after the last seek) and divides it out. The
// steering is then proportional with the show's rate fed forward: rate = show rate x
// (1 - drift / TAU) / g, so the drift decays as exp(-t / TAU) without overshoot (no
// integral term to wind up; TAU well above the window's delay); a playback rate is set
// only when it changes by more than tune.step (each change costs the audio renderer a
// re-buffer). The settings are window.showTune (docs/show_sync.py tries others).
(() => {
  const P = window.panel;
  const $ = (id) => document.getElementById(id);
  const TOKEN = new URLSearchParams(location.search).get("token");
  const tune = window.showTune = {
    seek: 0.25,     // median drift [s] beyond which it seeks
    tau: 1.0,       // [s] time constant of the steering
    maxDev: 0.1,    // largest playback-rate change from the show's rate
    step: 0.003,    // smallest playback-rate change made
    window: 5,      // reads (one per FOLLOW_MS) whose median drift steers
    gainS: 8.0,     // [s] of reads over which the audio clock's gain is measured
    keepPitch: false,   // time-stretch to keep the pitch (its clock stalls ~20 ms as it engages)
  };
  const FOLLOW_MS = 50;
  let show = null;          // the playing show's fields, or null
  let heard = null;         // {t, at, rate}: show time t [s] at page time at [ms]
  let offset = Infinity;    // smallest (arrival - robot wall time) seen [ms]: the clocks' offset
  let lead = 0.115;         // a seek lands this late [s] (rehearsed, then learnt)
  let rehearsal = null;     // null: not yet; "running", "cut" or "done" (the loaded audio)
  let seeked = false;       // the last step was a seek: the next drift says how late
  let drifts = [];          // the last tune.window drift reads [s]
  let runs = [];            // since the last seek: {at [ms], audio [s], rate asked}
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
    heard = { t: now.t, at: 1000 * now.at + offset,
              rate: Math.min(1.2, Math.max(0.8, now.rate || 1)) };
  }

  function median(xs) {
    const s = [...xs].sort((a, b) => a - b), m = s.length >> 1;
    return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2;
  }

  // Seek, play silently (muted, and volume 0) and fit a line to the clock's run from 180 to 300 ms after play():
  // the lead is how long after play() that line passes the seek's position. A start due
  // before it ends cuts it short (rehearsal "cut") and keeps the lead it had.
  async function rehearse(audio) {
    rehearsal = "running";
    try {
      const from = Math.min(1, 0.5 * (audio.duration || 0));
      audio.muted = true;     // (a phone's browser may ignore the volume: muted it keeps)
      audio.volume = 0;
      audio.currentTime = from;
      const t0 = performance.now();
      await audio.play();
      const xs = [], ys = [];
      while (performance.now() - t0 < 300 && rehearsal === "running") {
        const dt = performance.now() - t0;
        if (dt > 180) { xs.push(dt / 1000); ys.push(audio.currentTime); }
        await new Promise((r) => setTimeout(r, 5));
      }
      audio.pause();
      const n = xs.length;
      if (n > 5) {
        const mx = xs.reduce((a, b) => a + b) / n, my = ys.reduce((a, b) => a + b) / n;
        let sxy = 0, sxx = 0;
        for (let k = 0; k < n; k++) { sxy += (xs[k] - mx) * (ys[k] - my); sxx += (xs[k] - mx) ** 2; }
        const slope = sxy / sxx, lag = mx - (my - from) / slope;
        if (slope > 0.5 && slope < 1.5) lead = Math.min(0.3, Math.max(0, lag));
      }
    } catch (e) {  // not allowed to play yet: the start keeps the lead it had
    } finally {
      audio.volume = 1;
      audio.muted = false;
      rehearsal = "done";
    }
  }

  function seekTo(audio, want) {
    audio.currentTime = want + lead;
    seeked = true; seeks++; drifts = []; runs = [];
  }

  function gain(at, audio) {   // the audio clock's seconds per second of asked rate
    runs.push({ at, audio: audio.currentTime, rate: audio.playbackRate });
    while (runs.length > 2 && runs[0].at < at - 1000 * tune.gainS) runs.shift();
    const a = runs[0], b = runs[runs.length - 1];
    if (b.at - a.at < 1500) return 1;
    let asked = 0;
    for (let k = 1; k < runs.length; k++) {
      asked += runs[k - 1].rate * (runs[k].at - runs[k - 1].at) / 1000;
    }
    return Math.min(1.2, Math.max(0.8, (b.audio - a.audio) / asked));
  }

  function follow() {
    const audio = $("show-audio");
    if (!show || !show.audio || heard === null) return;
    const at = pageNow();
    const want = showTime(at) - show.audio_offset_s;   // where the audio should be [s]
    // (cut two reads ahead, so the element is free when the start is due)
    if (rehearsal === "running" && want + lead + 2 * FOLLOW_MS / 1000 >= 0) rehearsal = "cut";
    if (rehearsal !== "done" || want + lead < 0) return;
    if (audio.paused) {   // sent the lead early and ahead: the clock runs on time
      seekTo(audio, want);
      audio.preservesPitch = tune.keepPitch;
      audio.play().catch((e) => P.say("audio: " + e.message + " (tap the page once)", true));
      return;
    }
    drifts.push(audio.currentTime - want);
    if (drifts.length > tune.window) drifts.shift();
    const drift = median(drifts);
    if (drifts.length < tune.window) return;   // just seeked: the audio is settling
    if (seeked) {   // how far from where it was sent the seek landed, half learnt
      lead = Math.min(0.3, Math.max(0, lead - 0.5 * drift)); seeked = false;
    }
    if (Math.abs(drift) > tune.seek) {
      seekTo(audio, want);
      audio.playbackRate = heard.rate;
      return;
    }
    const dev = Math.min(tune.maxDev, Math.max(-tune.maxDev, -drift / tune.tau));
    const rate = heard.rate * (1 + dev) / gain(at, audio);
    if (Math.abs(rate - audio.playbackRate) > tune.step) audio.playbackRate = rate;
  }

  function stop(why) {
    const audio = $("show-audio");
    audio.pause();
    audio.removeAttribute("src");
    $("show-line").hidden = true;
    if (why) P.say(why);
    show = null; heard = null; cue = 0; offset = Infinity; drifts = []; rehearsal = null;
  }

  function prepare(now) {   // a new show: load its audio
    if (show && show.take === now.take) return;
    show = now; cue = 0;
    const audio = $("show-audio");
    if (now.audio) {
      audio.src = now.audio + (TOKEN ? "&token=" + encodeURIComponent(TOKEN) : "");
      rehearsal = null;
      audio.addEventListener("canplaythrough", () => rehearse(audio), { once: true });
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
  });
  setInterval(follow, FOLLOW_MS);   // the only caller: one drift read per FOLLOW_MS
  // For the tests and the curious: the audio's clock [s] and the page's wall time of that
  // read [ms], and the show time the page follows then [s].
  window.showClock = () => {
    const audio = $("show-audio"), at = pageNow();
    return { audio: audio.currentTime, at, playing: !audio.paused && rehearsal === "done",
             show: showTime(at), lead,
             offset: show ? show.audio_offset_s : null, clockOffset: offset, seeks,
             rate: audio.playbackRate };
  };
})();
