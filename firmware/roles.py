"""Build configuration of the firmware, derived from the spec (used by firmware/Makefile).

    python firmware/roles.py list                 roles, lower case, one a line
    python firmware/roles.py msgs ROLE            the generated msg_*.c this role sends or receives
    python firmware/roles.py config ROLE OUT.h    bus timing and addresses of ROLE as #defines
    python firmware/roles.py stubs OUTDIR         empty behaviours for every role (size images, fuzzing)
    python firmware/roles.py mk OUT.mk            ROLES and MSGS_<role> for make
    python firmware/roles.py fuzzroles OUT.h      every role's check and dispatch, for fuzz/fuzz_frame.c

The generated C has no per-bus timing constants (baud, turnaround, idle gap,
backoff slot), so the firmware build derives them here from the same model the
generator reads; nothing is typed in by hand.
"""
from __future__ import annotations

import math
import re
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
GEN_C = REPO / "generated" / "c"


def _spec():
    from codegen.load import load_spec
    return load_spec()


def msg_file(name: str) -> str:
    return f"msg_{name.lower()}.c"


def role_msgs(spec, role: str) -> list[str]:
    """The message files of every message the role sends or receives (docs/decisions.md D2: nothing else is linked)."""
    names = {m.name for m in spec.sends(role)} | {m.name for m in spec.receives(role)}
    return sorted(msg_file(n) for n in names)


def find_role(spec, name: str) -> str:
    for r in spec.roles:
        if r.lower() == name.lower():
            return r
    raise SystemExit(f"roles.py: unknown role {name!r} (known: {', '.join(r.lower() for r in spec.roles)})")


def role_config(spec, role: str) -> str:
    """#defines for one role's firmware: its first node's address, bus timing, backoff rank and slot."""
    node = spec.role_nodes(role)[0]
    lines = [
        f"/* Build configuration of role {role}, derived from the spec by firmware/roles.py. */",
        f"#ifndef FW_ROLE_CONFIG_H",
        f"#define FW_ROLE_CONFIG_H",
        f"#define FW_OWN_ADDRESS 0x{node.address:02X}u /* {node.short} */",
    ]
    if node.bus is not None:
        from behaviours.netconfig import NetConfig
        from behaviours.runtime import BusTiming, arbitration_rank
        bus = spec.buses[node.bus]
        master = spec.node(bus.master)
        net = NetConfig.from_spec(spec)
        t = BusTiming(node.bus)       # the Python runtime's own figures: one formula for both
        rank = arbitration_rank(net, node.bus, node.address)
        lines += [
            f"/* bus {bus.name}: {bus.long}, seed {bus.section} */",
            f"#define FW_BAUD {bus.baud}UL",
            f"#define FW_BITS_PER_CHAR {bus.bits_per_char}u",
            f"#define FW_CHAR_US {round(t.char_s * 1e6)}UL",
            f"#define FW_TURNAROUND_US {round(t.turnaround_s * 1e6)}UL",
            f"#define FW_IDLE_GAP_US {round(bus.idle_gap_us)}UL /* {bus.idle_gap_chars} characters */",
            f"#define FW_MASTER_ADDRESS 0x{master.address:02X}u /* {master.short} */",
            f"/* spec arbitration address_backoff: after a corrupt echo wait (rank + 1) slots, rank in rank_order */",
            f"#define FW_BACKOFF_RANK {rank}u",
            f"#define FW_BACKOFF_SLOT_US {round(t.slot_s * 1e6)}UL",
        ]
        lines += slave_timing(net, node, t, rank)
    else:
        own = spec.buses[node.masters]    # the MCP is no slave: the line it runs is the bus it masters
        lines += [f"/* bus {own.name} (mastered), seed {own.section} */", f"#define FW_BAUD {own.baud}UL",
                  f"#define FW_BITS_PER_CHAR {own.bits_per_char}u", f"#define FW_CHAR_US {round(own.char_time_us)}UL",
                  f"#define FW_TURNAROUND_US {round(own.turnaround_us)}UL",
                  f"#define FW_IDLE_GAP_US {round(own.idle_gap_us)}UL /* {own.idle_gap_chars} characters */",
                  "#define FW_MASTER_ADDRESS 0x00u", "#define FW_BACKOFF_RANK 0u", "#define FW_BACKOFF_SLOT_US 0UL",
                  "#define FW_QUIET_AFTER_MASTER_US 0UL", "#define FW_QUIET_AFTER_OTHER_US 0UL",
                  "#define FW_QUIET_IN_WINDOW_US 0UL", "#define FW_REQUEST_OPCODE 0x00u", "#define FW_BACKOFF_SCOPE_ALL 0u", "#define FW_BACKOFF_STEP_US 0UL",
                  "#define FW_REQUESTERS 0u"]
    lines += tuning(role) + alarm_limit(role)
    tx_max = spec.frame.overhead + max((m.max_size for m in spec.sends(role)), default=0)
    char_us = spec.buses[node.bus or node.masters].char_time_us
    low = role.lower()
    lines += [
        "#ifndef FW_BASELINE  /* the hand-written baseline uses no generated code */",
        f'#include "node_{low}.h"',
        f"#define FW_ROLE_NODE {low}_node",
        f"#define FW_ROLE_INIT {low}_node_init",
        f"#define FW_ROLE_RX {low}_rx",
        f"#define FW_ROLE_RX_INIT {role.upper()}_RX_INIT",
        f"#define FW_ROLE_RX_FEED {low}_rx_feed",
        f"#define FW_ROLE_RX_GAP {low}_rx_gap",
        f"#define FW_ROLE_RX_FRAME {low}_rx_frame",
        f"#define FW_ROLE_DISPATCH {low}_dispatch",
        f"#define FW_RX_MAX ARACHNAE_RX_MAX_{role}",
        "#endif",
        f"#define FW_TX_MAX {tx_max}u /* largest frame the role sends */",
        "/* the collision latch is read two characters + 2 ms after the line is released:",
        "   the echo's last character is through, and a simulator's sync step fits too */",
        f"#define FW_CD_WAIT_MS {math.ceil((2 * char_us + 2000) / 1000)}u",
        "#endif", ""]
    return "\n".join(lines)


def slave_timing(net, node, t, rank: int) -> list[str]:
    """When a slave of the bus may start a frame of its own (DATA_RDY): the figures of behaviours/runtime.py
    (slave_quiet for Runtime._slave_start, the window of _backoff_wait), computed by it, for the firmware."""
    from behaviours.runtime import slave_quiet
    bus = node.bus
    reflex = net.reflex_from(node.address)
    quiet = slave_quiet(t, net, rank, reflex is not None)
    scope_all = net.arbitration.get(bus) == "address_backoff" and net.backoff_scope == "all"
    interval = [] if reflex is None else [
        "/* spec reflexes (seed 5.2): this node raises a reflex request at most this often */",
        f"#define FW_REFLEX_MIN_INTERVAL_MS {math.ceil(reflex.min_interval_s * 1000)}u"]
    opcode = net.request_opcodes.get(bus, 0)
    return interval + [
        "/* seed 3.2.2 'when the bus is idle': the line quiet this long before a DATA_RDY, by what it carried last",
        "   (behaviours.runtime.slave_quiet: rank stagger and reflex lead included) */",
        f"#define FW_QUIET_AFTER_MASTER_US {math.ceil(quiet.after_master * 1e6)}UL",
        f"#define FW_QUIET_AFTER_OTHER_US {math.ceil(quiet.after_other * 1e6)}UL",
        f"#define FW_QUIET_IN_WINDOW_US {math.ceil(quiet.in_window * 1e6)}UL",
        "/* spec arbitration request_message: frames other than requests do not use up the window's idle slots */",
        f"#define FW_REQUEST_OPCODE 0x{opcode:02X}u",
        "/* spec address_backoff, scope all: after any corrupt frame, wait for our slot of the window */",
        f"#define FW_BACKOFF_SCOPE_ALL {1 if scope_all else 0}u",
        f"#define FW_BACKOFF_STEP_US {round(net.backoff_slots * t.slot_s * 1e6)}UL",
        f"#define FW_REQUESTERS {len(net.requesters.get(bus, ()))}u",
    ]


def alarm_limit(role: str) -> list[str]:
    """Whether the SET_ALARM limit's raw value IS the data field's raw value (behaviours.sensors.limit_in is the
    identity over the limit's whole raw range): then the firmware compares it as it comes, without linking the
    physical conversions (LSC: a log table); else it converts through the generated _to_milli/_from_milli."""
    from arachnae_proto import messages as M
    if role not in M.ALARM_THRESHOLDS:
        return []
    from behaviours.sensors import limit_in
    from behaviours.units import values_quantizer
    a = M.ALARM_THRESHOLDS[role]           # the spec's threshold and the record values it is compared with
    info = next(f for f in a.message.FIELDS if f.name == a.limit)
    lo, hi = info.conv.lo, info.conv.hi
    data = values_quantizer(a.data)
    same = all(limit_in(data, a.message, r) == r for r in range(lo, hi + 1))
    return [f"/* {a.message.NAME}.{a.limit} raw {lo}..{hi} equals the {'/'.join(a.data.fields)} raw value for every "
            f"value (checked by roles.py) */", f"#define FW_ALARM_LIMIT_IS_DATA_RAW {1 if same else 0}"]


def tuning(role: str) -> list[str]:
    """The behaviour's own numbers for this role (behaviours/tuning.py, CHOICE): seconds as milliseconds."""
    from behaviours import tuning as T
    out = ["/* behaviours/tuning.py (CHOICE, not protocol): the same numbers as the Python behaviour */"]
    names = sorted(n for n in vars(T) if n.startswith(f"{role}_") or n.startswith("SENSOR_"))
    for n in names:
        v = getattr(T, n)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            continue
        if n.endswith("_S"):
            out.append(f"#define TUNING_{n[:-2]}_MS {round(v * 1000)}u")
        elif n.endswith("_M"):
            out.append(f"#define TUNING_{n}M {round(v * 1000)}")
        elif isinstance(v, int):
            out.append(f"#define TUNING_{n} {v}")
    if role in T.ALARM_REARM_RAW:
        out.append(f"#define TUNING_ALARM_REARM_RAW {T.ALARM_REARM_RAW[role]}")
    return out


_PROTO = re.compile(r"^(void|arachnae_status|uint8_t)\s+(\w+)\((.*)\);$")


def stub_source(role: str) -> str:
    """Empty definitions of the callbacks node_<role>.h asks the behaviour for."""
    header = (GEN_C / f"node_{role.lower()}.h").read_text()
    part = header.split("---- defined by the behaviour ----", 1)[1]
    joined = re.sub(r",\n\s+", ", ", part)     # prototypes may wrap after a comma
    out = [f"/* Empty behaviour of role {role} (size images and fuzzing only; built by firmware/roles.py). */",
           f'#include "node_{role.lower()}.h"', ""]
    for line in joined.splitlines():
        m = _PROTO.match(line.strip())
        if not m:
            continue
        ret, name, args = m.groups()
        params = [a.strip().split()[-1].lstrip("*") for a in args.split(",") if a.strip() and a.strip() != "void"]
        body = "".join(f" (void){p};" for p in params)
        if ret == "arachnae_status":
            body += " return ARACHNAE_OK;"
        elif ret == "uint8_t":
            body += " return 0;"   # a request's callback: no reply now
        out.append(f"{ret} {name}({args}) {{{body} }}")
    return "\n".join(out) + "\n"


def fuzz_roles(spec) -> str:
    out = ["/* Every role's payload check, dispatch and parser (built by firmware/roles.py fuzzroles). */",
           "#include <string.h>"]
    out += [f'#include "node_{r.lower()}.h"' for r in spec.roles]
    out += ["", "typedef struct {", "    const char *name;",
            "    arachnae_payload_check_fn check;",
            "    /* NONE if `own` is not an address of the role, else the dispatch status of a frame the",
            "     * role's parser passed (dispatch takes only those: it does not check again, issue 15), OK for NULL */",
            "    arachnae_status (*dispatch)(uint8_t own, const uint8_t *frame);",
            "    uint16_t rx_max;   /* the role parser's buffer: ARACHNAE_RX_MAX_<role> */",
            "    /* the role's own parser (<role>_rx_feed/_gap) over one burst: its verdict as fuzz_frame.c's",
            "     * parse_burst gives it; an OK frame is copied to `out` (rx_max bytes), its length to *out_len */",
            "    arachnae_status (*rx)(uint8_t own, const uint8_t *data, uint16_t len, uint8_t *out, uint16_t *out_len);",
            "} fz_role;", ""]
    for r in spec.roles:
        low = r.lower()
        out += [f"static arachnae_status fz_dispatch_{low}(uint8_t own, const uint8_t *frame)", "{",
                f"    {low}_node node;",
                f"    if ({low}_node_init(&node, own, 0) != ARACHNAE_OK)",
                "        return ARACHNAE_NONE;",
                "    if (frame == 0)",
                "        return ARACHNAE_OK;   /* only asked whether own is an address of the role */",
                f"    return {low}_dispatch(&node, frame);", "}", "",
                f"static arachnae_status fz_rx_{low}(uint8_t own, const uint8_t *data, uint16_t len, uint8_t *out, uint16_t *out_len)",
                "{",
                f"    {low}_rx p = {r.upper()}_RX_INIT(own);",
                "    arachnae_status verdict = ARACHNAE_NONE, st;",
                "    const uint8_t *f;",
                "    uint16_t i;",
                "    (void)own;",
                "    for (i = 0; i < len; i++)",
                f"        if ((st = {low}_rx_feed(&p, data[i])) != ARACHNAE_NONE)",
                "            verdict = st;",
                f"    st = {low}_rx_gap(&p);",
                "    if (verdict == ARACHNAE_NONE)",
                "        verdict = st;",
                f"    f = {low}_rx_frame(&p, out_len);",
                "    if ((verdict == ARACHNAE_OK) != (f != 0))",
                "        return ARACHNAE_NONE;   /* frame() disagrees with the verdict: never a parser's answer */",
                "    if (f != 0)",
                "        memcpy(out, f, *out_len);",
                "    return verdict;", "}", ""]
    out += [f"static const fz_role fz_roles[{len(spec.roles)}] = {{"]
    out += [f'    {{"{r}", {r.lower()}_payload_check, fz_dispatch_{r.lower()}, ARACHNAE_RX_MAX_{r.upper()}, fz_rx_{r.lower()}}},'
            for r in spec.roles]
    out += ["};", ""]
    return "\n".join(out)


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    cmd, rest = argv[0], argv[1:]
    spec = _spec()
    if cmd == "list":
        print("\n".join(r.lower() for r in spec.roles))
    elif cmd == "msgs" and len(rest) == 1:
        print(" ".join(role_msgs(spec, find_role(spec, rest[0]))))
    elif cmd == "config" and len(rest) == 2:
        Path(rest[1]).parent.mkdir(parents=True, exist_ok=True)
        Path(rest[1]).write_text(role_config(spec, find_role(spec, rest[0])))
    elif cmd == "stubs" and len(rest) == 1:
        out = Path(rest[0])
        out.mkdir(parents=True, exist_ok=True)
        for r in spec.roles:
            (out / f"stub_{r.lower()}.c").write_text(stub_source(r))
    elif cmd == "mk" and len(rest) == 1:
        lines = [f"ROLES := {' '.join(r.lower() for r in spec.roles)}"]
        lines += [f"MSGS_{r.lower()} := {' '.join(role_msgs(spec, r))}" for r in spec.roles]
        Path(rest[0]).parent.mkdir(parents=True, exist_ok=True)
        Path(rest[0]).write_text("\n".join(lines) + "\n")
    elif cmd == "fuzzroles" and len(rest) == 1:
        Path(rest[0]).parent.mkdir(parents=True, exist_ok=True)
        Path(rest[0]).write_text(fuzz_roles(spec))
    else:
        print(f"roles.py: bad arguments {' '.join(argv)!r}; see the docstring", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
