"""Where a chased show's timecode comes from (``--chase KIND:WHERE``):

- ``ltc:FILE.wav``: LTC recorded in a WAV file, heard as if it came from an input from the
  moment the run starts, on the loop's own clock (a simulation faster than real time
  hears it faster too): for tests and rehearsals;
- ``ltc:DEVICE``: LTC from an audio input (an ALSA device such as ``hw:1,0`` or
  ``default``, read through ``arecord``, as the soundtrack plays through ``aplay``);
- ``mtc:PORT``: MIDI Time Code from a MIDI input port by name (mido with its rtmidi
  backend: ``pip install 'biped[midi]'``), or ``mtc:HOST:PORTNUM``, a mido socket port (a
  MIDI-over-TCP bridge, mido's ``PortServer``).

Each source stamps a reading with the loop's clock: live sources on the host's monotonic
clock as it arrives, placed on the loop's clock by its age when the loop polls (the loop
then runs on the wall clock: a simulation chasing a live source runs in real time).
"""

from __future__ import annotations

import logging
import queue
import shutil
import subprocess
import threading
import time
import wave
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from robot.errors import ConfigError
from robot.timecode.frames import RATES, Rate, frame_number
from robot.timecode.ltc import LtcDecoder, LtcFrame
from robot.timecode.mtc import MtcDecoder, Reading

log = logging.getLogger(__name__)
KINDS = ("ltc", "mtc")
#: arecord's format for an LTC input: 16-bit mono at 48 kHz, 10 ms a read.
CAPTURE_HZ, CAPTURE_CHUNK = 48_000, 480


class TimecodeSource(Protocol):
    """``prepare()`` does what can fail (a file read, a port opened: ConfigError, before
    anything moves); ``open(now)`` starts hearing it (``now``: the loop's clock [s]);
    ``poll(now)``: the readings that arrived up to ``now``; ``close()``; ``name``."""

    name: str

    def prepare(self) -> None: ...
    def open(self, now: float) -> None: ...
    def poll(self, now: float) -> list[Reading]: ...
    def close(self) -> None: ...


def ltc_rate(frame: LtcFrame, sample_rate: float) -> Rate:
    """The rate of an LTC word: 80 bits a frame, so the bit rate gives 24, 25 or 30; the
    drop-frame flag tells 29.97 drop-frame from 30."""
    fps = sample_rate / (80.0 * frame.bit_samples)
    base = min((24, 25, 30), key=lambda b: abs(b - fps))
    if base == 30 and frame.drop:
        return RATES["29.97df"]
    return RATES[str(base)]


def ltc_reading(frame: LtcFrame, sample_rate: float, at: float) -> Reading | None:
    rate = ltc_rate(frame, sample_rate)
    if frame.frames >= rate.base:
        return None
    n = frame_number(frame.hours, frame.minutes, frame.seconds, frame.frames, rate)
    return Reading(at, n + 1.0, rate)    # its last bit ended: the next frame begins


def read_wav(path: Path) -> tuple[np.ndarray, float]:
    """The first channel of a PCM WAV as floats, and its sample rate [Hz]."""
    try:
        with wave.open(str(path), "rb") as w:
            width, channels, rate = w.getsampwidth(), w.getnchannels(), w.getframerate()
            raw = w.readframes(w.getnframes())
    except (OSError, EOFError, wave.Error) as e:
        raise ConfigError(f"--chase ltc:{path}: not a readable WAV file: {e}") from None
    if width == 1:
        x = np.frombuffer(raw, dtype=np.uint8).astype(np.float64) - 128.0
    elif width in (2, 4):
        x = np.frombuffer(raw, dtype=f"<i{width}").astype(np.float64)
    elif width == 3:
        b = np.frombuffer(raw, dtype=np.uint8).reshape(-1, 3).astype(np.int32)
        x = ((b[:, 0] | (b[:, 1] << 8) | (b[:, 2] << 16)) << 8 >> 8).astype(np.float64)
    else:
        raise ConfigError(f"--chase ltc:{path}: {8 * width}-bit samples; expected 8-32 bit PCM")
    return x[::channels] if channels > 1 else x, float(rate)


class LtcFile:
    """LTC in a WAV file, heard from ``open`` on the loop's clock."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.name = f"ltc:{path}"
        self._words: list[LtcFrame] = []
        self._rate = 0.0
        self._frames: list[Reading] = []
        self._next = 0

    def prepare(self) -> None:
        x, self._rate = read_wav(self.path)
        self._words = LtcDecoder(self._rate).feed(x)
        if not self._words:
            raise ConfigError(f"--chase ltc:{self.path}: no LTC found in it (expected "
                              "SMPTE linear timecode audio)")

    def open(self, now: float) -> None:
        self._frames = [r for f in self._words
                        if (r := ltc_reading(f, self._rate, now + f.end / self._rate))
                        is not None]

    def poll(self, now: float) -> list[Reading]:
        out = []
        while self._next < len(self._frames) and self._frames[self._next].at <= now:
            out.append(self._frames[self._next])
            self._next += 1
        return out

    def close(self) -> None:
        self._frames = []


class _Live:
    """A source heard by a thread of its own on the host's clock: readings queued,
    mapped onto the loop's clock at ``poll``."""

    name = "live"

    def __init__(self) -> None:
        self._queue: queue.Queue[Reading] = queue.Queue()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def _start(self, now: float, target: Any) -> None:
        self._thread = threading.Thread(target=target, daemon=True, name=self.name)
        self._thread.start()

    def poll(self, now: float) -> list[Reading]:
        """Readings since the last poll, each placed on the loop's clock by its age now
        (the two clocks compared afresh each poll: a simulation that fell behind the wall
        clock does not shift the timecode)."""
        out: list[Reading] = []
        heard = time.monotonic()
        while True:
            try:
                r = self._queue.get_nowait()
            except queue.Empty:
                return out
            out.append(Reading(now - (heard - r.at), r.frame, r.rate, r.locate))

    def _put(self, reading: Reading | None) -> None:
        if reading is not None:
            self._queue.put(reading)


class LtcDevice(_Live):
    """LTC from an ALSA capture device through ``arecord``."""

    def __init__(self, device: str) -> None:
        super().__init__()
        self.device = device
        self.name = f"ltc:{device}"
        self._proc: subprocess.Popen[bytes] | None = None

    def prepare(self) -> None:
        if shutil.which("arecord") is None:
            raise ConfigError(f"--chase ltc:{self.device}: arecord not found (ALSA's "
                              "alsa-utils); or give a WAV file")

    def open(self, now: float) -> None:
        self._proc = subprocess.Popen(
            ["arecord", "-q", "-D", self.device, "-f", "S16_LE", "-c", "1", "-r",
             str(CAPTURE_HZ), "-t", "raw"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self._start(now, self._listen)

    def _listen(self) -> None:
        proc = self._proc
        assert proc is not None and proc.stdout is not None
        decoder, fed = LtcDecoder(CAPTURE_HZ), 0
        while not self._stop.is_set():
            chunk = proc.stdout.read(2 * CAPTURE_CHUNK)
            if not chunk:
                err = proc.stderr.read().decode(errors="replace").strip() if proc.stderr else ""
                log.warning("LTC input %s ended%s", self.device, f": {err}" if err else "")
                return
            arrived = time.monotonic()
            x = np.frombuffer(chunk, dtype="<i2")
            fed += len(x)
            for f in decoder.feed(x):
                self._put(ltc_reading(f, CAPTURE_HZ, arrived - (fed - f.end) / CAPTURE_HZ))

    def close(self) -> None:
        self._stop.set()
        if self._proc is not None and self._proc.poll() is None:
            self._proc.terminate()
            self._proc.wait(timeout=2.0)


class MtcPort(_Live):
    """MTC from a mido input port (by name, or HOST:PORTNUM: a socket port)."""

    def __init__(self, port: str) -> None:
        super().__init__()
        self.port_name = port
        self.name = f"mtc:{port}"
        self._port: Any = None
        self._decoder = MtcDecoder()

    def prepare(self) -> None:
        try:
            import mido
            import mido.sockets
        except ImportError:
            raise ConfigError(f"--chase {self.name}: needs mido (pip install "
                              "'biped[midi]')") from None
        host, _, num = self.port_name.rpartition(":")
        try:
            if host and num.isdigit():
                self._port = mido.sockets.connect(host, int(num))
            else:
                self._port = mido.open_input(self.port_name)
        except (OSError, ImportError) as e:
            names = ", ".join(mido.get_input_names()) if not host else ""
            raise ConfigError(f"--chase {self.name}: cannot open it: {e}"
                              + (f"; inputs: {names or '(none)'}" if not host else "")) from None

    def open(self, now: float) -> None:
        self._start(now, self._listen)

    def _listen(self) -> None:
        while not self._stop.is_set():
            try:
                msg = self._port.receive(block=True)
            except (OSError, EOFError, ValueError):     # closed (ValueError: by us)
                return
            if msg is None:
                return
            self.feed(msg, time.monotonic())

    def feed(self, msg: Any, at: float) -> None:
        """One mido message heard at ``at`` [s, monotonic]."""
        if msg.type == "quarter_frame":
            self._put(self._decoder.quarter(msg.frame_type, msg.frame_value, at))
        elif msg.type == "sysex":
            self._put(self._decoder.sysex(msg.data, at))

    def close(self) -> None:
        self._stop.set()
        if self._port is not None:
            try:
                self._port.close()
            except OSError:
                pass


def source_of(spec: str) -> TimecodeSource:
    """The source of ``--chase KIND:WHERE``; ConfigError naming the valid kinds."""
    kind, _, where = spec.partition(":")
    if kind not in KINDS or not where:
        raise ConfigError(f"--chase {spec}: expected ltc:FILE.wav, ltc:DEVICE or mtc:PORT "
                          f"(kinds: {', '.join(KINDS)})")
    if kind == "mtc":
        return MtcPort(where)
    path = Path(where)
    if path.suffix.lower() == ".wav":
        if not path.is_file():
            raise ConfigError(f"--chase ltc:{where}: file not found")
        return LtcFile(path)
    return LtcDevice(where)
