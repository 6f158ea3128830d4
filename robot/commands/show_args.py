"""Show-control options of `biped panel` and `biped play` (docs/show-control.md): OSC in
and status out, a cue list, MIDI in (the panel). ``show_options`` checks them all before
anything moves: a bad address, allow-list, cue list or mapping file is one line, exit 2."""

from __future__ import annotations

import argparse
from pathlib import Path

from robot.commands.common import rate_hz
from robot.showctl.cues import CueList
from robot.showctl.midi_map import load_map
from robot.showctl.options import MidiOptions, OscOptions, ShowOptions
from robot.showctl.osc_out import REPLY_HZ
from robot.showctl.sources import Sources, host_port


def _port(text: str) -> int:
    if not text.isdigit() or not 0 <= int(text) <= 65535:
        raise argparse.ArgumentTypeError(f"expected a UDP port number in [0, 65535], got "
                                         f"{text!r}")
    return int(text)


def add_show_args(p: argparse.ArgumentParser, *, midi: bool = True) -> None:
    g = p.add_argument_group("show control (docs/show-control.md)")
    g.add_argument("--osc", type=_port, default=None, metavar="PORT",
                   help="listen for OSC on this UDP port (/biped/...: parameters, start, "
                        "stop, estop, presets, takes, cues, poses)")
    g.add_argument("--osc-host", default="127.0.0.1", metavar="ADDR",
                   help="address OSC listens on (default: %(default)s; beyond loopback "
                        "needs --osc-allow: OSC has no authentication)")
    g.add_argument("--osc-allow", default=None, metavar="ADDRS",
                   help="senders OSC obeys beyond loopback: addresses or networks, comma "
                        "separated (192.168.1.20,10.0.0.0/24)")
    g.add_argument("--osc-reply", default=None, metavar="HOST:PORT",
                   help="send status over OSC there (state, fault, show clock, joints)")
    g.add_argument("--osc-reply-hz", type=rate_hz, default=REPLY_HZ, metavar="HZ",
                   help="status messages per second (default: %(default)g)")
    g.add_argument("--cues", default=None, metavar="FILE",
                   help="a cue list (TOML) for /biped/cue, /biped/go and MIDI Show Control")
    if midi:
        g.add_argument("--midi", default=None, metavar="PORT",
                       help="MIDI input port by name, or socket:HOST:PORT (needs the midi "
                            "extra)")
        g.add_argument("--midi-map", default=None, metavar="FILE",
                       help="MIDI mapping (TOML; learn writes it; default: midi.toml in "
                            "the studio directory)")


def show_options(args: argparse.Namespace, *, studio_dir: Path | None = None) -> ShowOptions:
    """The options as objects, every file read and checked (ConfigError, one line)."""
    osc = None
    if args.osc is not None:
        reply = host_port(args.osc_reply, flag="--osc-reply") if args.osc_reply else None
        osc = OscOptions(port=args.osc, host=args.osc_host,
                         sources=Sources.parse(args.osc_allow, host=args.osc_host),
                         reply=reply, reply_hz=args.osc_reply_hz)
    midi = None
    port = getattr(args, "midi", None)
    map_arg = getattr(args, "midi_map", None)
    if port is not None or map_arg is not None:
        path = Path(map_arg) if map_arg else (studio_dir or Path(".")) / "midi.toml"
        mapping = load_map(path)
        if port is not None:
            midi = MidiOptions(port=port, map_path=path, mapping=mapping)
    cues = CueList.load(Path(args.cues)) if args.cues else None
    return ShowOptions(osc=osc, midi=midi, cues=cues)
