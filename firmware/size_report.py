"""Flash, RAM and stack of every role's firmware image on AVR and Cortex-M0 (`make -C firmware size`).

Sizes come from the linker map of each image (firmware/build/<target>/<role>.map), so
they count only what --gc-sections kept, split by where it came from:
    codec      generated/c arachnae_frame.c, log10_*.c and the role's msg_*.c
    skeleton   generated/c node_<role>.c
    firmware   main.c, the board HAL and the behaviour (or an empty stub)
    runtime    C start-up, libgcc, libc, vector table
Stack: worst case over the static call graph (objdump calls + -fstack-usage frames, plus
the return address each call pushes), deepest path first; the generic parser's one indirect call
is resolved to the role's payload check. parse = the RX interrupt's parser path (<role>_rx_feed), dispatch = the
skeleton without the behaviour, node = main with all it calls plus the deepest interrupt.
Issue 15: the budgets (a sensor role in 1 KiB, any role in 2 KiB, the TPSC within 1.5x of the
hand-written baseline) and, with --nanopb, nanopb's codec bytes for the same roles beside ours.
Writes build/size.json; prints the tables. Exit 1 if the codec has data or bss of
its own or an image could not be analysed (a budget overrun is reported, tests/firmware
test_size.py holds the limits).
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from firmware.sil_bridge import PROBE_GAP_MS, SilError, ram_probe  # noqa: E402  (run as a script from firmware/)

SENSOR_ROLES = ("usrc", "tpsc", "irrc", "isc", "tsc", "lsc", "psc")
AVR_FLASH_BUDGET = 2048          # issue 6: codec + skeleton of any role in 2 KiB of AVR flash
SENSOR_FLASH_BUDGET = 1024       # issue 15: a sensor role's codec + skeleton in 1 KiB
BASELINE_RATIO = 1.5             # issue 15: a role within 1.5x of its hand-written baseline
TOOLS = {"avr": ("avr-objdump", 2), "m0": ("arm-none-eabi-objdump", 0)}   # objdump, bytes a call pushes

FLASH_SECTIONS = (".text", ".rodata", ".progmem", ".isr_vector", ".vectors", ".init", ".fini", ".trampolines", ".ctors", ".dtors", ".jumptables")


@dataclass
class Part:
    text: int = 0
    data: int = 0
    bss: int = 0

    def add(self, kind: str, n: int) -> None:
        setattr(self, kind, getattr(self, kind) + n)

    @property
    def flash(self) -> int:
        return self.text + self.data


@dataclass
class Image:
    role: str
    target: str
    parts: dict[str, Part] = field(default_factory=lambda: {k: Part() for k in ("codec", "skeleton", "firmware", "runtime")})
    stack: dict[str, int] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    messages: Part = field(default_factory=Part)     # the codec's msg_*.o only (per-message code)
    sim_ram: int | None = None    # simavr high-water mark (static + deepest stack seen), --sil-ram roles only

    @property
    def total(self) -> Part:
        t = Part()
        for p in self.parts.values():
            t.text, t.data, t.bss = t.text + p.text, t.data + p.data, t.bss + p.bss
        return t


def category(obj: str, role: str) -> str:
    name = Path(obj).name
    if "/nanopb/" in obj:        # nanopb runtime and the role's .pb.c; the driver is the firmware
        return "firmware" if name.startswith("npb_") else "codec"
    if "/gen/" in obj:
        return "skeleton" if name == f"node_{role}.o" else "codec"
    if "/baseline/" in obj:      # the hand-written protocol code stands in for codec + skeleton
        return "codec" if name.endswith("_proto.o") or name == "bl_frame.o" else "firmware"
    if "/fw/" in obj:
        return "firmware"
    return "runtime"


_IN = re.compile(r"^ (\S+)\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+)$")
_IN_NAME = re.compile(r"^ (\S+)$")
_IN_REST = re.compile(r"^\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+)$")
_OUT = re.compile(r"^(\.\S+)\s")


def kind_of(out_section: str) -> str | None:
    if out_section in (".bss", ".noinit") or out_section.startswith(".bss"):
        return "bss"
    if out_section == ".data":
        return "data"
    if any(out_section.startswith(s) for s in FLASH_SECTIONS):
        return "text"
    return None       # debug, comment, eeprom, fuse ...


def parse_map(path: Path, image: Image) -> None:
    lines = path.read_text().splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("Linker script and memory map"))
    out_section = ""
    pending: str | None = None
    for line in lines[start + 1:]:
        m = _OUT.match(line)
        if m:
            out_section = m.group(1)
            continue
        m = _IN.match(line)
        if m:
            sec, size, obj = m.group(1), int(m.group(3), 16), m.group(4)
        elif pending is not None and _IN_REST.match(line):
            mm = _IN_REST.match(line)
            sec, size, obj = pending, int(mm.group(2), 16), mm.group(3)
        else:
            mm = _IN_NAME.match(line)
            pending = mm.group(1) if mm and not line.strip().startswith(("0x", "*", "LOAD", "KEEP")) else None
            continue
        pending = None
        kind = kind_of(out_section)
        if kind is None or size == 0 or sec.startswith("*"):
            continue
        image.parts[category(obj, image.role)].add(kind, size)
        if "/gen/" in obj and Path(obj).name.startswith("msg_"):
            image.messages.add(kind, size)


# ---- stack --------------------------------------------------------------------------
_FUNC = re.compile(r"^[0-9a-f]+ <([^>]+)>:$")
_AVR_CALL = re.compile(r"\t(r?call|r?jmp)\t.*<([^>+]+)>$")
_ARM_CALL = re.compile(r"\t(bl|b|b\.n|b\.w)\t[0-9a-f]+ <([^>+]+)>$")
_INDIRECT = re.compile(r"\t(icall|eicall|blx\tr\d+|bx\tr[0-9]\b)")


def call_graph(elf: Path, target: str) -> tuple[dict[str, set[str]], dict[str, bool]]:
    """callee sets and 'has an indirect call' per function, from the disassembly."""
    tool = TOOLS[target][0]
    text = subprocess.run([tool, "-d", str(elf)], check=True, capture_output=True, text=True).stdout
    calls: dict[str, set[str]] = {}
    indirect: dict[str, bool] = {}
    cur = None
    pat = _AVR_CALL if target == "avr" else _ARM_CALL
    for line in text.splitlines():
        m = _FUNC.match(line)
        if m:
            cur = m.group(1)
            calls.setdefault(cur, set())
            indirect.setdefault(cur, False)
            continue
        if cur is None:
            continue
        m = pat.search(line)
        if m and m.group(2) != cur:
            calls[cur].add(m.group(2))
        if _INDIRECT.search(line):
            indirect[cur] = True
    return calls, indirect


def frames(build: Path, target: str, role: str) -> dict[str, int]:
    """-fstack-usage frame of every function compiled into this image's objects."""
    out: dict[str, int] = {}
    dirs = [build / target / "gen", build / target / role, build / target / "baseline"]
    for d in dirs:
        for su in d.rglob("*.su"):
            for line in su.read_text().splitlines():
                loc, size, _kind = line.rsplit("\t", 2)
                out[loc.rsplit(":", 1)[-1]] = max(out.get(loc.rsplit(":", 1)[-1], 0), int(size))
    return out


def worst(fn: str, calls, indirect, frame, resolve: dict[str, str], push: int, stop: set[str],
          notes: list[str], seen: tuple[str, ...] = ()) -> int:
    if fn in seen:
        notes.append(f"recursion through {fn}")
        return 0
    if fn in stop:
        return 0
    own = frame.get(fn)
    if own is None:     # clones: objdump says send.isra.0 where the .su file says send.isra
        own = next((v for k, v in frame.items() if k.split(".")[0] == fn.split(".")[0]), None)
    if own is None:
        own = 0
        if calls.get(fn):
            notes.append(f"no stack figure for {fn}")
    callees = set(calls.get(fn, ()))
    if indirect.get(fn):
        if fn in resolve:
            callees.add(resolve[fn])
        elif fn.startswith("__vector") or fn in ("__do_copy_data", "__do_clear_bss"):
            pass
        else:
            notes.append(f"unresolved indirect call in {fn}")
    deepest = max((worst(c, calls, indirect, frame, resolve, push, stop, notes, seen + (fn,)) + push
                   for c in callees), default=0)
    return own + deepest


def analyse_stack(build: Path, image: Image, elf: Path) -> None:
    target, role = image.target, image.role
    calls, indirect = call_graph(elf, target)
    frame = frames(build, target, role)
    push = TOOLS[target][1]
    resolve = {f: f"{role}_payload_check" for f in ("arachnae_parser_feed", "verdict")}
    behaviour = {f for f in calls if f.startswith(f"{role}_on_") or f in (f"{role}_send",)}
    notes: list[str] = []
    if is_baseline(image.role):
        image.stack["parse"] = worst("fw_rx_byte", calls, indirect, frame, {}, push, set(), notes)
        image.stack["dispatch"] = worst("fw_dispatch", calls, indirect, frame, {}, push, {"hal_send"}, notes)
    else:
        # decoding a frame: the RX interrupt's parser path, and the dispatch without the behaviour
        if f"{role}_rx_feed" not in calls:     # the role's own parser (node_<role>.c) must be the one linked
            notes.append(f"unresolved parser: no {role}_rx_feed in the image")
        image.stack["parse"] = worst(f"{role}_rx_feed", calls, indirect, frame, resolve, push, set(), notes)
        image.stack["dispatch"] = worst(f"{role}_dispatch", calls, indirect, frame, resolve, push, behaviour, notes)
    # the whole node: main with everything it calls, plus the deepest interrupt on top of it
    isrs = [f for f in calls if f.startswith("__vector_") or f.endswith("_Handler") or f.endswith("IRQHandler")]
    isrs = [f for f in isrs if f not in ("Reset_Handler", "Default_Handler", "__vector_default")]
    main = worst("main", calls, indirect, frame, resolve, push, set(), notes)
    isr = max((worst(f, calls, indirect, frame, resolve, push, set(), notes) for f in isrs), default=0)
    image.stack["node"] = main + isr + push   # an interrupt pushes its return address too
    image.notes.extend(sorted(set(notes)))


def is_baseline(role: str) -> bool:
    return role.startswith("baseline_")


def load_images(build: Path, baselines: list[str]) -> list[Image]:
    roles = (build / "roles.mk").read_text().split("\n", 1)[0].split(":=", 1)[1].split()
    images = []
    for target in ("avr", "m0"):
        for role in roles + [f"baseline_{b}" for b in baselines]:
            elf, mp = build / target / f"{role}.elf", build / target / f"{role}.map"
            if not elf.exists() or not mp.exists():
                raise SystemExit(f"size_report: {elf} missing; run `make -C firmware images` first")
            img = Image(role, target)
            parse_map(mp, img)
            analyse_stack(build, img, elf)
            images.append(img)
    return images


def table(images: list[Image], target: str) -> list[str]:
    head = (f"{'role':14} {'codec t/d/b':>14} {'skeleton t/d/b':>15} {'codec+skel':>10} "
            f"{'firmware t/b':>13} {'image flash':>11} {'static RAM':>10} {'stack parse/dispatch/node':>26} "
            f"{'RAM+stack':>9}" + (f" {'simavr RAM':>10}" if target == "avr" else ""))
    rows = [head, "-" * len(head)]
    for img in images:
        if img.target != target:
            continue
        c, s, f, t = img.parts["codec"], img.parts["skeleton"], img.parts["firmware"], img.total
        stack = f"{img.stack.get('parse', 0)}/{img.stack.get('dispatch', 0)}/{img.stack.get('node', 0)}"
        rows.append(f"{img.role:14} {f'{c.text}/{c.data}/{c.bss}':>14} {f'{s.text}/{s.data}/{s.bss}':>15} "
                    f"{c.flash + s.flash:>10} {f'{f.text}/{f.bss}':>13} {t.flash:>11} {t.data + t.bss:>10} "
                    f"{stack:>26} {t.data + t.bss + img.stack.get('node', 0):>9}"
                    + (f" {img.sim_ram if img.sim_ram is not None else '-':>10}" if target == "avr" else ""))
    return rows


def sim_ram(build: Path, images: list[Image], roles: list[str]) -> None:
    """The simavr RAM high-water mark of each listed role's AVR image (issue 15 item 4)."""
    if not roles:
        return
    for img in images:
        if img.target == "avr" and img.role in roles:
            try:
                use = ram_probe(build / "avr" / f"{img.role}.elf", img.role)
            except SilError as exc:
                raise SystemExit(f"size_report: simavr run of {img.role}: {exc}") from None
            img.sim_ram = use.static + use.stack


def load_nanopb(build: Path, roles: list[str]) -> list[Image]:
    """nanopb's codec of the same roles (make -C firmware nanopb): runtime + generated .pb.c."""
    images = []
    for role in roles:
        mp = build / "avr" / f"nanopb_{role}.map"
        if not mp.exists():
            raise SystemExit(f"size_report: {mp} missing; run `make -C firmware nanopb` first")
        img = Image(role, "avr")
        parse_map(mp, img)
        images.append(img)
    return images


def codec_skel(img: Image) -> int:
    return img.parts["codec"].flash + img.parts["skeleton"].flash


def budgets(images: list[Image], failures: list[str]) -> list[str]:
    out = ["", f"== budget (issue 15): codec + skeleton in AVR flash, a sensor role <= {SENSOR_FLASH_BUDGET}, "
           f"any role <= {AVR_FLASH_BUDGET}; the codec has no data or bss"]
    for img in images:
        c = img.parts["codec"]
        if (c.data or c.bss) and not is_baseline(img.role):
            failures.append(f"{img.target} {img.role}: the codec has {c.data} bytes of data and {c.bss} of bss")
        if img.target == "avr" and not is_baseline(img.role):
            used = codec_skel(img)
            limit = SENSOR_FLASH_BUDGET if img.role in SENSOR_ROLES else AVR_FLASH_BUDGET
            verdict = "fits" if used <= limit else f"OVER by {used - limit}"
            out.append(f"  {img.role:8} {used:5} bytes of {limit}: {verdict}")
    return out


def comparison(images: list[Image], nanopb: list[Image]) -> list[str]:
    """Ours beside the hand-written baseline and nanopb, per role (AVR)."""
    base_images = {i.role.removeprefix("baseline_"): i for i in images if i.target == "avr" and is_baseline(i.role)}
    baselines = {role: codec_skel(i) for role, i in base_images.items()}
    npb = {i.role: i.parts["codec"].flash for i in nanopb}
    head = (f"{'role':8} {'ours codec+skel':>15} {'ours msg_*.c':>12} {'baseline':>9} {'ours/baseline':>13} "
            f"{'nanopb codec':>12} {'nanopb/ours':>11}")
    out = ["", "== AVR codec bytes: generated (ours) vs hand-written baseline (firmware/baseline/) vs nanopb "
           "(firmware/nanopb/, runtime + descriptors; no framing, CRC, parser, dispatch or range checks)",
           head, "-" * len(head)]
    for img in images:
        if img.target != "avr" or is_baseline(img.role):
            continue
        ours = codec_skel(img)
        b, n = baselines.get(img.role), npb.get(img.role)
        ratio = f"{ours / b:.2f}x" if b else "-"
        nratio = f"{n / ours:.2f}x" if n else "-"
        out.append(f"{img.role:8} {ours:>15} {img.messages.flash:>12} {b if b else '-':>9} {ratio:>13} "
                   f"{n if n else '-':>12} {nratio:>11}")
    for role, base in baselines.items():
        ours = next((codec_skel(i) for i in images if i.target == "avr" and i.role == role), None)
        if ours is None:
            continue
        bar = int(BASELINE_RATIO * base)
        out.append(f"  {role} bar: ours <= {BASELINE_RATIO} x baseline = {bar} bytes: "
                   + ("met" if ours <= bar else f"NOT met, over by {ours - bar}"))
    for role, base in base_images.items():
        gen = next(i for i in images if i.target == "avr" and i.role == role)
        out.append(f"  {role} images: generated {gen.total.flash} bytes flash, {gen.total.data + gen.total.bss} static RAM; "
                   f"baseline {base.total.flash} bytes flash, {base.total.data + base.total.bss} static RAM"
                   + ("" if role == "tpsc" else " (baseline: protocol code, hook stubs for the behaviour)"))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=str(HERE / "build"), help="firmware build folder")
    ap.add_argument("--nanopb", default="", help="roles with a nanopb build to compare with (space separated)")
    ap.add_argument("--baselines", default="tpsc", help="roles with a hand-written baseline image (space separated)")
    ap.add_argument("--sil-ram", default="", help="roles whose AVR image runs in simavr for its RAM high-water mark "
                                                    "(space separated; needs `make -C firmware sil`)")
    args = ap.parse_args(argv)
    build = Path(args.build)
    images = load_images(build, args.baselines.split())
    sim_ram(build, images, args.sil_ram.split())
    nanopb = load_nanopb(build, args.nanopb.split())
    failures: list[str] = []
    out: list[str] = []
    for target, name in (("avr", "AVR ATmega328P, avr-gcc -Os"), ("m0", "Cortex-M0, arm-none-eabi-gcc -Os")):
        out += ["", f"== {name}: bytes (t/d/b = text/data/bss; static RAM = data + bss of the image; stack in bytes,"
                f" worst case of the static call graph: parse = RX interrupt path, dispatch = skeleton without the"
                f" behaviour, node = main + deepest ISR; RAM+stack = static RAM + node stack, the RAM the role needs"
                f" at most{', of 2048 on an ATmega328P' if target == 'avr' else ''})"]
        out += table(images, target)
    if args.sil_ram:
        out.append(f"  simavr RAM = static RAM + the deepest stack of a simavr run (start-up, each request without fields"
                   f" from the master, a contact on the first input, one every {PROBE_GAP_MS} ms; firmware/sil_bridge.py"
                   " ram_probe): what that run reached, beside the static worst case RAM+stack")
    out += budgets(images, failures)
    out += comparison(images, nanopb)
    for img in images:
        for n in img.notes:
            out.append(f"  note {img.target} {img.role}: {n}")
            if n.startswith(("unresolved", "recursion")):
                failures.append(f"{img.target} {img.role}: {n}")
    print("\n".join(out))
    (build / "size.json").write_text(json.dumps(
        [{"role": i.role, "target": i.target, "stack": i.stack, "notes": i.notes, "messages": vars(i.messages),
          "sim_ram": i.sim_ram,
          **{k: vars(p) for k, p in i.parts.items()}} for i in images]
        + [{"role": i.role, "target": "avr-nanopb", "codec": vars(i.parts["codec"])} for i in nanopb], indent=1) + "\n")
    for f in failures:
        print(f"size_report: {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
