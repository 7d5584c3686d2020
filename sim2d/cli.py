"""`arachnae sim run` and `arachnae sim batch` (issue 4)."""
from __future__ import annotations

import argparse
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from arachnae.errors import UserError


def register(sub: Any) -> None:
    sim = sub.add_parser("sim", help="2-D simulation of the robot and its network")
    ssub = sim.add_subparsers(dest="sim_command", metavar="SIMCOMMAND", parser_class=type(sim))
    ssub.required = True

    run = ssub.add_parser("run", help="run one scenario headless")
    run.add_argument("scenario", help="scenario YAML file")
    run.add_argument("--seed", type=_seed, help="override the scenario's seed")
    run.add_argument("--out", help="output folder (default sim-out/NAME-seedN); an existing one is replaced only "
                                   "if it holds a previous run")
    run.add_argument("--force", action="store_true",
                     help="replace an existing --out folder even if it is not a previous run")
    run.add_argument("--gif", action="store_true", help="also write an animation run.gif")
    run.add_argument("--sil", action="append", default=[], metavar="NODE",
                     help="run NODE (e.g. TPSC; repeatable or a comma list: USRC,TPSC,IRRC,ISC,TSC,LSC,PSC) as AVR "
                          "firmware in simavr (software in the loop; `make firmware` first)")
    run.add_argument("--console", metavar="LINE",
                     help="a VT100 terminal on the UIC/RCP's RS-232 line (seed 4.1): pty (prints the device to open "
                          "with screen/picocom), stdio (this terminal) or serial:DEVICE (pyserial); paces the run")
    run.add_argument("--pace", type=_pace, metavar="X",
                     help="keep to the wall clock, X simulated seconds per second (default 1 with --console)")
    run.set_defaults(func=cmd_run)

    batch = ssub.add_parser("batch", help="run scenarios x seeds in parallel")
    batch.add_argument("scenarios", nargs="+", help="scenario YAML files")
    batch.add_argument("--seeds", default="1", help="seeds: '1,2,7' or '1-10' (default 1)")
    batch.add_argument("-j", "--jobs", type=_jobs, default=None, help="worker processes (default: CPU count)")
    batch.add_argument("--out", default="sim-out", help="parent folder of the runs' output folders")
    batch.add_argument("--force", action="store_true",
                       help="replace existing run folders (and summary.md) even if they are not previous runs")
    batch.add_argument("--outputs", choices=("all", "failed"), default="all",
                       help="which runs write every output (default all); with `failed` a passing run's folder holds "
                            "trace.tsv and metrics.json only (no pcapng, pictures or report.html: ~10 %% of a run)")
    batch.set_defaults(func=cmd_batch)

    sweep = ssub.add_parser("sweep", help="run a fault sweep (many runs, parameters varied) on a Dask cluster")
    sweep.add_argument("sweep", help="sweep YAML file (sim2d/sweep.schema.yaml)")
    sweep.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="an existing Dask cluster (default: a local one)")
    sweep.add_argument("--workers", type=_jobs, default=None, help="local worker processes (default: CPU count)")
    sweep.add_argument("--out", help="results folder (default sweep-out/NAME); an interrupted sweep resumes in it")
    sweep.set_defaults(func=cmd_sweep)

    top = sub.add_parser("sweep", help="statistics of a sweep's results")
    tsub = top.add_subparsers(dest="sweep_command", metavar="SWEEPCOMMAND", parser_class=type(sim))
    tsub.required = True
    report = tsub.add_parser("report", help="pass rates with Wilson intervals, failure rate per parameter bin, "
                                            "worst runs, PNG plots and report.md")
    report.add_argument("results", help="a sweep's results folder")
    report.set_defaults(func=cmd_sweep_report)


MAX_SEED = 2**63 - 1          # sim2d/scenario.schema.yaml: seed


def _seed(text: str) -> int:
    try:
        value = int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"must be 0 .. {MAX_SEED}, got {value}")
    return value


def _jobs(text: str) -> int:
    try:
        value = int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 1 <= value <= 256:
        raise argparse.ArgumentTypeError(f"must be 1 .. 256, got {value}")
    return value


def _pace(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def parse_seeds(text: str) -> list[int]:
    seeds: list[int] = []
    try:
        for part in text.split(","):
            if "-" in part.strip()[1:]:
                a, b = part.split("-", 1)
                seeds.extend(range(int(a), int(b) + 1))
            else:
                seeds.append(int(part))
    except ValueError:
        raise UserError(f"--seeds: expected numbers like '1,2,7' or '1-10', got {text!r}") from None
    if not seeds or any(not 0 <= s <= MAX_SEED for s in seeds):
        raise UserError(f"--seeds: expected seeds 0 .. {MAX_SEED}, got {text!r}")
    if len(seeds) > 100_000:
        raise UserError(f"--seeds: {len(seeds)} seeds; at most 100000 in one batch")
    return seeds


def _check_file(path: str) -> None:
    if not Path(path).is_file():
        raise UserError(f"{path}: no such scenario file")


def _open_console(where: str) -> Any:
    """The host end of the RCP line (console.terminal); a bad device is a one-line error."""
    from console.terminal import attach

    if where not in ("pty", "stdio") and not where.startswith("serial:"):
        raise UserError(f"--console: expected pty, stdio or serial:DEVICE, got {where!r}")
    try:
        port = attach(where)
    except (OSError, ValueError) as exc:
        raise UserError(f"--console {where}: cannot open the line ({exc})") from None
    except Exception as exc:            # pyserial's SerialException
        raise UserError(f"--console {where}: cannot open the line ({exc})") from None
    if where == "pty":
        print(f"RCP console on {port.peer}: connect a terminal, e.g. `screen {port.peer}` or "
              f"`picocom {port.peer}`", flush=True)
    return port


def cmd_run(args: argparse.Namespace) -> int:
    from sim2d import runner

    _check_file(args.scenario)
    replace_nodes = None
    sil_made: list[Any] = []
    sil_errors: tuple[type[Exception], ...] = ()
    if args.sil:
        from firmware.sil_bridge import SilError, check_sil_nodes, sil_factory, sil_names

        sil_errors = (SilError,)
        names = sil_names(args.sil)
        check_sil_nodes(runner.load_spec_once(), names)
        replace_nodes = {name: sil_factory(made=sil_made) for name in names}
    if args.out is not None:
        runner.check_target(args.out, args.force)     # refuse before a long run, and again when writing
    console = _open_console(args.console) if args.console else None
    try:
        outcome = runner.run(args.scenario, args.seed, gif=args.gif, replace_nodes=replace_nodes,
                             console=console, pace=args.pace)
    except sil_errors as exc:
        raise UserError(f"--sil: the firmware run failed: {exc}") from None   # e.g. the AVR crashed in simavr
    finally:
        if console is not None:
            console.close()             # restores a raw terminal before anything is printed
    out = runner.write_outputs(outcome, args.out or runner.default_out(outcome), gif=args.gif, force=args.force)
    m = outcome.result.metrics
    print(f"{outcome.scenario.name} seed {outcome.scenario.seed}: POST {m['post']['verdict']}, "
          f"walked {m['distance_walked_m']:.2f} m, collisions {m['collisions']}, frames {m['frames']}")
    print(f"trace hash {m['trace_hash']}")
    print(f"output {out}")
    for name, ok, detail in outcome.expectations:
        print(f"  {'PASS' if ok else 'FAIL'} {name}: {detail}")
    if sil_made:
        from firmware.sil_bridge import ram_lines, ram_use

        print("RAM high-water of the SIL nodes in simavr (bytes):")
        print("\n".join(ram_lines(ram_use([n for n in sil_made if n.host.proc.poll() is None]))))
    if outcome.failed:
        sys.stderr.write(f"{outcome.scenario.path}: expectation failed: {', '.join(n for n, _, _ in outcome.failed)}\n")
        return 1
    return 0


def _batch_one(job: tuple[str, int, str, bool, bool]) -> tuple[str, int, dict[str, Any] | None, list, str | None]:
    from sim2d import runner

    path, seed, out_root, force, all_outputs = job
    try:
        outcome = runner.run(path, seed)
        runner.write_outputs(outcome, Path(out_root) / f"{outcome.scenario.name}-seed{seed}", force=force,
                             full=all_outputs or bool(outcome.failed))
        return path, seed, outcome.result.metrics, outcome.expectations, None
    except UserError as exc:
        return path, seed, None, [], str(exc)


def cmd_batch(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    seeds = parse_seeds(args.seeds)
    for p in args.scenarios:
        _check_file(p)
    from sim2d.runner import load_spec_once
    from sim2d.scenario import load_scenario
    from sim2d.runner import check_summary, check_target
    spec = load_spec_once()
    root = Path(args.out)
    if root.is_symlink() or (root.exists() and not root.is_dir()):
        raise UserError(f"--out {root}: exists and is not a folder")
    check_summary(root, args.force)
    targets: dict[Path, str] = {}
    for p in args.scenarios:
        name = load_scenario(p, spec).name      # report a bad file before starting any worker
        for s in seeds:
            target = root / f"{name}-seed{s}"
            if target in targets:
                raise UserError(f"{p}: writes {target}, as {targets[target]} does (give one a different name)")
            targets[target] = p
            check_target(target, args.force)     # refuse what a run would clobber before any run starts
    jobs = [(p, s, args.out, args.force, args.outputs == "all") for p in args.scenarios for s in seeds]
    rows = []
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        for row in tqdm(pool.map(_batch_one, jobs), total=len(jobs), desc="sim batch", unit="run", file=sys.stderr):
            rows.append(row)
    header = f"{'scenario':32} {'seed':>5} {'POST':12} {'walked_m':>8} {'coll':>4} {'lost':>5} {'result':6} hash"
    print(header)
    failures = 0
    for path, seed, m, exps, err in rows:
        if err is not None:
            failures += 1
            print(f"{Path(path).stem:32} {seed:>5} ERROR {err}")
            continue
        bad = [n for n, ok, _ in exps if not ok]
        failures += bool(bad)
        print(f"{m['scenario'][:32]:32} {seed:>5} {str(m['post']['verdict']):12} {m['distance_walked_m']:8.2f} "
              f"{m['collisions']:>4} {m['frame_loss']:>5} {'FAIL' if bad else 'PASS':6} {m['trace_hash'][:12]}"
              + (f"  failed: {', '.join(bad)}" if bad else ""))
    print(f"{len(rows) - failures} passed, {failures} failed")
    from sim2d.runner import write_summary
    from sim2d.summary import markdown
    done = [dict(m, expectations=[{"name": n, "passed": ok, "detail": d} for n, ok, d in exps])
            for _p, _s, m, exps, err in rows if err is None]
    summary = write_summary(args.out, markdown(done), args.force)
    print(f"key metrics per run: {summary}")
    return 1 if failures else 0


def cmd_sweep(args: argparse.Namespace) -> int:
    from sim2d import sweep as sw
    from sim2d.runner import load_spec_once

    if args.scheduler is not None and args.workers is not None:
        raise UserError("--workers: a local cluster's size; it does not apply with --scheduler")
    spec = load_spec_once()
    s = sw.load_sweep(args.sweep, spec)
    out = Path(args.out) if args.out else Path("sweep-out") / s.name
    res = sw.execute(s, spec, out, args.scheduler, args.workers)
    print(f"{res.runs} runs ({res.ran} run now, {res.runs - res.ran} finished before): "
          f"{res.runs - res.failed} passed, {res.failed} failed")
    print(f"table {res.table}")
    if res.failed:
        print(f"failing runs' outputs in {out / 'failed'}; `arachnae sweep report {out}` for the statistics")
    return 0


def cmd_sweep_report(args: argparse.Namespace) -> int:
    from sim2d.sweep_report import write_report

    md = write_report(Path(args.results))
    print(md.read_text(), end="")
    print(f"report {md} and {md.with_suffix('.html')}")
    return 0
