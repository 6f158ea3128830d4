"""Show control at the message level: OSC datagrams (built by python-osc) and MIDI bytes
(written here from the MIDI 1.0 and MSC specifications) in; the actions, parameter values
and e-stops that reach a recording target out. No panel, no bus: robot.showctl alone."""

from __future__ import annotations

import logging
import math
import socket
import threading
import time
from collections.abc import Mapping
from pathlib import Path

import pytest
from panel_wire import osc_datagram as osc
from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
from pythonosc.osc_message_builder import OscMessageBuilder
from pythonosc.osc_packet import OscPacket
from waiting import wait_for

from robot.config.params import SPECS
from robot.errors import ConfigError
from robot.showctl.actions import Command, Ignored, Named, SetParam, parse
from robot.showctl.cues import CueList
from robot.showctl.feed import Feed
from robot.showctl.midi_in import MidiIn
from robot.showctl.midi_map import CcMap, MidiMap, load_map
from robot.showctl.osc_in import OscListener
from robot.showctl.osc_out import Status, StatusSender
from robot.showctl.sources import Sources


class Recorder:
    """A feed target that records what reaches it; ``hold`` blocks its commands."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, object, float]] = []
        self.hold = threading.Event()
        self.hold.set()
        self.in_act = threading.Event()

    def params(self, changes: Mapping[str, float], received: float) -> None:
        self.calls.append(("params", dict(changes), received))

    def act(self, action: Command | Named, received: float) -> None:
        self.in_act.set()
        self.hold.wait(10)
        self.calls.append(("act", action, received))

    def estop(self, received: float) -> None:
        self.calls.append(("estop", None, received))

    def of(self, kind: str) -> list[object]:
        return [c[1] for c in list(self.calls) if c[0] == kind]




@pytest.fixture
def fed() -> tuple[Recorder, Feed]:
    target = Recorder()
    feed = Feed(target, rate_hz=200.0)
    feed.start()
    yield target, feed
    target.hold.set()
    feed.close()


# ------------------------------------------------------------------------------ OSC
@pytest.mark.parametrize(("address", "args", "action"), [
    ("/biped/param/speed", [0.5], SetParam("speed", 0.5)),
    ("/biped/param/Wpos_R", [1], SetParam("Apos_R", 1.0)),       # an alias, an int
    ("/biped/start", [], Command("start")),
    ("/biped/start", [1.0], Command("start")),                  # a button pressed
    ("/biped/stop", [1], Command("stop")),
    ("/biped/take/stop", [], Command("take stop")),
    ("/biped/go", [], Command("go")),
    ("/biped/preset", ["jog"], Named("preset", "jog")),
    ("/biped/take/play", ["wave"], Named("take", "wave")),
    ("/biped/take/record", [], Named("record", None)),
    ("/biped/take/record", ["t1"], Named("record", "t1")),
    ("/biped/cue", [3], Named("cue", "3")),                     # QLab sends numbers
    ("/biped/cue", [1.5], Named("cue", "1.5")),
    ("/biped/pose", ["bow"], Named("pose", "bow")),
    ("/biped/pose", ["bow", 1], Named("pose", "bow", layer=True)),
])
def test_the_address_space(address: str, args: list[object], action: object) -> None:
    assert parse(address, args) == action


@pytest.mark.parametrize(("address", "args", "kind"), [
    ("/biped/param/speed", [2.0], "value /biped/param/speed"),   # outside [-1, 1.5]
    ("/biped/param/speed", ["fast"], "type /biped/param/speed"),
    ("/biped/param/speed", [True], "type /biped/param/speed"),   # OSC's T
    ("/biped/param/speed", [0.1, 0.2], "type /biped/param/speed"),
    ("/biped/param/sped", [0.5], "param"),
    ("/biped/walk", [], "address"),
    ("/biped/preset", [], "type /biped/preset"),
    ("/biped/start", ["now"], "type /biped/start"),
    ("/biped/pose", ["bow", "x"], "type /biped/pose"),
])
def test_a_wrong_message_is_ignored_by_kind(address: str, args: list[object], kind: str
                                            ) -> None:
    got = parse(address, args)
    assert isinstance(got, Ignored) and got.kind == kind and not got.quiet
    assert address.split("/")[-1] in got.why or "biped" in got.why


def test_a_button_release_does_nothing_quietly() -> None:
    got = parse("/biped/start", [0.0])
    assert isinstance(got, Ignored) and got.quiet


def test_parameter_changes_are_coalesced_to_the_loop_rate(fed: tuple[Recorder, Feed]) -> None:
    target, feed = fed
    t0 = time.monotonic()
    for k in range(10_000):
        feed.put(SetParam("speed", k / 10_000), time.monotonic())
    assert wait_for(lambda: target.of("params")
                    and target.of("params")[-1] == {"speed": 9_999 / 10_000})
    elapsed = time.monotonic() - t0
    updates = target.of("params")
    assert len(updates) <= 200.0 * elapsed + 2, (len(updates), elapsed)
    values = [u["speed"] for u in updates]                      # type: ignore[index]
    assert values == sorted(values)                             # in order, never undone


def test_commands_keep_their_order_with_the_changes_before_them(
        fed: tuple[Recorder, Feed]) -> None:
    target, feed = fed
    for a in (SetParam("speed", 0.3), Command("start"), Command("start"),
              SetParam("speed", 0.4), Named("preset", "jog"), Command("go"), Command("go"),
              SetParam("turn", 0.1)):
        feed.put(a, time.monotonic())
    assert wait_for(lambda: len(target.calls) == 7)
    assert [(c[0], c[1]) for c in target.calls] == [
        ("params", {"speed": 0.3}), ("act", Command("start")),   # the repeat: one start
        ("params", {"speed": 0.4}), ("act", Named("preset", "jog")),
        ("act", Command("go")), ("act", Command("go")),          # each GO: the next cue
        ("params", {"turn": 0.1})]


def test_the_estop_never_waits_behind_a_command(fed: tuple[Recorder, Feed]) -> None:
    target, feed = fed
    target.hold.clear()                        # the next command blocks (a slow start)
    feed.put(Command("start"), time.monotonic())
    assert target.in_act.wait(5)
    for k in range(100):
        feed.put(Named("take", f"t{k}"), time.monotonic())
    sent = time.monotonic()
    feed.put(Command("estop"), sent)
    assert wait_for(lambda: target.of("estop") == [None], timeout_s=5)
    assert [c[2] for c in target.calls if c[0] == "estop"] == [sent]   # arrival kept
    assert target.of("act") == []              # the start is still blocked
    assert feed.stats.dropped == 100 - 64      # the queue is short; a flood is dropped


def _listener(feed: Feed) -> tuple[OscListener, socket.socket]:
    listener = OscListener(feed, port=0)
    listener.open()
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    return listener, sender


def test_osc_over_udp_reaches_the_target(fed: tuple[Recorder, Feed],
                                         caplog: pytest.LogCaptureFixture) -> None:
    target, feed = fed
    listener, sender = _listener(feed)
    try:
        to = ("127.0.0.1", listener.port)
        with caplog.at_level(logging.WARNING):
            for _ in range(50):
                sender.sendto(osc("/biped/param/speed", "fast"), to)
                sender.sendto(osc("/biped/nowhere"), to)
                sender.sendto(b"not osc at all", to)
            sender.sendto(osc("/biped/param/turn", 0.25), to)
            sender.sendto(osc("/biped/preset", "jog"), to)
            assert wait_for(lambda: Named("preset", "jog") in target.of("act"))
        assert {"turn": 0.25} in target.of("params")
        assert wait_for(lambda: sum(feed.once.summary().values()) == 150)
        assert feed.once.summary() == {"type /biped/param/speed": 50, "address": 50,
                                       "malformed": 50}
        lines = [r for r in caplog.records if r.levelno == logging.WARNING]
        assert len(lines) == 3                 # once per kind, whatever the count
    finally:
        listener.close()
        sender.close()


def test_an_estop_in_a_bundle_goes_first(fed: tuple[Recorder, Feed]) -> None:
    target, feed = fed
    target.hold.clear()
    feed.put(Command("start"), time.monotonic())
    assert target.in_act.wait(5)               # the command path is busy
    listener, sender = _listener(feed)
    try:
        b = OscBundleBuilder(IMMEDIATELY)
        for m in (OscMessageBuilder("/biped/param/speed"), OscMessageBuilder("/biped/estop")):
            if m.address.endswith("speed"):
                m.add_arg(0.2)
            b.add_content(m.build())
        sender.sendto(b.build().dgram, ("127.0.0.1", listener.port))
        assert wait_for(lambda: target.of("estop") == [None], timeout_s=5)
        assert feed.stats.estops == 1
    finally:
        listener.close()
        sender.close()


def test_beyond_loopback_needs_an_allow_list() -> None:
    with pytest.raises(ConfigError, match="allow-list.*no authentication"):
        Sources.parse(None, host="0.0.0.0")
    with pytest.raises(ConfigError, match="--osc-allow 'ten'"):
        Sources.parse("ten", host="0.0.0.0")
    s = Sources.parse("192.168.1.20, 10.0.0.0/24", host="0.0.0.0")
    assert s.allows("192.168.1.20") and s.allows("10.0.0.77") and s.allows("127.0.0.1")
    assert s.allows("::ffff:10.0.0.3")
    assert not s.allows("192.168.1.21") and not s.allows("10.0.1.1")
    assert Sources().allows("::1") and not Sources().allows("192.168.1.20")


def test_status_goes_out_asosc() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as rx:
        rx.bind(("127.0.0.1", 0))
        rx.settimeout(5)
        status = Status("walking", None, 1.25, "wave", (("r_knee", 0.5), ("l_knee", -0.5)))
        sender = StatusSender(lambda: status, host="127.0.0.1", port=rx.getsockname()[1],
                              hz=50.0)
        sender.start()
        try:
            data = rx.recv(65536)
        finally:
            sender.close()
    got = {m.message.address: m.message.params for m in OscPacket(data).messages}
    assert got == {"/biped/state": ["walking"], "/biped/fault": [""],
                   "/biped/show/t": [1.25], "/biped/show/take": ["wave"],
                   "/biped/joint/r_knee": [0.5], "/biped/joint/l_knee": [-0.5]}


# ------------------------------------------------------------------------------ MIDI
MAP = """
[[cc]]
channel = 1
cc = 7
param = "speed"
range = [0.0, 1.5]

[[cc]]
channel = 2
cc = 1
param = "torso_lean"
range = [0.3, -0.3]            # turned round
curve = "squared"

[[cc]]
channel = 2
cc = 2
param = "fps"
range = [10.0, 40.0]
curve = "exponential"

[[note]]
channel = 10
note = 36
take = "wave"

[[note]]
channel = 10
note = 38
do = "estop"

[msc]
device = 5
"""


@pytest.fixture
def midi(fed: tuple[Recorder, Feed], tmp_path: Path) -> tuple[Recorder, MidiIn]:
    path = tmp_path / "midi.toml"
    path.write_text(MAP)
    return fed[0], MidiIn(fed[1], path)


def _params(target: Recorder, n: int) -> list[dict[str, float]]:
    assert wait_for(lambda: len(target.of("params")) >= n)
    return target.of("params")  # type: ignore[return-value]


def test_a_control_change_sets_its_parameter_along_its_curve(
        midi: tuple[Recorder, MidiIn]) -> None:
    target, m = midi
    m.feed_bytes(bytes([0xB0, 7, 64]))           # CC 7 = 64 on channel 1
    assert _params(target, 1)[-1] == {"speed": 1.5 * 64 / 127}
    m.feed_bytes(bytes([0xB1, 1, 127]))          # channel 2, the top: the range's end
    assert _params(target, 2)[-1] == {"torso_lean": pytest.approx(-0.3)}
    m.feed_bytes(bytes([0xB1, 1]))               # a message split across two reads
    m.feed_bytes(bytes([32]))
    x = 32 / 127
    assert _params(target, 3)[-1] == {"torso_lean": pytest.approx(0.3 - 0.6 * x * x)}
    m.feed_bytes(bytes([0xB1, 2, 100]))
    assert _params(target, 4)[-1] == {"fps": pytest.approx(10.0 * 4.0 ** (100 / 127))}
    m.feed_bytes(bytes([0xB0, 8, 100]))          # not in the mapping: counted, ignored
    assert wait_for(lambda: m.feed.once.summary().get("unmapped cc") == 1)


def test_a_note_fires_a_take_and_another_the_estop(midi: tuple[Recorder, MidiIn]) -> None:
    target, m = midi
    m.feed_bytes(bytes([0x99, 36, 0]))           # note on, velocity 0: a note off
    m.feed_bytes(bytes([0x89, 36, 64]))          # note off
    m.feed_bytes(bytes([0x99, 36, 100]))         # channel 10, note 36
    assert wait_for(lambda: target.of("act") == [Named("take", "wave")])
    m.feed_bytes(bytes([0x99, 38, 127]))
    assert wait_for(lambda: target.of("estop") == [None])


def _msc(device: int, command: int, cue: str = "") -> bytes:
    """F0 7F <device> 02 <format: 01 lighting> <command> <cue in ASCII> F7 (RP-002)."""
    return bytes([0xF0, 0x7F, device, 0x02, 0x01, command, *cue.encode(), 0xF7])


def test_midi_show_control_go_and_stop(midi: tuple[Recorder, MidiIn]) -> None:
    target, m = midi
    m.feed_bytes(_msc(6, 0x01, "1"))             # another device: not ours
    m.feed_bytes(_msc(5, 0x01, "12.5"))
    m.feed_bytes(_msc(0x7F, 0x01))               # all-call, no number: the next cue
    m.feed_bytes(_msc(5, 0x02))
    m.feed_bytes(_msc(5, 0x03))                  # RESUME: not answered
    assert wait_for(lambda: len(target.of("act")) == 3)
    assert target.of("act") == [Named("cue", "12.5"), Command("go"), Command("stop")]
    assert wait_for(lambda: m.feed.once.summary().get("msc 03") == 1)


def test_learn_binds_the_next_control_and_saves_the_mapping(
        midi: tuple[Recorder, MidiIn]) -> None:
    target, m = midi
    assert m.learn("Wpos_R") == "Apos_R"
    m.feed_bytes(bytes([0xB0, 7, 127]))          # was speed's: now the wrist's
    spec = SPECS["Apos_R"]
    assert _params(target, 1)[-1] == {"Apos_R": spec.hi}
    assert m.learning is None
    saved = load_map(m.path)
    assert saved.cc_for(1, 7) == CcMap(1, 7, "Apos_R", spec.lo, spec.hi, "linear")
    assert saved.note_for(10, 36) is not None and saved.msc_device == 5
    assert len(saved.cc) == 3 and [c.param for c in saved.cc].count("speed") == 0
    with pytest.raises(ConfigError, match="unknown gait parameter 'nope'"):
        m.learn("nope")


@pytest.mark.parametrize(("text", "where"), [
    ("[[cc]]\nchannel = 17\ncc = 1\nparam = 'speed'", "cc[0].channel"),
    ("[[cc]]\nchannel = 1\ncc = 128\nparam = 'speed'", "cc[0].cc"),
    ("[[cc]]\nchannel = 1\ncc = 1\nparam = 'sped'", "cc[0].param"),
    ("[[cc]]\nchannel = 1\ncc = 1\nparam = 'speed'\nrange = [0, 9]", "cc[0].range[1]"),
    ("[[cc]]\nchannel = 1\ncc = 1\nparam = 'speed'\ncurve = 'cubic'", "cc[0].curve"),
    ("[[cc]]\nchannel = 1\ncc = 1\nparam = 'speed'\nrange = [-1, 1]\ncurve = 'exponential'",
     "cc[0].curve"),
    ("[[cc]]\nchannel = 1\ncc = 1\nparam = 'speed'\n[[cc]]\nchannel = 1\ncc = 1\n"
     "param = 'turn'", "cc[1]"),
    ("[[note]]\nchannel = 1\nnote = 60", "note[0]"),
    ("[[note]]\nchannel = 1\nnote = 60\ntake = 'a'\npreset = 'b'", "note[0]"),
    ("[[note]]\nchannel = 1\nnote = 60\ndo = 'jump'", "note[0].do"),
    ("[[note]]\nchannel = 1\nnote = 60\ntake = 'a'\nvelocity = 3", "note[0].velocity"),
    ("[msc]\ndevice = 127", "msc.device"),
    ("[[fader]]\nchannel = 1", "fader"),
])
def test_a_bad_mapping_is_one_line_naming_the_file_and_entry(tmp_path: Path, text: str,
                                                             where: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as e:
        load_map(path)
    line = str(e.value)
    assert "\n" not in line and line.startswith(f"{path}: {where}"), line


def test_every_curve_stays_inside_the_parameter_range() -> None:
    for curve in ("linear", "squared", "sqrt"):
        m = CcMap(1, 1, "speed", -1.0, 1.5, curve)
        values = [m.value(v) for v in range(128)]
        assert values[0] == -1.0 and values[-1] == 1.5
        assert values == sorted(values)
    e = CcMap(1, 1, "fps", 1.0, 100.0, "exponential")
    ratios = [e.value(v + 1) / e.value(v) for v in range(127)]
    assert max(ratios) == pytest.approx(min(ratios)) == pytest.approx(100 ** (1 / 127))
    assert math.isclose(e.value(127), 100.0)
    assert MidiMap().cc_for(1, 1) is None


# ------------------------------------------------------------------------------ cues
def test_a_cue_list_fires_by_name_number_and_in_order(tmp_path: Path) -> None:
    path = tmp_path / "cues.toml"
    path.write_text('[[cue]]\nnumber = "1"\nname = "walk in"\npreset = "walk"\n'
                    '[[cue]]\nnumber = 2\ndo = "start"\n'
                    '[[cue]]\nname = "bow"\npose = "bow"\nlayer = true\n')
    cues = CueList.load(path)
    assert [c.action for c in cues.cues] == [Named("preset", "walk"), Command("start"),
                                             Named("pose", "bow", layer=True)]
    assert cues.go() is cues.cues[0] and cues.go() is cues.cues[1]
    assert cues.find("walk in") is cues.cues[0] and cues.go() is cues.cues[1]
    assert cues.find("bow") is cues.cues[2] and cues.go() is None
    assert cues.find("3") is None


@pytest.mark.parametrize(("text", "where"), [
    ('[[cue]]\npreset = "walk"', "cue[0]: a cue needs a number or a name"),
    ('[[cue]]\nname = "a"\n[[cue]]\nname = "a"\ndo = "stop"', "cue[0]: expected exactly"),
    ('[[cue]]\nname = "a"\ndo = "stop"\n[[cue]]\nname = "a"\ndo = "stop"', "cue[1]: 'a'"),
    ('[[cue]]\nname = "a"\ncue = "b"', "cue[0].cue"),
    ('[[cue]]\nname = "a"\ndo = "stop"\nlayer = true', "cue[0].layer"),
    ('[[cue]]\nname = "a"\ndo = "stop"\ncolour = 1', "cue[0].colour"),
])
def test_a_bad_cue_list_is_one_line(tmp_path: Path, text: str, where: str) -> None:
    path = tmp_path / "cues.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as e:
        CueList.load(path)
    assert str(e.value).startswith(f"{path}: {where}"), str(e.value)
