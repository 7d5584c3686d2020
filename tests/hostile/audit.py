"""A hostile-input audit (issue 10): many generated bad inputs per surface, counted by outcome.

Each probe is one input a user could give, with what the contract asks of it:
- `bad=True`: it is wrong for certain (a string where a number goes, NaN, an unknown key, a frame with a
  flipped byte): it must be refused with one line;
- `bad=False`: it may be valid (a huge or negative number, a missing key that may be optional): it may be
  accepted, but never end in a traceback.

Outcomes: `refused` (a one-line UserError), `accepted`, `traceback` (any other exception), `long` (refused
with more than one line). The contract is 0 tracebacks, 0 bad inputs accepted and 0 long refusals.

Surface `run`: scenario mutants the loader accepted are started as `sim run --out` would start them, cut
to RUN_CAP_S of simulated time (a sample of them: QUICK.runs, FULL.runs): no traceback, and the output folder
is whole (marker, metrics.json) with nothing half-written beside it.

`python -m tests.hostile.audit [--full] [-j N]` prints the table for every surface and lists each failure
(-j: forked worker processes); tests/hostile/test_audit.py asserts the contract on the quick set.
"""
from __future__ import annotations

import copy
import io
import math
import random
import re
import shutil
import sys
import tempfile
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path
from typing import Any, Callable, Iterator, NamedTuple

import yaml

from arachnae.cli import main as cli_main
from arachnae.errors import UserError

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"


class Probe(NamedTuple):
    surface: str
    name: str
    run: Callable[[], Any]      # raises UserError to refuse; returns to accept
    bad: bool


class Outcome(NamedTuple):
    probe: Probe
    kind: str                   # refused | accepted | traceback | long
    detail: str
    value: Any = None           # what an accepted probe returned (a scenario's run, to be started later)

    @property
    def failed(self) -> bool:
        return self.kind in ("traceback", "long") or (self.kind == "accepted" and self.probe.bad)


def run_probe(probe: Probe) -> Outcome:
    try:
        value = probe.run()
    except UserError as exc:
        text = str(exc)
        return Outcome(probe, "refused" if _one_line_each(probe, text) else "long", text)
    except Exception as exc:  # noqa: BLE001 - the audit counts exactly these
        return Outcome(probe, "traceback", f"{type(exc).__name__}: {exc}")
    return Outcome(probe, "accepted", "", value)


_LOCATED = re.compile(r"^\S+:\d+: \S")


def _one_line_each(probe: Probe, text: str) -> bool:
    """One line; the spec check, like a compiler, may give several, one per field, each `file:line: ...`."""
    lines = text.strip().splitlines()
    return len(lines) == 1 or probe.surface == "spec" and all(_LOCATED.match(line) for line in lines)


def run_cli(*argv: str) -> None:
    """`arachnae ARGV` in process; a non-zero exit with one line on stderr counts as a refusal."""
    err, out = io.StringIO(), io.StringIO()
    try:
        with redirect_stderr(err), redirect_stdout(out):
            code = cli_main(list(argv))
    except SystemExit as exc:                       # argparse
        code = int(exc.code or 0)
    if code != 0:
        raise UserError(err.getvalue().strip() or f"exit {code} without a message")
    if "Traceback" in err.getvalue():
        raise RuntimeError(err.getvalue())


# -- value mutations --------------------------------------------------------------------------------
class Mutant(NamedTuple):
    label: str
    value: Any
    bad: bool


def mutations(value: Any) -> Iterator[Mutant]:
    """Replacement values for one leaf of a YAML document, each marked as certainly wrong or not."""
    if isinstance(value, bool):
        yield Mutant("bool->str", "sometimes", True)
        yield Mutant("bool->list", [True], True)
    elif isinstance(value, (int, float)):
        yield Mutant("num->str", "abc", True)
        yield Mutant("num->list", [value], True)
        yield Mutant("num->nan", math.nan, True)
        yield Mutant("num->inf", math.inf, False)
        yield Mutant("num->huge", 1e300, False)
        yield Mutant("num->negative", -abs(value) - 1, False)
        yield Mutant("num->null", None, False)
    elif isinstance(value, str):
        yield Mutant("str->map", {"x": 1}, True)
        yield Mutant("str->list", [value], False)
        yield Mutant("str->empty", "", False)
        yield Mutant("str->control", value + "\x1b[2J\n../..", False)
    elif isinstance(value, list):
        yield Mutant("list->map", {"k": value}, True)
        yield Mutant("list->empty", [], False)
        yield Mutant("list->nested", [value], False)
    elif isinstance(value, dict):
        yield Mutant("map->unknown-key", {**value, "bogus_key_zz": 1}, True)
        yield Mutant("map->list", list(value.values()), False)      # its values may be a valid list (seeds)
        yield Mutant("map->empty", {}, False)


def leaves(doc: Any, path: tuple = ()) -> Iterator[tuple[tuple, Any]]:
    """Every node below the root (mappings, lists and scalars), with its path."""
    if path:
        yield path, doc
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from leaves(v, path + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from leaves(v, path + (i,))


def with_value(doc: Any, path: tuple, value: Any) -> Any:
    out = copy.deepcopy(doc)
    node = out
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return out


def without(doc: Any, path: tuple) -> Any:
    out = copy.deepcopy(doc)
    node = out
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]
    return out


def doc_mutants(doc: Any) -> Iterator[tuple[str, Any, bool]]:
    """(label, mutated document, certainly bad) for every node and every mutation of it."""
    for path, value in leaves(doc):
        where = ".".join(str(p) for p in path)
        for m in mutations(value):
            yield f"{where}: {m.label}", with_value(doc, path, m.value), m.bad
        if isinstance(path[-1], str):
            yield f"{where}: removed", without(doc, path), False


def dump(doc: Any) -> str:
    return yaml.safe_dump(doc, sort_keys=False, allow_unicode=True)


# -- surfaces ---------------------------------------------------------------------------------------
def _file_probes(surface: str, work: Path, bases: list[Path], load: Callable[[Path], Any],
                 then: Callable[[Path], Any] | None = None) -> Iterator[Probe]:
    """Every mutation of every node of each base file, written beside it in a copy of scenarios/ (so its
    includes resolve) and given to `load`, as the command would. With `then`, an accepted mutant returns
    a callable that writes it again and gives it to `then` (the audit starts a sample of them)."""
    root = work / "scenarios"
    if not root.exists():
        shutil.copytree(SCENARIOS, root)
    for base in bases:
        doc = yaml.safe_load(base.read_text(encoding="utf-8"))
        folder = root / base.parent.relative_to(SCENARIOS)
        for i, (label, mutant, bad) in enumerate(doc_mutants(doc)):
            def with_file(use: Callable[[Path], Any], path=folder / f"audit_{base.stem}_{i}.yaml",
                          text=dump(mutant)) -> Any:
                path.write_text(text, encoding="utf-8")
                try:
                    return use(path)
                finally:
                    path.unlink()

            def run(with_file=with_file) -> Any:
                with_file(load)
                return (lambda: with_file(then)) if then is not None else None
            yield Probe(surface, f"{base.name} {label}", run, bad)


RUN_CAP_S = 2.0     # simulated seconds of each accepted scenario the audit starts


def simulate(path: Path, spec: Any, out: Path) -> None:
    """`sim run PATH --out OUT`, cut to RUN_CAP_S: a UserError is a refusal; afterwards OUT must be a whole run
    (its marker and metrics.json) and nothing half-written may be left beside it."""
    import json

    from sim2d import runner

    runner.write_outputs(runner.run(str(path), spec=spec, max_duration=RUN_CAP_S), out)
    leftovers = [p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}.")]
    if leftovers or not (out / runner.RUN_MARKER).is_file():
        raise RuntimeError(f"half-written output: {leftovers or 'no ' + runner.RUN_MARKER}")
    json.loads((out / "metrics.json").read_text())


def scenario_probes(work: Path, files: list[str], spec: Any) -> Iterator[Probe]:
    """Scenario files, loaded as `sim run` loads them; an accepted one can then be run (run_probes)."""
    from sim2d.scenario import load_scenario
    runs = work / "runs"
    runs.mkdir(exist_ok=True)
    yield from _file_probes("scenario", work, [SCENARIOS / f for f in files], lambda p: load_scenario(p, spec),
                            lambda p: simulate(p, spec, runs / p.stem))


def run_probes(outcomes: list[Outcome], count: int | None, rng: random.Random) -> list[Probe]:
    """The accepted scenario mutants started for RUN_CAP_S (a sample of `count`, or all): surface `run`."""
    accepted = [o for o in outcomes if o.kind == "accepted" and callable(o.value)]
    if count is not None and len(accepted) > count:
        accepted = rng.sample(accepted, count)
    return [Probe("run", o.probe.name, o.value, False) for o in accepted]


def sweep_probes(work: Path, spec: Any) -> Iterator[Probe]:
    """Sweep files, loaded as `sim sweep` loads them."""
    from sim2d.sweep import load_sweep
    yield from _file_probes("sweep", work, sorted((SCENARIOS / "sweeps").glob("*.yaml")), lambda p: load_sweep(p, spec))


def spec_probes(work: Path, limit: int | None, rng: random.Random) -> Iterator[Probe]:
    """Mutations of the spec's files, checked as `arachnae spec check` checks them (a sample when limited)."""
    from codegen.load import load_spec
    spec_root = REPO / "spec"
    files = sorted(spec_root.glob("*.yaml"))
    for target in files:
        doc = yaml.safe_load(target.read_text(encoding="utf-8"))
        mutants = list(doc_mutants(doc))
        if limit is not None and len(mutants) > limit:
            mutants = rng.sample(mutants, limit)
        for i, (label, mutant, bad) in enumerate(mutants):
            def run(target=target, text=dump(mutant), i=i):
                folder = work / f"spec_{target.stem}_{i}"
                folder.mkdir()
                try:
                    for f in files:
                        shutil.copy(f, folder / f.name)
                    (folder / target.name).write_text(text, encoding="utf-8")
                    load_spec(str(folder))
                finally:
                    shutil.rmtree(folder)
            yield Probe("spec", f"{target.name} {label}", run, bad)


def frame_probes(rng: random.Random, count: int) -> Iterator[Probe]:
    """Random hex and every single-byte corruption of the shared vectors' frames, through `arachnae decode`."""
    vectors = REPO / "generated" / "vectors"
    frames: list[str] = []
    for f in sorted(vectors.glob("*")):
        for line in f.read_text(encoding="utf-8", errors="replace").splitlines():
            parts = line.split()
            if len(parts) == 4 and parts[0] == "msg":          # msg NAME LABEL HEX (codegen/vectors.py)
                frames.append(parts[3])
    for i in range(count):
        raw = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 12)))
        yield Probe("frame", f"random {raw.hex()}", lambda raw=raw: run_cli("decode", raw.hex() or "zz"), False)
    for hexframe in frames[:count]:
        data = bytearray(bytes.fromhex(hexframe))
        pos = rng.randrange(len(data))
        data[pos] ^= 1 << rng.randrange(8)
        yield Probe("frame", f"bit flip at {pos} of {hexframe}",
                    lambda d=bytes(data): run_cli("decode", d.hex()), True)
    for arg in ["--own", "xyz", "--own", "-1", "--own", "0x100", "--own", "LCP(9)"][1::2]:
        yield Probe("frame", f"--own {arg}", lambda arg=arg: run_cli("decode", "--own", arg, "00"), True)


def console_probes(rng: random.Random, count: int) -> Iterator[Probe]:
    """Random bytes into the console's key decoder: keys are ASCII, nothing raises."""
    from behaviours.rcp_keys import KeyDecoder

    def run(data: bytes) -> None:
        keys = KeyDecoder().feed(data)
        if any(len(k) != 1 or ord(k) >= 0x80 for k in keys):
            raise RuntimeError(f"non-ASCII key from {data!r}")
    for i in range(count):
        data = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 40)))
        yield Probe("console", f"bytes {data.hex()}", lambda d=data: run(d), False)


def cli_probes(work: Path) -> Iterator[Probe]:
    """Bad values for the options of quick subcommands, through the real parser."""
    missing = str(work / "no-such-file.yaml")
    folder = str(work)
    cases: list[tuple[list[str], bool]] = [
        (["sim", "run", missing], True), (["sim", "run", folder], True),
        (["sim", "run", str(SCENARIOS / "default.yaml"), "--seed", "x"], True),
        (["sim", "run", str(SCENARIOS / "default.yaml"), "--pace", "nan"], True),
        (["sim", "run", str(SCENARIOS / "default.yaml"), "--pace", "-1"], True),
        (["sim", "run", str(SCENARIOS / "default.yaml"), "--sil", "NOBODY"], True),
        (["sim", "run", str(SCENARIOS / "default.yaml"), "--console", "bogus"], True),
        (["sim", "batch", missing], True), (["sim", "batch", str(SCENARIOS / "default.yaml"), "--seeds", "5-1"], True),
        (["sim", "batch", str(SCENARIOS / "default.yaml"), "--seeds", "a-b"], True),
        (["sim", "batch", str(SCENARIOS / "default.yaml"), "-j", "0"], True),
        (["sim", "sweep", missing], True), (["sweep", "report", missing], True),
        (["spec", "check", "--spec", missing], True), (["spec", "check", "--spec", folder], True),
        (["codegen", "--spec", missing], True), (["timing", "--spec", missing], True),
        (["timing", "--scope", "nobody"], True), (["docs", "--spec", missing], True),
        (["capture", "vcd", missing], True), (["capture", "vcd", folder], True),
        (["replay", missing, str(work / "tty")], True), (["monitor", str(work / "no-tty")], True),
        (["monitor", str(work / "no-tty"), "--count", "abc"], True),
        (["check", "arbitration", "--spec", missing], True),
    ]
    for argv, bad in cases:
        yield Probe("cli", " ".join(argv).replace(str(work), "TMP"), lambda argv=argv: run_cli(*argv), bad)


class Plan(NamedTuple):
    """How much the audit tries: the quick set (tests/hostile/test_audit.py) or --full."""
    scenarios: list[str] | None     # scenario files (None: every one in scenarios/)
    spec_per_file: int              # sampled mutations of each spec file (the spec check takes ~1 s each)
    frames: int
    console: int
    runs: int | None                # accepted scenario mutants started (None: all of them)


QUICK = Plan(["default.yaml", "fault_battery.yaml", "worst_contention.yaml"], 40, 100, 300, 4)
FULL = Plan(None, 300, 400, 2000, 120)


def all_probes(work: Path, plan: Plan, rng: random.Random) -> Iterator[Probe]:
    from codegen.load import load_spec
    spec = load_spec(None)
    files = plan.scenarios or sorted(p.name for p in SCENARIOS.glob("*.yaml"))
    yield from scenario_probes(work, files, spec)
    yield from sweep_probes(work, spec)
    yield from spec_probes(work, plan.spec_per_file, rng)
    yield from frame_probes(rng, plan.frames)
    yield from console_probes(rng, plan.console)
    yield from cli_probes(work)


_PROBES: list[Probe] = []       # the probes a forked worker runs, by index


def _run_index(i: int) -> tuple[str, str, bool]:
    o = run_probe(_PROBES[i])
    return o.kind, o.detail, callable(o.value)


def _run_all(probes: list[Probe], jobs: int) -> list[Outcome]:
    """Run the probes, in `jobs` forked processes when more than one (closures cannot be pickled: the
    workers inherit them). A worker's accepted scenario keeps no value: its run is started in the parent."""
    if jobs <= 1:
        return [run_probe(p) for p in probes]
    import multiprocessing

    _PROBES[:] = probes
    with multiprocessing.get_context("fork").Pool(jobs) as pool:
        results = pool.map(_run_index, range(len(probes)), chunksize=8)
    return [Outcome(p, kind, detail, (lambda p=p: p.run()()) if runnable else None)
            for p, (kind, detail, runnable) in zip(probes, results)]


def audit(full: bool = False, jobs: int = 1) -> list[Outcome]:
    """Every probe of the plan; then a sample of the scenarios the loader accepted, started (surface `run`)."""
    plan = FULL if full else QUICK
    rng = random.Random(10)
    with tempfile.TemporaryDirectory(prefix="arachnae-audit-") as tmp:
        outcomes = _run_all(list(all_probes(Path(tmp), plan, rng)), jobs)
        return outcomes + _run_all(run_probes(outcomes, plan.runs, rng), jobs)


def table(outcomes: list[Outcome]) -> str:
    counts: dict[str, Counter] = {}
    for o in outcomes:
        c = counts.setdefault(o.probe.surface, Counter())
        c["tried"] += 1
        c["certainly bad"] += o.probe.bad
        c[o.kind] += 1
        c["bad accepted"] += o.kind == "accepted" and o.probe.bad
    cols = ["tried", "certainly bad", "refused", "accepted", "bad accepted", "traceback", "long"]
    lines = ["surface    " + "".join(f"{c:>15}" for c in cols)]
    for surface, c in counts.items():
        lines.append(f"{surface:<11}" + "".join(f"{c[k]:>15}" for k in cols))
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    """python -m tests.hostile.audit [--full] [-j N]"""
    jobs = int(argv[argv.index("-j") + 1]) if "-j" in argv else 1
    outcomes = audit(full="--full" in argv, jobs=jobs)
    print(table(outcomes))
    failures = [o for o in outcomes if o.failed]
    for o in failures:
        print(f"FAIL {o.kind}: [{o.probe.surface}] {o.probe.name} -> {o.detail[:300]}")
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
