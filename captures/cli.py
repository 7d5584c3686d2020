"""`arachnae capture vcd`, `arachnae monitor` and `arachnae replay`: bus captures for other tools and live lines (issue 13)."""
from __future__ import annotations

import argparse
import math
import signal
import sys
import time
from pathlib import Path
from typing import Any

from arachnae.errors import UserError

REPO = Path(__file__).resolve().parent.parent
DECODERS = REPO / "generated" / "sigrok"
REDRAW_S = 0.25                  # the live table's redraw period


def register(sub: Any) -> None:
    cap = sub.add_parser("capture", help="bus captures: convert a run's bus.pcapng")
    csub = cap.add_subparsers(dest="capture_command", metavar="ACTION", parser_class=type(cap))
    csub.required = True
    vcd = csub.add_parser("vcd", help="UART waveforms of the buses as VCD (sigrok-cli -I vcd, PulseView, GTKWave)")
    vcd.add_argument("capture", help="a run folder (its bus.pcapng) or a pcapng file")
    vcd.add_argument("--bus", action="append", default=[], metavar="BUS", help="only this bus (repeatable; default: every bus)")
    vcd.add_argument("--out", help="VCD file to write (default: bus.vcd beside the capture)")
    vcd.set_defaults(func=cmd_vcd)

    mon = sub.add_parser("monitor", help="decode the frames on a serial line or pty live")
    mon.add_argument("port", help="serial device or pty, e.g. /dev/ttyUSB0")
    mon.add_argument("--bus", help="the bus on the line: its baud rate and idle gap (default: the spec's first bus)")
    mon.add_argument("--pcapng", metavar="FILE", help="also write every frame to this new pcapng capture")
    mon.add_argument("--plain", action="store_true",
                     help="one tab-separated line per frame instead of the live table (automatic when stdout is no terminal)")
    mon.add_argument("--count", type=int, metavar="N", help="stop after N frames (default: at Ctrl-C)")
    mon.set_defaults(func=cmd_monitor)

    rep = sub.add_parser("replay", help="play a capture's frames back onto a serial line or pty with their timing")
    rep.add_argument("capture", help="a run folder (its bus.pcapng) or a pcapng file")
    rep.add_argument("port", help="serial device or pty to write to")
    rep.add_argument("--speed", type=float, default=1.0, metavar="X", help="time scale: 2 plays twice as fast (default 1)")
    rep.add_argument("--bus", help="which bus of the capture (needed when it holds several)")
    rep.set_defaults(func=cmd_replay)

    dec = sub.add_parser("decode", help="decode a captured frame given in hex")
    dec.add_argument("hex", nargs="+", help="frame bytes in hex; spaces and colons are ignored")
    dec.add_argument("--own", default=None, metavar="ADDR",
                     help="check the destination against this node address (0x21, 33 or a name such as LCP(1))")
    dec.set_defaults(func=_decode)


# -- shared checks --------------------------------------------------------------------------
def _capture_path(src: str) -> Path:
    p = Path(src)
    pcap = p / "bus.pcapng" if p.is_dir() else p
    if not pcap.is_file():
        raise UserError(f"{pcap}: no such capture")
    return pcap


def _spec_bus(spec: Any, name: str) -> Any:
    if name not in spec.buses:
        raise UserError(f"--bus {name}: not a bus of the spec (one of {', '.join(spec.buses)})")
    return spec.buses[name]


def _capture_buses(cap: Any, spec: Any, pcap: Path, wanted: list[str]) -> list[str]:
    """The wanted buses (all of ours when none is named), each checked against the spec and the capture."""
    ours = [i.name for i in cap.interfaces if i.linktype == spec.frame.pcap_linktype and i.name in spec.buses]
    for name in wanted:
        _spec_bus(spec, name)
        if name not in ours:
            raise UserError(f"{pcap}: has no interface for bus {name}")
    if not ours:
        raise UserError(f"{pcap}: no interface is a bus of the spec with link type {spec.frame.pcap_linktype}")
    return wanted or ours


def _open_port(port: str, baud: int, mode: str) -> Any:
    """A pyserial port at the bus's baud rate (a pty ignores it); a port that will not open is one line."""
    import serial

    try:
        return serial.Serial(port, baudrate=baud, timeout=0, write_timeout=None)
    except (OSError, ValueError) as exc:       # SerialException is an OSError
        raise UserError(f"{port}: cannot open the port for {mode} ({exc})") from None


# -- capture vcd ----------------------------------------------------------------------------
def sigrok_command(vcd: Path, bus: Any) -> str:
    """The sigrok-cli line that decodes one bus of a VCD written here with the generated decoder."""
    return (f"SIGROKDECODE_DIR={DECODERS} sigrok-cli -I vcd -i {vcd} "
            f"-P uart:baudrate={bus.baud}:rx={bus.name},arachnae:bus={bus.name} -A arachnae")


def cmd_vcd(args: argparse.Namespace) -> int:
    from captures.pcapng import read_file
    from arachnae.files import refuse_foreign
    from captures.vcd import VCD_MARK, capture_vcd
    from codegen.load import load_spec

    pcap = _capture_path(args.capture)
    spec = load_spec()
    cap = read_file(pcap)
    names = _capture_buses(cap, spec, pcap, args.bus)
    out = Path(args.out) if args.out else pcap.with_suffix(".vcd")
    if not out.parent.is_dir():
        raise UserError(f"--out {out}: no such folder")
    refuse_foreign(out, VCD_MARK, "`arachnae capture vcd`")
    buses = {n: spec.buses[n] for n in names}
    capture_vcd(out, cap.frames, buses)
    print(f"wrote {out}: {', '.join(names)} ({sum(f.bus in buses for f in cap.frames)} frames)")
    for bus in buses.values():
        print(f"  {sigrok_command(out, bus)}")
    return 0


# -- monitor --------------------------------------------------------------------------------
def _stop_on_signals() -> tuple[list[bool], dict]:
    """Ctrl-C (and SIGTERM) set a flag the read loop checks: the frame being handled is finished first."""
    stop = [False]

    def handler(signum, frame):
        stop[0] = True

    old = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    return stop, old


def cmd_monitor(args: argparse.Namespace) -> int:
    from captures.decode import decode
    from captures.monitor import LiveTable, MonitorStats, Recorder, frames_from, plain_line
    from codegen.load import load_spec

    spec = load_spec()
    bus = _spec_bus(spec, args.bus) if args.bus else next(iter(spec.buses.values()))
    if args.count is not None and args.count < 1:
        raise UserError(f"--count: expected a number of frames >= 1, got {args.count}")
    pcap_out = None
    if args.pcapng:
        target = Path(args.pcapng)
        if not target.parent.is_dir():
            raise UserError(f"--pcapng {target}: no such folder")
        try:
            pcap_out = open(target, "xb")         # never over a user's file
        except FileExistsError:
            raise UserError(f"--pcapng {target}: exists already; name a new file") from None
        except OSError as exc:
            raise UserError(f"--pcapng {target}: cannot write ({exc.strerror or exc})") from None
    try:
        port = _open_port(args.port, bus.baud, "reading")
    except UserError:
        if pcap_out is not None:
            pcap_out.close()
            Path(args.pcapng).unlink()            # ours, just created and still empty
        raise
    recorder = Recorder(pcap_out, spec, bus.name) if pcap_out is not None else None
    plain = args.plain or not sys.stdout.isatty()
    stats = MonitorStats()
    gap_s = bus.idle_gap_us * 1e-6              # seed 3.2.2: the idle gap ends a frame
    sys.stderr.write(f"monitoring {args.port}: bus {bus.name}, {bus.baud} baud, idle gap {gap_s * 1e3:.2f} ms"
                     + (f", capture {args.pcapng}" if recorder else "") + "; Ctrl-C ends\n")
    sys.stderr.flush()
    stop, old = _stop_on_signals()
    live = None
    lost = None
    try:
        if not plain:
            from rich.live import Live

            live = Live(LiveTable(stats, f"{args.port} ({bus.name}, {bus.baud} baud)"), auto_refresh=False,
                        redirect_stderr=False)
            live.start()
        t0_ns = time.time_ns()
        drawn = 0.0
        done = lambda: stop[0] or (args.count is not None and stats.frames >= args.count)  # noqa: E731
        try:
            for raw in frames_from(port, spec, gap_s, done):
                d = decode(raw.data)
                stats.add(d, raw.data, time.monotonic())
                if recorder is not None:
                    recorder.write(raw)
                if plain:
                    print(plain_line(raw, d, bus.name, t0_ns), flush=True)
                elif time.monotonic() - drawn >= REDRAW_S:
                    live.refresh()
                    drawn = time.monotonic()
                if done():
                    break
        except OSError as exc:                  # the adapter went away: keep what was seen
            lost = exc
    finally:
        if live is not None:
            live.refresh()
            live.stop()
        for s, h in old.items():
            signal.signal(s, h)
        port.close()
        if pcap_out is not None:
            pcap_out.close()
    sys.stderr.write("\n".join(stats.summary(time.monotonic())
                               + ([f"capture written to {args.pcapng}"] if recorder else [])) + "\n")
    if lost is not None:
        raise UserError(f"{args.port}: line lost ({lost})")
    return 0


# -- replay ---------------------------------------------------------------------------------
def cmd_replay(args: argparse.Namespace) -> int:
    from captures.pcapng import read_file
    from captures.replay import replay
    from codegen.load import load_spec

    if not (args.speed > 0 and math.isfinite(args.speed)):
        raise UserError(f"--speed: expected a factor > 0, got {args.speed}")
    pcap = _capture_path(args.capture)
    spec = load_spec()
    cap = read_file(pcap)
    names = _capture_buses(cap, spec, pcap, [args.bus] if args.bus else [])
    if len(names) > 1:
        raise UserError(f"{pcap}: holds the buses {', '.join(names)}; choose one with --bus")
    bus = spec.buses[names[0]]
    frames = [f for f in cap.frames if f.bus == bus.name]
    port = _open_port(args.port, bus.baud, "writing")
    started = time.monotonic()
    try:
        sent = replay(port, frames, bus, args.speed)
    except OSError as exc:
        raise UserError(f"{args.port}: write failed ({exc})") from None
    finally:
        port.close()
    print(f"replayed {sent} frames of bus {bus.name} onto {args.port} in {time.monotonic() - started:.1f} s")
    return 0


# -- decode: one frame given in hex ------------------------------------------------------------
def _decode(args: argparse.Namespace) -> int:
    text = "".join(args.hex).replace(":", "").replace(" ", "")
    if text.lower().startswith("0x"):
        text = text[2:]
    try:
        data = bytes.fromhex(text)
    except ValueError:
        raise UserError(f"decode: '{' '.join(args.hex)}' is not a hex string") from None
    from arachnae_proto import CodecError, frame
    from arachnae_proto.network import name_of

    own = _node_address(args.own) if args.own is not None else None
    try:
        f = frame.parse(data, own)      # size, checksum, address, route (seed 3.2.1), message
        frame.check_roles(f)            # and the sender's and receiver's roles (spec messages.yaml from/to)
    except CodecError as err:
        raise UserError(f"decode: {err.kind.name}: {err}") from None
    m = f.message
    print(f"{name_of(f.src)} -> {name_of(f.dst)}  {m.NAME} (opcode 0x{m.OPCODE:02X}, seed {m.SECTION})")
    for info in m.FIELDS:
        print(f"  {info.name:14} {info.describe(getattr(m, info.name))}")
    sys.stdout.flush()
    return 0


def _node_address(text: str) -> int:
    """--own: a node's address (0x21, 33) or short name (LCP(1)); broadcast and unknown addresses are refused."""
    from arachnae_proto.network import ADDRESS_OF, NODE_ADDRESSES

    if text in ADDRESS_OF:
        return ADDRESS_OF[text]
    try:
        value = int(text, 0)
    except ValueError:
        raise UserError(f"decode: --own {text!r}: expected a node address such as 0x21 or a node name "
                        "such as LCP(1) (`arachnae spec nodes` lists them)") from None
    if value not in NODE_ADDRESSES:
        raise UserError(f"decode: --own {text}: not a node address "
                        "(`arachnae spec nodes` lists them)")
    return value

