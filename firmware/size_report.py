"""Flash, RAM and stack of every role's firmware image on AVR and Cortex-M0 (`make -C firmware size`).

Sizes come from the linker map of each image (firmware/build/<target>/<role>.map), so
they count only what --gc-sections kept, split by where it came from:
    codec      generated/c arachnae_frame.c, log10_*.c and the role's msg_*.c
    skeleton   generated/c node_<role>.c
    firmware   main.c, the board HAL and the behaviour (or an empty stub)
    runtime    C start-up, libgcc, libc, vector table
Stack: worst case over the static call graph (objdump calls + -fstack-usage frames);
the parser's one indirect call is resolved to the role's payload check.
Writes build/size.json; prints the tables. Exit 1 if the codec has data or bss of
its own or an image could not be analysed.
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
SENSOR_ROLES = ("usrc", "tpsc", "irrc", "isc", "tsc", "lsc", "psc")
AVR_FLASH_BUDGET = 2048          # issue 6: codec + skeleton of one sensor role in 2 KiB of AVR flash
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

    @property
    def total(self) -> Part:
        t = Part()
        for p in self.parts.values():
            t.text, t.data, t.bss = t.text + p.text, t.data + p.data, t.bss + p.bss
        return t


def category(obj: str, role: str) -> str:
    name = Path(obj).name
    if "/gen/" in obj:
        return "skeleton" if name == f"node_{role}.o" else "codec"
    if "/baseline/" in obj:      # the hand-written protocol code stands in for codec + skeleton
        return "codec" if name == "tpsc_proto.o" else "firmware"
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
    if image.role == "baseline_tpsc":
        image.stack["parse"] = worst("fw_rx_byte", calls, indirect, frame, {}, push, set(), notes)
        image.stack["dispatch"] = worst("fw_dispatch", calls, indirect, frame, {}, push, {"hal_send"}, notes)
    else:
        # decoding a frame: the RX interrupt's parser path, and the dispatch without the behaviour
        image.stack["parse"] = worst("arachnae_parser_feed", calls, indirect, frame, resolve, push, set(), notes)
        image.stack["dispatch"] = worst(f"{role}_dispatch", calls, indirect, frame, resolve, push, behaviour, notes)
    # the whole node: main with everything it calls, plus the deepest interrupt on top of it
    isrs = [f for f in calls if f.startswith("__vector_") or f.endswith("_Handler") or f.endswith("IRQHandler")]
    isrs = [f for f in isrs if f not in ("Reset_Handler", "Default_Handler", "__vector_default")]
    main = worst("main", calls, indirect, frame, resolve, push, set(), notes)
    isr = max((worst(f, calls, indirect, frame, resolve, push, set(), notes) for f in isrs), default=0)
    image.stack["node"] = main + isr + push   # an interrupt pushes its return address too
    image.notes.extend(sorted(set(notes)))


def load_images(build: Path) -> list[Image]:
    roles = (build / "roles.mk").read_text().split("\n", 1)[0].split(":=", 1)[1].split()
    images = []
    for target in ("avr", "m0"):
        for role in roles + ["baseline_tpsc"]:
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
            f"{'firmware t/b':>13} {'image flash':>11} {'image RAM':>9} {'stack parse/dispatch/node':>26}")
    rows = [head, "-" * len(head)]
    for img in images:
        if img.target != target:
            continue
        c, s, f, t = img.parts["codec"], img.parts["skeleton"], img.parts["firmware"], img.total
        stack = f"{img.stack.get('parse', 0)}/{img.stack.get('dispatch', 0)}/{img.stack.get('node', 0)}"
        rows.append(f"{img.role:14} {f'{c.text}/{c.data}/{c.bss}':>14} {f'{s.text}/{s.data}/{s.bss}':>15} "
                    f"{c.flash + s.flash:>10} {f'{f.text}/{f.bss}':>13} {t.flash:>11} {t.data + t.bss:>9} "
                    f"{stack:>26}")
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=str(HERE / "build"), help="firmware build folder")
    args = ap.parse_args(argv)
    build = Path(args.build)
    images = load_images(build)
    failures: list[str] = []
    out: list[str] = []
    for target, name in (("avr", "AVR ATmega328P, avr-gcc -Os"), ("m0", "Cortex-M0, arm-none-eabi-gcc -Os")):
        out += ["", f"== {name}: bytes (t/d/b = text/data/bss; stack in bytes, worst case of the static call graph)"]
        out += table(images, target)
    out += ["", f"== budget: codec + skeleton of a sensor role in {AVR_FLASH_BUDGET} bytes of AVR flash, codec without data or bss"]
    for img in images:
        c, s = img.parts["codec"], img.parts["skeleton"]
        if (c.data or c.bss) and img.role != "baseline_tpsc":
            failures.append(f"{img.target} {img.role}: the codec has {c.data} bytes of data and {c.bss} of bss")
        if img.target == "avr" and img.role in SENSOR_ROLES:
            used = c.flash + s.flash
            verdict = "fits" if used <= AVR_FLASH_BUDGET else f"OVER by {used - AVR_FLASH_BUDGET}"
            out.append(f"  {img.role:6} {used:5} bytes: {verdict} ({AVR_FLASH_BUDGET - used:+d} left)")
    base = next(i for i in images if i.target == "avr" and i.role == "baseline_tpsc")
    gen = next(i for i in images if i.target == "avr" and i.role == "tpsc")
    gb = gen.parts["codec"].flash + gen.parts["skeleton"].flash
    out += ["", "== TPSC on AVR: generated codec + skeleton vs the hand-written baseline (firmware/baseline/)",
            f"  generated codec+skeleton {gb} bytes; generated image {gen.total.flash} bytes flash, {gen.total.data + gen.total.bss} RAM",
            f"  baseline protocol code (baseline/tpsc_proto.c) {base.parts['codec'].flash} bytes flash, "
            f"{base.parts['codec'].bss} bss; baseline image {base.total.flash} bytes flash, {base.total.data + base.total.bss} RAM",
            f"  image difference: {gen.total.flash - base.total.flash:+d} bytes flash for the generated version"]
    for img in images:
        for n in img.notes:
            out.append(f"  note {img.target} {img.role}: {n}")
            if n.startswith(("unresolved", "recursion")):
                failures.append(f"{img.target} {img.role}: {n}")
    print("\n".join(out))
    (build / "size.json").write_text(json.dumps(
        [{"role": i.role, "target": i.target, "stack": i.stack, "notes": i.notes,
          **{k: vars(p) for k, p in i.parts.items()}} for i in images], indent=1) + "\n")
    for f in failures:
        print(f"size_report: {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
