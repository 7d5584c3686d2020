"""Run scenarios and write their output folders, never at the cost of anything of the user's.

Outputs go to a fresh temporary folder beside the target and are moved into place only when
complete. An existing target is replaced only when it is recognisably a previous run (it holds
RUN_MARKER, which every run writes), otherwise refused; `--force` overrides that, but never for the
current folder, a parent of it, the home folder or a file that is not a folder (issue 10, item 1).
"""
from __future__ import annotations

import functools
import json
import os
import shutil
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from arachnae.errors import UserError
from sim2d.level0_io import WallClock, attach_console
from sim2d.metrics import check_expectations
from sim2d.scenario import Scenario, load_scenario
from sim2d.sim import Result, Simulation, capture_frames
from tracecheck.trace import COLUMNS, trace_lines

GIF_FRAME_S = 0.5
RUN_MARKER = ".arachnae-run"        # in every run folder: {"scenario", "name", "seed"} as JSON
BATCH_MARKER = ".arachnae-batch"    # in a batch's parent folder: its summary.md is ours to replace


@dataclass
class Outcome:
    scenario: Scenario
    result: Result
    expectations: list[tuple[str, bool, str]]
    rcp_screen: bytes = b""          # what the UIC/RCP drew on its VT100 terminal (sim2d.level0_io)
    spec: Any = None                 # the spec the run used (bus names and rates of the capture)

    @property
    def failed(self) -> list[tuple[str, bool, str]]:
        return [e for e in self.expectations if not e[1]]


@functools.cache
def load_spec_once() -> Any:
    """The spec, loaded once per process (1-2 s of YAML parsing and lint): every run of a batch or sweep
    worker (forked from a parent that loaded it already) shares it. Runs only read it."""
    from codegen.load import load_spec
    return load_spec()


def run(path: str, seed: int | None = None, spec: Any = None, gif: bool = False,
        replace_nodes: dict[str, Any] | None = None, console: Any = None, pace: float | None = None,
        max_duration: float | None = None) -> Outcome:
    """`console`: a host terminal line (console.terminal) on the UIC/RCP's RS-232 port; with it, or with
    `pace` (simulated seconds per wall second), the run keeps to the wall clock. `max_duration` cuts the run
    short (the hostile-input audit starts every scenario it accepts this way)."""
    spec = spec or load_spec_once()
    sc = load_scenario(path, spec)
    if seed is not None:
        sc = sc.with_seed(seed)
    if max_duration is not None and sc.duration > max_duration:
        sc = replace(sc, duration=max_duration)
    sim = Simulation(sc, spec, keep_frames_every=GIF_FRAME_S if gif else None, replace_nodes=replace_nodes)
    if console is not None or pace is not None:
        attach_console(sim, console if console is not None else WallClock(), 1.0 if pace is None else pace)
    result = sim.run()
    return Outcome(sc, result, check_expectations(sc, result.metrics), bytes(sim.rcp.screen), spec)


def run_sil(path: str, sil: tuple[str, ...], seed: int | None = None, spec: Any = None,
            made: list[Any] | None = None) -> Outcome:
    """`run` with the nodes in `sil` (names or comma lists) run as AVR firmware in simavr, as `arachnae sim run
    --sil` does; the SilNodes made are appended to `made` (their RAM use can be read until they are closed)."""
    from firmware.sil_bridge import check_sil_nodes, sil_factory, sil_names
    spec = spec or load_spec_once()
    names = sil_names(list(sil))
    check_sil_nodes(spec, names)
    return run(path, seed, spec=spec, replace_nodes={name: sil_factory(made=made) for name in names})


def _protected(target: Path) -> str | None:
    """Why `target` may never be replaced, or None."""
    real, cwd, home = target.resolve(), Path.cwd().resolve(), Path.home().resolve()
    if real == cwd or real in cwd.parents:
        return "is the current folder or one of its parents"
    if real == home or real == Path(real.anchor):
        return "is the home folder or the root of the file system"
    return None


def check_target(out_dir: str | Path, force: bool = False) -> Path:
    """Refuse (UserError) an output folder whose replacement could lose something of the user's."""
    out = Path(out_dir)
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise UserError(f"--out {out}: exists and is not a folder; refusing to replace it")
    if not out.exists():
        if out.parent.exists() and not out.parent.is_dir():
            raise UserError(f"--out {out}: {out.parent} is not a folder")
        return out
    why = _protected(out)
    if why:
        raise UserError(f"--out {out}: {why}; refusing to replace it (name a new folder)")
    if (out / RUN_MARKER).is_file() or not any(out.iterdir()):
        return out                      # a previous run, or an empty folder: nothing to lose
    if not force:
        raise UserError(f"--out {out}: exists and is not a previous run (no {RUN_MARKER}); refusing to replace it "
                        "(name a new folder, or --force)")
    return out


def write_outputs(outcome: Outcome, out_dir: str | Path, gif: bool = False, force: bool = False,
                  full: bool = True) -> Path:
    """trace.tsv, bus.pcapng, metrics.json, run.png (and run.gif), report.html into a new folder, then moved to out_dir
    (check_target). Not `full`: trace.tsv and metrics.json only (a passing run of `sim batch --outputs failed`)."""
    out = check_target(out_dir, force)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    except OSError as exc:
        raise UserError(f"--out {out}: cannot create the output folder ({exc.strerror})") from None
    try:
        r = outcome.result
        lines = r.trace_rows if r.trace_rows is not None else trace_lines(r.frames, r.notes)
        with open(tmp / "trace.tsv", "w") as fh:
            fh.write("\t".join(COLUMNS) + "\n")
            fh.write("\n".join(lines) + ("\n" if lines else ""))
        metrics = dict(r.metrics)
        metrics["expectations"] = [{"name": n, "passed": ok, "detail": d} for n, ok, d in outcome.expectations]
        (tmp / "metrics.json").write_text(json.dumps(metrics, indent=2) + "\n")
        if full:
            _write_views(outcome, tmp, gif)
        sc = outcome.scenario
        (tmp / RUN_MARKER).write_text(json.dumps({"scenario": sc.path, "name": sc.name, "seed": sc.seed}) + "\n")
        os.chmod(tmp, 0o755)
        _move_into_place(tmp, check_target(out, force))     # checked again: the run may have taken minutes
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise UserError(f"--out {out}: cannot write the outputs ({exc.strerror or exc})") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out


def _write_views(outcome: Outcome, tmp: Path, gif: bool) -> None:
    """The run's capture, pictures, node artifacts and report.html (after trace.tsv and metrics.json) into `tmp`."""
    from captures.pcapng import bus_interfaces, write_file
    from sim2d.render import render_gif, render_png
    from sim2d.report import write_report

    r = outcome.result
    # the same frames for Wireshark: one interface per bus, the spec's user link type (issue 13)
    write_file(tmp / "bus.pcapng", bus_interfaces(outcome.spec or load_spec_once()), capture_frames(r.frames))
    render_png(r, str(tmp / "run.png"))
    for node in r.nodes.values():         # debug-port dumps a node offers (e.g. the NP3's map)
        artifacts = getattr(node, "write_artifacts", None)
        if artifacts is not None:
            artifacts(tmp)
    ssc = r.nodes.get("SSC")
    if outcome.scenario.speech_wav and ssc is not None:   # scenario `speech: {wav: true}`
        ssc.write_wavs(tmp / "speech")
    (tmp / "rcp_screen.vt100").write_bytes(outcome.rcp_screen)   # the UIC/RCP's terminal output
    if gif:
        render_gif(r, str(tmp / "run.gif"))
    write_report(outcome, tmp)               # report.html, from the outputs above (issue 13)


def _move_into_place(tmp: Path, out: Path) -> None:
    """Swap the complete new folder in; the old one (checked by check_target) goes only once the new one is there."""
    if not out.exists():
        os.replace(tmp, out)
        return
    old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old.", dir=out.parent))
    os.replace(out, old / out.name)
    try:
        os.replace(tmp, out)
    except OSError:
        os.replace(old / out.name, out)     # put the previous run back
        shutil.rmtree(old, ignore_errors=True)
        raise
    shutil.rmtree(old, ignore_errors=True)


def check_summary(root: str | Path, force: bool = False) -> Path:
    """Where a batch's summary.md goes; an existing one is replaced only in a batch folder of ours (or --force)."""
    root = Path(root)
    summary = root / "summary.md"
    if summary.is_symlink() or (summary.exists() and not summary.is_file()):
        raise UserError(f"{summary}: exists and is not a file; not replacing it")
    if summary.exists() and not (root / BATCH_MARKER).is_file() and not force:
        raise UserError(f"{summary}: exists and {root} is not a batch folder (no {BATCH_MARKER}); "
                        "not replacing it (--force replaces it)")
    return summary


def write_summary(root: str | Path, text: str, force: bool = False) -> Path:
    """A batch's summary.md, written to a temporary file and renamed over the old one only when complete."""
    summary = check_summary(root, force)
    tmp: str | None = None
    try:
        summary.parent.mkdir(parents=True, exist_ok=True)
        (summary.parent / BATCH_MARKER).touch()
        fd, tmp = tempfile.mkstemp(prefix=".summary.", suffix=".md", dir=summary.parent)
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, summary)
    except OSError as exc:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
        raise UserError(f"{summary}: cannot write ({exc.strerror or exc})") from None
    return summary


def default_out(outcome: Outcome) -> Path:
    return Path("sim-out") / f"{outcome.scenario.name}-seed{outcome.scenario.seed}"
