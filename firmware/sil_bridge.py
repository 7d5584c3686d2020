"""Software in the loop: a node's AVR firmware, run by simavr, on a bus of the 2D simulator.

`SilHost` drives firmware/sil/sil_host (a libsimavr program) over a pipe in AVR
cycles; `SilNode` is a sim2d node (the interface sim2d.sim gives a
behaviours.runtime.Runtime: built as cls(address, transmit, hw, config), then
start(), receive(bus, data), on_echo(bus, sent, heard)) whose behaviour is the
firmware, so sim2d runs it like any Python node:

    from firmware.sil_bridge import sil_factory
    proc = sil_factory()(n.address, hw.transmit, hw, self.config)   # instead of behaviour_class(n.role)(...)

Time: the AVR runs at 16 MHz simulated; its cycle counter is kept in step with
the simulation clock (cycle = t * 16e6). Every SYNC_S the AVR is run up to the
simulation time, but never past the start of a frame that is on its bus, so the
bytes of every received frame reach its UART at the times they cross the wire
(byte i of a frame that started at t0 is handed to the UART at t0 + i char times;
simavr raises RXC one of its character times later). When the firmware starts
transmitting, the AVR runs ahead without input (its receiver is off while DE is
high, hal.h) until it releases the RS-485 driver (PD2); the frame then goes on the
bus at the time of its first byte, or at the latest one sync period later. When
the bus reports an echo that differs from the frame, the bridge sets the
collision-detect latch (PC2) the firmware reads FW_CD_WAIT_MS after the frame;
the next DE rising edge clears it, as the latch on the board does.

Sensors: the firmware asks its sensor front end (hal.h hal_sample, GPIOR0..2 in
simavr) for a conversion; the bridge reads the simulated world through the node's
hardware (sim2d.hardware: sonar_ping, ir_ranges, ...) and answers in the XMIT_DATA
field's raw steps, quantised by behaviours.units as the Python sensors do. The
firmware's debug-port notes (hal_note) become hw.note events, and its debug record
(fw_debug in RAM) is what debug_metrics() reports, as a Python node's would.
"""
from __future__ import annotations

import os
import re
import subprocess
import weakref
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, NamedTuple


from arachnae_proto import frame as proto_frame, messages as proto_messages
from arachnae_proto.enums import RangeStatus
from codegen.load import load_spec

FIRMWARE = Path(__file__).resolve().parent
BUILD = FIRMWARE / "build"
HOST = BUILD / "sil" / "sil_host"
F_CPU = 16_000_000
CARRIER_MARGIN = 0.2      # characters past the first byte's RXC before carrier detect drops
SYNC_S = 0.001            # simulated time between two syncs of the AVR with the simulation
DE_PIN = "D2"             # RS-485 driver enable (avr/hal_avr.c)
TEST_POINT = "B5"         # pulsed by the firmware when it detects a stimulus
INPUT_PINS = ("C0", "C1")  # sensor switches, active low (avr/hal_avr.c)
CD_PIN = "C2"             # collision-detect latch, set on a corrupt echo
CARRIER_PIN = "C3"        # carrier detect: high from another station's start bit to its first byte (hal_avr.c)

AVR_DATA = 0x800000       # avr-gcc's offset of data-space symbols


@lru_cache(maxsize=None)
def hal_enum(prefix: str) -> dict[str, int]:
    """Values of hal.h's enum constants named PREFIX* (one definition, shared with the firmware)."""
    text = (FIRMWARE / "hal.h").read_text()
    out: dict[str, int] = {}
    for body in re.findall(r"enum(?:\s+\w+)?\s*\{([^}]*)\}", text):
        value = -1
        for item in body.split(","):
            m = re.match(r"\s*(\w+)\s*(?:=\s*(0x[0-9A-Fa-f]+|\d+))?\s*$", item)
            if not m:
                continue
            value = int(m.group(2), 0) if m.group(2) else value + 1
            if m.group(1).startswith(prefix):
                out[m.group(1)[len(prefix):]] = value
    return out


@lru_cache(maxsize=None)
def symbol_address(elf: Path, name: str) -> tuple[int, int]:
    """(data-space address, size) of a RAM symbol of the firmware (avr-nm)."""
    out = subprocess.run(["avr-nm", "-S", str(elf)], capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[3] == name:
            return int(parts[0], 16) - AVR_DATA, int(parts[1], 16)
    raise SilError(f"{elf}: no symbol {name}")


# Roles with hand-written firmware behaviour (firmware/nodes/<role>.c), i.e. what --sil accepts.
SIL_ROLES = tuple(sorted(p.stem.upper() for p in (FIRMWARE / "nodes").glob("*.c")))


class SilError(RuntimeError):
    pass


class SilHost:
    """One simavr process running one ELF; all times in AVR cycles."""

    def __init__(self, elf: Path | str, watch: tuple[str, ...] = (DE_PIN, TEST_POINT), host: Path = HOST):
        for p, what in ((Path(host), "the simavr host"), (Path(elf), "the firmware")):
            if not p.exists():
                raise SilError(f"{p}: {what} is not built; run `make -C firmware sil`")
        args = [str(host), "-f", str(F_CPU)]
        for w in watch:
            args += ["-w", w]
        self.proc = subprocess.Popen(args + [str(elf)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1)
        self.cycle = 0
        self._close = weakref.finalize(self, SilHost._stop, self.proc)

    @staticmethod
    def _stop(proc: subprocess.Popen) -> None:
        if proc.poll() is None:
            try:
                proc.stdin.write("q\n")
                proc.stdin.flush()
                proc.wait(timeout=2)
            except (OSError, subprocess.TimeoutExpired):
                proc.kill()
                proc.wait()

    def close(self) -> None:
        self._close()

    def _command(self, line: str) -> list[tuple]:
        """Send one command; return its events up to the closing 'c CYCLE'."""
        try:
            self.proc.stdin.write(line + "\n")
            self.proc.stdin.flush()
        except OSError as exc:
            raise SilError(f"sil_host exited ({exc})") from None
        events: list[tuple] = []
        while True:
            reply = self.proc.stdout.readline()
            if not reply:
                raise SilError(f"sil_host exited with status {self.proc.wait()} after {line!r}")
            kind, *rest = reply.split()
            if kind == "c":
                self.cycle = int(rest[0])
                return events
            if kind == "t":
                events.append(("t", int(rest[0]), int(rest[1], 16)))
            elif kind == "p":
                events.append(("p", int(rest[0]), rest[1], int(rest[2])))
            elif kind == "m":
                events.append(("m", int(rest[0]), int(rest[1])))
            elif kind == "a":
                events.append(("a", int(rest[0]), int(rest[1]), int(rest[2])))
            elif kind == "d":
                events.append(("d", bytes(int(b, 16) for b in rest)))
            elif kind == "x":
                raise SilError(f"the AVR stopped at cycle {rest[0]} (simavr state {rest[1]})")
            else:
                raise SilError(f"sil_host: unexpected line {reply!r}")

    def run(self, cycle: int) -> list[tuple]:
        """Run until `cycle` or the first UART byte / watched pin change, whichever comes first."""
        return self._command(f"r {cycle}")

    def run_until(self, cycle: int) -> list[tuple]:
        events: list[tuple] = []
        while self.cycle < cycle:
            events += self.run(cycle)
        return events

    def inject(self, cycle: int, byte: int) -> None:
        self._command(f"i {cycle} {byte:02x}")

    def set_pin(self, pin: str, value: int) -> None:
        self._command(f"s {pin} {1 if value else 0}")

    def reply(self, values: list[int]) -> None:
        """What the firmware reads next from its sensor port: 16-bit values, little-endian."""
        data = b"".join((v & 0xFFFF).to_bytes(2, "little") for v in values)
        self._command("v " + " ".join(f"{b:02x}" for b in data))

    def read_ram(self, address: int, size: int) -> bytes:
        (_, data), = self._command(f"d {address} {size}")
        return data

    def stack_used(self) -> int:
        """Deepest stack use so far, bytes (RAMEND - lowest SP)."""
        (_, min_sp, ramend), = self._command("m")
        return ramend - min_sp


class SilNode:
    """A sim2d node whose behaviour is the AVR firmware of its role, run in simavr.

    Same interface as a behaviours.runtime.Runtime node as sim2d.sim builds it:
    SilNode(address, transmit, hw, config), start(), receive(bus, data),
    on_echo(bus, sent, heard); `hw` is the node's sim2d.hardware.NodeHardware.
    """

    SCAN_S = 0.02             # input sampling, the Python TPSC's scan period (behaviours.tuning)

    def __init__(self, address: int, transmit: Callable[[str, bytes], None], hw: Any, config: Any = None,
                 elf: Path | str | None = None, sync_s: float = SYNC_S):
        node = hw.node
        if node.role not in SIL_ROLES:
            raise SilError(f"{node.short}: no firmware behaviour for role {node.role} (have: {', '.join(SIL_ROLES)})")
        self.address, self.transmit, self.hw, self.node = address, transmit, hw, node
        self.elf = Path(elf) if elf is not None else BUILD / "avr" / f"{node.role.lower()}.elf"
        self.sync_s = sync_s
        self.bus_name = node.bus
        bus = hw.sim.spec.buses[node.bus]
        self.char_s = bus.bits_per_char / bus.baud
        self.host = SilHost(self.elf)
        self.frames_sent = 0
        self.stimuli = 0
        self.carrier = False      # CARRIER_PIN is high

    # -- time --------------------------------------------------------------
    @property
    def now(self) -> float:
        return self.hw.now()

    def _cycles(self, t: float) -> int:
        return round(t * F_CPU)

    def _time(self, cycle: int) -> float:
        return cycle / F_CPU

    # -- sim2d interface ------------------------------------------------------
    def start(self) -> None:
        self.host.set_pin(CD_PIN, 0)
        self._inputs()
        self.hw.after(self.sync_s, self._sync)
        self.hw.after(self.SCAN_S, self._scan)

    def receive(self, bus: str, data: bytes) -> None:
        """Bytes heard on the bus (the whole frame, at its end): each byte reaches the UART at its time."""
        if not self.hw.alive:
            return
        t0 = self.now - len(data) * self.char_s          # when the frame's first byte started
        self._advance(t0)
        for i, b in enumerate(data):
            self.host.inject(max(self.host.cycle, self._cycles(t0 + i * self.char_s)), b)
        if self.carrier:
            # carrier detect holds until the first byte is in (RXC, one character after the start bit):
            # from then on the UART's gap timer tells the firmware a frame is coming in
            self._advance(t0 + (1 + CARRIER_MARGIN) * self.char_s)
            self.host.set_pin(CARRIER_PIN, 0)
            self.carrier = False

    def on_echo(self, bus: str, sent: bytes, heard: bytes) -> None:
        if self.hw.alive and heard != sent:
            self.host.set_pin(CD_PIN, 1)        # seed 3.2.2: the echo shows the frame was corrupted

    # -- inputs ---------------------------------------------------------------
    def _scan(self) -> None:
        self._inputs()
        self.hw.after(self.SCAN_S, self._scan)

    def _inputs(self) -> None:
        if self.node.role == "TPSC":
            left, right = self.hw.whiskers()
            for pin, touched in zip(INPUT_PINS, (left, right)):
                self.host.set_pin(pin, 0 if touched else 1)      # switches to ground, pull-ups

    # -- keeping the AVR in step ------------------------------------------------
    def _sync(self) -> None:
        if not self.hw.alive:
            self.host.close()
            return
        target = self.now
        port = self.hw.ports.get(self.bus_name)
        starts: list[float] = []
        if port is not None:
            # never run past the start of a frame still on the wire: its bytes arrive at receive()
            starts = [tx.start for tx in port.bus.active if tx.port is not port]
            if starts:
                target = min(target, min(starts))
        self._advance(target)
        if bool(starts) != self.carrier:
            # seed 3.2.2 "when the bus is idle": the firmware senses the start bit (bus.py's carrier
            # sense) instead of starting its own frame before the first byte of this one is in; it drops
            # at the first byte (receive) or, for a frame this node does not hear (lost), at its end
            self.host.set_pin(CARRIER_PIN, 1 if starts else 0)
            self.carrier = bool(starts)
        self.hw.after(self.sync_s, self._sync)

    def _advance(self, t: float) -> None:
        target = self._cycles(t)
        while self.host.cycle < target:
            for ev in self.host.run(target):
                self._event(ev)

    def _event(self, ev: tuple) -> None:
        if ev[0] == "a":
            self._port(ev[2], ev[3], self._time(ev[1]))
        elif ev[0] == "t":
            self._transmit(ev[1], ev[2])
        elif ev[0] == "p" and ev[2] == DE_PIN and ev[3] == 1:
            self.host.set_pin(CD_PIN, 0)
        elif ev[0] == "p" and ev[2] == TEST_POINT and ev[3] == 1:
            self.stimuli += 1
            self.hw.note("stimulus", kind="whisker")

    # -- sensor front end and debug port (hal.h) ----------------------------------
    def _port(self, code: int, arg: int, at: float) -> None:
        """A port request of the firmware made at time `at` (the simulator learns of it up to a sync later)."""
        sample, note = hal_enum("HAL_SAMPLE_"), hal_enum("HAL_NOTE_")
        if code in sample.values():
            self.host.reply(self._sample(next(k for k, v in sample.items() if v == code), arg))
        elif code == note["STIMULUS"]:
            kinds = {v: k.lower() for k, v in hal_enum("HAL_STIMULUS_").items()}
            self.stimuli += 1
            self.hw.note("stimulus", kind=kinds.get(arg, str(arg)))
        elif code == note["ALARM"]:
            self.hw.note("sensor_alarm", node=self.node.short, channels=[c for c in range(16) if arg >> c & 1])
        elif code == note["STATUS"]:
            self.hw.note("sensor_status", node=self.node.short, status=RangeStatus(arg).name)
        elif code == note["REFLEX"]:
            reflex = next(r for r in self.hw.sim.spec.reflexes if r.source == self.node.short)
            self.hw.note("reflex_raised", reflex=reflex.name, at=at)
        else:
            raise SilError(f"{self.node.short}: unknown sensor port request {code:#04x}")

    def _sample(self, kind: str, arg: int) -> list[int]:
        """One conversion of the front end, in the reply field's raw steps (behaviours.units)."""
        q, hw = _quantizers(), self.hw
        if kind == "SONAR":
            metres, dt = hw.sonar_ping(arg)
            return [q["us"].hi if metres is None else q["us"].raw(metres), min(0xFFFF, round(dt * 1e6))]
        if kind == "IR":
            return [q["ir"].hi if m is None else q["ir"].raw(m * 100) for m in hw.ir_ranges()]
        if kind == "INCLINATION":
            return [q["isc"].raw(a) for a in hw.inclination()]
        if kind == "TEMPERATURES":
            temps = hw.temperatures()
            return [len(temps)] + [q["tsc"].raw(c) for c in temps]
        if kind == "LIGHT":
            return [q["lsc"].raw(hw.light())]
        if kind == "BATTERY":
            return [q["psc"].raw(hw.battery())]
        raise SilError(f"{self.node.short}: no front end for {kind}")

    def debug_metrics(self) -> dict:
        """The firmware's debug record (hal.h fw_debug), named as behaviours/sensors.py names them."""
        role = self.node.role
        if role == "TPSC":
            return {}
        address, size = symbol_address(self.elf, "fw_debug")
        raw = self.host.read_ram(address, size)
        names = hal_enum("FW_DBG_")
        dbg = {k.lower(): int.from_bytes(raw[2 * v:2 * v + 2], "little", signed=True)
               for k, v in names.items() if k != "COUNT"}
        out: dict[str, Any] = {"alarms": dbg["alarms"]}
        if role in ("USRC", "IRRC"):
            out.update(status=RangeStatus(dbg["status"]).name, measurements=dbg["measurements"],
                       second_sets=dbg["second_sets"])
        if role == "PSC":
            volts = _quantizers()["psc"].phys
            measured = dbg["mean"] != 0          # raw 0 is outside the voltage field's range: no measurement yet
            out.update({k: round(volts(dbg[n]), 3) if measured else None
                        for k, n in (("mean_v", "mean"), ("mean_min_v", "mean_min"), ("level_min_v", "level_min"))})
        return out

    def _transmit(self, first_cycle: int, first: int) -> None:
        """The firmware started a frame: run it, without input, until it releases the line."""
        frame = bytearray([first])
        quiet = self._cycles(3 * self.char_s * 1.2)       # simavr's characters are 11 bits long
        last = first_cycle
        while len(frame) < 300:
            events = self.host.run(last + quiet)
            done = False
            for ev in events:
                if ev[0] == "t":
                    frame.append(ev[2])
                    last = ev[1]
                elif ev[0] == "p" and ev[2] == DE_PIN and ev[3] == 0:
                    done = True
                else:
                    self._event(ev)
            if done or (not events and self.host.cycle >= last + quiet):
                break
        self.frames_sent += 1
        driven = self._time(first_cycle)
        if driven >= self.now:
            self.hw.after(driven - self.now, self.transmit, self.bus_name, bytes(frame))
        else:   # seen up to a sync period late: the bus judges its carrier sense at the time it drove the line
            self.transmit(self.bus_name, bytes(frame), driven)


@lru_cache(maxsize=None)
def _quantizers() -> dict[str, Any]:
    """The sensors' field conversions (behaviours.units), the front end's transfer functions."""
    from behaviours.units import RECORD_QUANTIZER as Q          # the spec's record_values of each sensor
    return {"us": Q["USRC"], "ir": Q["IRRC"], "isc": Q["ISC"], "tsc": Q["TSC"], "lsc": Q["LSC"], "psc": Q["PSC"]}


def sil_factory(elf: Path | str | None = None, made: list[SilNode] | None = None) -> Callable[..., SilNode]:
    """What sim2d.sim calls instead of behaviour_class(role) for a node run as firmware:
    factory(address, hw.transmit, hw, config); each node made is appended to `made`."""
    def make(address: int, transmit: Callable[[str, bytes], None], hw: Any, config: Any = None) -> SilNode:
        node = SilNode(address, transmit, hw, config, elf)
        if made is not None:
            made.append(node)
        return node
    return make


class RamUse(NamedTuple):
    """simavr's high-water mark of one SIL node's RAM: static data plus the deepest stack seen."""
    node: str
    static: int           # .data + .bss bytes (avr-size)
    stack: int            # RAMEND - lowest SP during the run
    ram: int              # the MCU's SRAM bytes


def static_ram(elf: Path) -> int:
    out = subprocess.run(["avr-size", "-A", str(elf)], capture_output=True, text=True, check=True).stdout
    return sum(int(line.split()[1]) for line in out.splitlines() if line.split()[:1] in ([".data"], [".bss"]))


RAM_BYTES = 2048          # ATmega328P SRAM (the SIL target, avr/hal_avr.c)


def ram_use(nodes: list[SilNode]) -> list[RamUse]:
    """Per SIL node, at the end of a run (its simavr process must still be running)."""
    return [RamUse(n.node.short, static_ram(n.elf), n.host.stack_used(), RAM_BYTES) for n in nodes]


PROBE_GAP_MS = 50         # between two requests of the RAM probe: the reply and the idle gap fit in it


def ram_probe(elf: Path, role: str) -> RamUse:
    """simavr's RAM high-water mark of one role's firmware on its own (`make size`, issue 15 item 4): start-up,
    then every request without fields the role takes from its bus master (INIT, ID_REQ, STATUS_REQ, XMIT_DATA ...),
    each answered, and a whisker contact (the TPSC's DATA_RDY path; other roles leave those inputs alone), one every
    PROBE_GAP_MS; a few hundred simulated milliseconds. The figure is the deepest stack seen plus static RAM: what
    this run reached, a lower bound beside the static call-graph figure of size_report.py."""
    spec = load_spec()
    node = spec.role_nodes(role.upper())[0]
    bus = spec.buses[node.bus]
    master = spec.node(bus.master)
    char = F_CPU * bus.bits_per_char // bus.baud
    gap = F_CPU // 1000 * PROBE_GAP_MS
    requests = [proto_frame.build(node.address, master.address, proto_messages.BY_NAME[m.name]())
                for m in spec.receives(role.upper()) if not m.fields and master.role in m.senders]
    host = SilHost(elf)
    try:
        for pin in INPUT_PINS:
            host.set_pin(pin, 1)            # switches open (active low)
        host.set_pin(CD_PIN, 0)
        host.run_until(gap)
        for data in requests:
            start = host.cycle
            for i, b in enumerate(data):
                host.inject(start + i * char, b)
            host.run_until(start + gap)
        host.set_pin(INPUT_PINS[0], 0)      # a contact on the first input
        host.run_until(host.cycle + gap)
        host.set_pin(INPUT_PINS[0], 1)
        host.run_until(host.cycle + gap)
        return RamUse(role, static_ram(Path(elf)), host.stack_used(), RAM_BYTES)
    finally:
        host.close()


def ram_lines(uses: list[RamUse]) -> list[str]:
    out = ["node   static  stack  high-water  of SRAM"]
    for u in uses:
        out.append(f"{u.node:<6} {u.static:>6} {u.stack:>6} {u.static + u.stack:>11}  {u.ram}")
    return out


def sil_names(args: list[str]) -> list[str]:
    """--sil values: repeated and/or comma lists (USRC,TPSC,IRRC), in order, each once."""
    out: list[str] = []
    for arg in args:
        for name in re.split(r",(?![^()]*\))", arg):      # JAC(1,1) keeps its comma
            name = name.strip()
            if name and name not in out:
                out.append(name)
    return out


def check_sil_nodes(spec: Any, names: list[str]) -> None:
    """One-line errors for --sil arguments (arachnae.errors.UserError)."""
    from arachnae.errors import UserError
    if not names:
        raise UserError("--sil: no node given (e.g. --sil TPSC or --sil USRC,TPSC,IRRC)")
    for name in names:
        node = next((n for n in spec.nodes if n.short == name), None)
        if node is None:
            raise UserError(f"--sil {name}: no such node (e.g. TPSC, JAC(1,1))")
        if node.role not in SIL_ROLES:
            raise UserError(f"--sil {name}: role {node.role} has no firmware (firmware/nodes/: {', '.join(SIL_ROLES)})")
    missing = [p for p in [HOST] + [BUILD / "avr" / f"{n.role.lower()}.elf" for n in spec.nodes if n.short in names]
               if not p.exists()]
    if missing:
        raise UserError(f"--sil: {os.path.relpath(missing[0])} is not built; run `make firmware`")
