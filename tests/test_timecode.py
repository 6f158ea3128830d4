"""Timecode pieces against facts from the standards and an independent encoder: SMPTE
drop-frame counting (published frame numbers), LTC audio written by tests/ltc_encode.py
(from the ST 12-1 bit layout, level by sample instant, RC-rounded edges, hum, noise,
offset) decoded at 24, 25, 29.97 drop-frame and 30 fps at 48 and 44.1 kHz, word end times
within 0.1 ms, dropouts and jumps; MTC quarter frames as bytes (mido's parser) with the
rate bits, the two-frame span of a group, a full-frame locate; the chase clock's lock,
dropout, loss and jump from readings made by hand."""

from __future__ import annotations

import mido
import numpy as np
import pytest
from ltc_encode import drop_frame_labels, encode, plain_labels

from robot.errors import ConfigError
from robot.timecode.chase import ChaseClock
from robot.timecode.frames import RATES, frame_number, label, parse_timecode
from robot.timecode.ltc import LtcDecoder
from robot.timecode.mtc import MtcDecoder
from robot.timecode.sources import ltc_rate


@pytest.mark.parametrize(("tc", "frame"), [("00:01:00;02", 1800), ("00:10:00;00", 17982),
                                           ("00:00:59;29", 1799), ("01:00:00;00", 107892),
                                           ("23:59:59;29", 2589407)])
def test_drop_frame_numbers_are_the_published_ones(tc: str, frame: int) -> None:
    rate = RATES["29.97df"]
    assert parse_timecode(tc, rate) == frame
    assert label(frame, rate) == tuple(int(v) for v in tc.replace(";", ":").split(":"))


def test_drop_frame_labels_round_trip_against_a_label_by_label_count() -> None:
    rate = RATES["29.97df"]
    counted = drop_frame_labels(0, 40_000)
    assert [label(n, rate) for n in range(40_000)] == counted
    assert [frame_number(*lab, rate) for lab in counted] == list(range(40_000))


def test_a_skipped_label_and_a_bad_one_are_refused() -> None:
    with pytest.raises(ConfigError, match="no such drop-frame label"):
        parse_timecode("00:01:00;00", RATES["29.97df"])
    with pytest.raises(ConfigError, match="HH:MM:SS:FF"):
        parse_timecode("1:2:3", RATES["30"])


CASES = [(24.0, 24, False, 48_000), (25.0, 25, False, 44_100), (30.0, 30, False, 48_000),
         (30000 / 1001, 30, True, 44_100), (30000 / 1001, 30, True, 48_000)]


@pytest.mark.parametrize(("fps", "base", "drop", "sr"), CASES)
def test_ltc_from_an_independent_encoder_decodes(fps: float, base: int, drop: bool,
                                                 sr: int) -> None:
    labels = (drop_frame_labels(17_960, 90) if drop                # across 00:10:00;00
              else plain_labels(3600 * base - 45, 90, base))       # across 01:00:00:00
    audio = encode(labels, fps, sample_rate=sr, drop=drop)
    decoder = LtcDecoder(sr)
    words = []
    for chunk in np.array_split(audio, 97):                        # as an input delivers it
        words += decoder.feed(chunk)
    got = [(w.hours, w.minutes, w.seconds, w.frames) for w in words]
    first = labels.index(got[0])
    assert first <= 2 and got == labels[first:first + len(got)] and len(got) >= 87
    ends = np.array([w.end for w in words]) / sr
    assert np.abs(ends - (np.arange(first, first + len(got)) + 1) / fps).max() < 1e-4
    rate = ltc_rate(words[0], sr)
    assert (rate.base, rate.drop) == (base, drop)


def test_ltc_resumes_after_silence_and_follows_a_jump() -> None:
    labels = plain_labels(0, 40, 30) + [None] * 20 + plain_labels(900, 40, 30)
    words = LtcDecoder(48_000).feed(encode(labels, 30.0))
    got = [(w.hours, w.minutes, w.seconds, w.frames) for w in words]
    assert got[:38] == labels[1:39]
    after = [g for g in got if g[2] >= 30]
    assert after and after == plain_labels(900, 40, 30)[40 - len(after) - 1:-1]
    assert len(after) >= 36


def _qf(tc: tuple[int, int, int, int], code: int) -> list[bytes]:
    """The eight quarter frames of a timecode, as MIDI bytes (F1 0nnndddd)."""
    h, m, s, f = tc
    nibbles = [f & 15, f >> 4, s & 15, s >> 4, m & 15, m >> 4, h & 15, (h >> 4) | (code << 1)]
    return [bytes([0xF1, (piece << 4) | v]) for piece, v in enumerate(nibbles)]


@pytest.mark.parametrize(("code", "name"), [(0, "24"), (1, "25"), (2, "29.97df"), (3, "30")])
def test_mtc_quarter_frames_give_the_time_and_rate(code: int, name: str) -> None:
    rate = RATES[name]
    dec, parser = MtcDecoder(), mido.Parser()
    readings = []
    start = frame_number(1, 2, 3, 4, rate)
    q = 1.0 / (4 * rate.fps)                              # a quarter frame [s]
    k = 0
    for group in range(6):                                # 12 frames, every other labelled
        for byte in _qf(label(start + 2 * group, rate), code):
            parser.feed(byte)
            for msg in parser:
                r = dec.quarter(msg.frame_type, msg.frame_value, at=k * q)
                if r is not None:
                    readings.append(r)
            k += 1
    assert all(r.rate == rate for r in readings)
    first = readings[0]                       # piece 7 of the first group: T + 7/4 frames
    assert first.at == pytest.approx(7 * q) and first.frame == pytest.approx(start + 1.75)
    # every later piece: the time it arrived at, on the frame count
    assert all(r.frame == pytest.approx(start + r.at / q / 4) for r in readings)
    assert len(readings) == 6 * 8 - 7


def test_mtc_full_frame_locates_and_lost_pieces_resync() -> None:
    dec, parser = MtcDecoder(), mido.Parser()
    parser.feed(bytes([0xF0, 0x7F, 0x7F, 0x01, 0x01, 0x61, 0x00, 0x00, 0x00, 0xF7]))
    msg = next(iter(parser))
    r = dec.sysex(msg.data, at=0.0)
    assert r is not None and r.locate and r.rate == RATES["30"]
    assert r.frame == frame_number(1, 0, 0, 0, RATES["30"])
    pieces = _qf((1, 0, 0, 10), 3)
    assert [dec.quarter(p[1] >> 4, p[1] & 15, 0.0) for p in pieces[:3] + pieces[4:]] == \
        [None] * 7                                        # piece 3 lost: nothing claimed


def test_the_chase_clock_locks_freewheels_counts_and_jumps() -> None:
    rate = RATES["25"]
    c = ChaseClock((0, 0, 10, 0), freewheel=10)
    start = frame_number(0, 0, 10, 0, rate)
    rng = np.random.default_rng(2)
    for k in range(50):                                   # 2 ms of jitter on arrival
        c.reading(k * 0.04 + rng.uniform(-0.002, 0.002), start - 25 + k, rate)
    assert c.show_time(49 * 0.04) == pytest.approx(24 / 25, abs=0.004)
    assert c.stats.max_error_frames < 0.1 and c.stats.jumps == 0
    assert c.check(49 * 0.04 + 0.2)                       # 5 frames silent: freewheel
    assert c.stats.dropouts == 1
    assert not c.check(49 * 0.04 + 0.5)                   # 12.5 frames: lost
    c.reading(2.5, start + 250, rate)                     # a jump to 10 s of show
    assert c.stats.jumps == 1 and c.show_time(2.5) == pytest.approx(10.0)
