"""Fault sweeps (issue 14): many runs of base scenarios with parameters overridden, on a Dask cluster.

A sweep file (sim2d/sweep.schema.yaml) names base scenarios, seeds, a grid and/or a seeded random
sample over parameters (fault kind, node, time and span; sensor noise; bus loss and corruption;
obstacle jitter; start pose) and the metrics to collect. Each run's scenario is the base scenario
(includes merged) with the overrides applied, written to RESULTS/scenarios/RUN.yaml and checked by
sim2d.scenario.load_scenario like any scenario file, so an override that makes no sense (a fault after
the end, an obstacle jittered onto the start pose) is refused before any run starts, and the file is the
run's replay: `arachnae sim run RESULTS/scenarios/RUN.yaml`.

Why Dask (dask.distributed): a real sweep outgrows one machine; the same code runs on a LocalCluster or,
with --scheduler, on an existing cluster (the workers must have the toolkit installed and see the
RESULTS folder and the scenario files at the same paths, e.g. a shared file system).

Results: RESULTS/rows/RUN.json for each finished run (written atomically as it completes, so an
interrupted sweep resumes with the runs still missing), then RESULTS/results.parquet, one row per run
sorted by run id, the same whatever the number of workers; RESULTS/failed/RUN/ holds the usual run
outputs (sim2d.runner.write_outputs) of failing runs only.
"""
from __future__ import annotations

import copy
import hashlib
import itertools
import json
import os
import random
import shutil
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable

import yaml

from arachnae.errors import UserError, located
from arachnae.validation import check_schema, fill_defaults
from arachnae.yamlio import LDict, load_yaml, locate, new_dict
from sim2d.metrics import lookup, metric_path_problem, metrics_schema
# the scenario loader's own include merge and schema with the spec's names (one place for both)
from sim2d.scenario import gather_includes, load_scenario, safe_name, scenario_schema

_SCHEMA: dict[str, Any] = load_yaml(Path(__file__).with_name("sweep.schema.yaml"))
PARAMS: tuple[str, ...] = tuple(_SCHEMA["properties"]["grid"]["properties"])
SWEEP_MARKER = ".arachnae-sweep"      # in every results folder: {"sweep", "plan"} as JSON
MAX_RUNS = 100_000
# a parameter that needs others to mean something: (parameter, the ones it needs)
_NEEDS = (("fault_kind", ("fault_node",)), ("fault_for", ("fault_node",)), ("fault_node", ("fault_at",)),
          ("fault_at", ("fault_node",)), ("sensor_noise", ("sensor",)), ("sensor", ("sensor_noise",)),
          ("bus_loss", ("bus",)), ("bus_corrupt", ("bus",)))


@dataclass(frozen=True)
class RunSpec:
    """One run of a sweep: a base scenario, a seed and the parameter values that override it."""

    index: int
    base: str                       # the base scenario file as the sweep names it (relative to the sweep file)
    base_path: Path
    seed: int
    params: dict[str, Any]          # only the parameters the sweep varies
    where: list[Any]                # the sweep document path to point at when this run's scenario is refused

    @property
    def run_id(self) -> str:
        return f"r{self.index:06d}"


@dataclass(frozen=True)
class Sweep:
    path: str
    name: str
    runs: tuple[RunSpec, ...]
    metrics: tuple[str, ...]
    params: tuple[str, ...]         # the parameters the sweep varies, in PARAMS order
    doc: Any                        # the checked sweep document (for file:line of a refused run)


@dataclass(frozen=True)
class Plan:
    """The runs' effective scenarios, checked, and the hash that identifies the sweep in its results folder."""

    sweep: Sweep
    texts: dict[str, str]           # run id -> effective scenario YAML
    digest: str


def _schema(spec: Any) -> dict[str, Any]:
    """sim2d/sweep.schema.yaml with the spec's node and bus names, as the scenario loader fills them in."""
    schema = copy.deepcopy(_SCHEMA)
    names = scenario_schema(spec)["$defs"]
    schema["$defs"]["node"], schema["$defs"]["bus"] = names["node"], names["bus"]
    return schema


def _read(path: Path, shown: str) -> LDict:
    if not path.is_file():
        raise UserError(located(shown, None, "no such sweep file"))
    doc = load_yaml(path, shown)
    if not isinstance(doc, LDict):
        raise UserError(located(shown, getattr(doc, "line", 1) or 1, "a sweep file is a mapping of keys "
                                                                      "(scenarios, seeds, grid, sample, metrics)"))
    return doc


def _seeds(doc: LDict) -> list[int]:
    seeds = doc["seeds"]
    if isinstance(seeds, dict):
        if seeds["from"] > seeds["to"]:
            raise locate(doc, ["seeds"], f"seeds: from {seeds['from']} is above to {seeds['to']}")
        if seeds["to"] - seeds["from"] >= MAX_RUNS:
            raise locate(doc, ["seeds"], f"seeds: more than {MAX_RUNS} seeds")
        return list(range(seeds["from"], seeds["to"] + 1))
    if len(set(seeds)) != len(seeds):
        raise locate(doc, ["seeds"], "seeds: a seed is listed twice")
    return list(seeds)


def _check_params(doc: LDict) -> dict[str, list[Any]]:
    """Where each varied parameter is given (path in the document); refuses one given twice or missing a partner."""
    grid, ranges = doc.get("grid", {}), doc.get("sample", {}).get("ranges", {})
    where: dict[str, list[Any]] = {}
    for p in PARAMS:
        if p in grid and p in ranges:
            raise locate(doc, ["sample", "ranges", p], f"sample.ranges.{p}: {p} is also in grid; give it in one place")
        if p in grid or p in ranges:
            where[p] = ["grid", p] if p in grid else ["sample", "ranges", p]
    for p, needs in _NEEDS:
        for n in needs:
            if p in where and n not in where:
                raise locate(doc, where[p], f"{'.'.join(map(str, where[p]))}: {p} needs {n} too")
    if "bus" in where and "bus_loss" not in where and "bus_corrupt" not in where:
        raise locate(doc, where["bus"], f"{'.'.join(where['bus'])}: bus needs bus_loss or bus_corrupt")
    for p, r in ranges.items():
        if "min" in r and r["min"] > r["max"]:
            raise locate(doc, ["sample", "ranges", p], f"sample.ranges.{p}: min {r['min']} is above max {r['max']}")
    return where


def load_sweep(path: str | Path, spec: Any) -> Sweep:
    """Read and check a sweep file (structure: sim2d/sweep.schema.yaml; then meaning) and list its runs."""
    shown = str(path)
    doc = _read(Path(path), shown)
    schema = _schema(spec)
    check_schema(doc, schema)
    fill_defaults(doc, schema)
    where = _check_params(doc)
    bases: list[tuple[str, Path]] = []
    for i, name in enumerate(doc["scenarios"]):
        target = (Path(path).parent / name)
        if not target.is_file():
            raise locate(doc, ["scenarios", i], f"scenarios[{i}]: no such scenario file {name!r}")
        bases.append((name, target.resolve()))
    measured = ("coverage", "wall_band")
    mschema = metrics_schema(spec, measured)
    for i, m in enumerate(doc["metrics"]):
        problem = metric_path_problem(mschema, m)
        if problem or not all(m.split(".")):
            raise locate(doc, ["metrics", i], f"metrics[{i}]: {m!r} names no metric: {problem or 'empty part'}")
    if len(set(doc["metrics"])) != len(doc["metrics"]):
        raise locate(doc, ["metrics"], "metrics: a metric is listed twice")
    seeds = _seeds(doc)
    grid = doc.get("grid", {})
    points = [dict(zip(grid, combo)) for combo in itertools.product(*(grid[p] for p in grid))] if grid else [{}]
    sample = doc.get("sample")
    draws = sample["count"] if sample else 1
    total = len(bases) * len(seeds) * len(points) * draws
    if total > MAX_RUNS:
        raise locate(doc, [], f"(top level): {total} runs; at most {MAX_RUNS} in one sweep")
    runs: list[RunSpec] = []
    for (name, base_path), seed, point in itertools.product(bases, seeds, points):
        for draw in range(draws):
            params = dict(point)
            if sample:
                params.update(_draw(sample, len(runs), draw))
            first = next((where[p] for p in PARAMS if p in params), ["scenarios", bases.index((name, base_path))])
            runs.append(RunSpec(len(runs), name, base_path, seed, {p: params[p] for p in PARAMS if p in params},
                                first))
    return Sweep(shown, doc.get("name") or safe_name(Path(shown).stem), tuple(runs), tuple(doc["metrics"]),
                 tuple(p for p in PARAMS if p in where), doc)


def _draw(sample: LDict, index: int, draw: int) -> dict[str, Any]:
    """One random draw of sample.ranges: a string-seeded generator, the same in every process and on every machine."""
    rng = random.Random(f"arachnae-sweep:{sample['seed']}:{index}:{draw}")
    out: dict[str, Any] = {}
    for p, r in sample["ranges"].items():
        out[p] = rng.choice(list(r["choice"])) if "choice" in r else round(rng.uniform(r["min"], r["max"]), 6)
    return out


# -- the effective scenario of each run ------------------------------------------------------------
def _plain(value: Any) -> Any:
    """LDict/LList -> dict/list, numbers kept as they are (a seed stays an integer)."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def apply_overrides(base: dict[str, Any], run: RunSpec) -> dict[str, Any]:
    """The base scenario document (includes merged) with the run's seed and parameter values applied."""
    doc = copy.deepcopy(base)
    doc.pop("include", None)
    p = run.params
    doc["seed"] = run.seed
    faults = doc.setdefault("faults", [])
    if "fault_node" in p:
        fault: dict[str, Any] = {"at": p["fault_at"], p.get("fault_kind", "kill"): p["fault_node"]}
        if "fault_for" in p:
            fault["until"] = round(p["fault_at"] + p["fault_for"], 6)
        faults.append(fault)
    if "sensor" in p:
        faults.append({"at": 0, "sensor": p["sensor"], "noise": p["sensor_noise"]})
    if "bus" in p:
        faults.append({"at": 0, "bus": p["bus"], "loss": p.get("bus_loss", 0.0), "corrupt": p.get("bus_corrupt", 0.0)})
    if not faults:
        doc.pop("faults")
    if p.get("obstacle_jitter"):
        rng = random.Random(f"arachnae-jitter:{run.index}:{run.seed}")
        j = p["obstacle_jitter"]
        for ob in doc.get("obstacles", []):
            dx, dy = rng.uniform(-j, j), rng.uniform(-j, j)
            ob["polygon"] = [[round(x + dx, 6), round(y + dy, 6)] for x, y in ob["polygon"]]
    pose = doc["robot"]["pose"] if isinstance(doc.get("robot"), dict) and "pose" in doc["robot"] else None
    for i, key in enumerate(("start_x", "start_y", "start_heading")):
        if key in p and pose is not None:
            pose[i] = p[key]
    return doc


def plan(sweep: Sweep, spec: Any, staging: Path) -> Plan:
    """Every run's effective scenario as YAML, each checked by sim2d.scenario.load_scenario in `staging`."""
    bases: dict[Path, dict[str, Any]] = {}
    texts: dict[str, str] = {}
    for run in sweep.runs:
        if run.base_path not in bases:
            merged = new_dict(run.base, 1)
            gather_includes(run.base_path, run.base, (run.base_path,), merged)
            bases[run.base_path] = _plain(merged)
        doc = apply_overrides(bases[run.base_path], run)
        head = (f"# {sweep.name} run {run.run_id}: {run.base} seed {run.seed}"
                + "".join(f", {k}={v}" for k, v in run.params.items()) + "\n")
        text = head + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120)
        file = staging / f"{run.run_id}.yaml"
        file.write_text(text)
        try:
            load_scenario(file, spec)
        except UserError as exc:
            detail = str(exc).removeprefix(str(file)).lstrip(":0123456789 ")
            shown = ", ".join(f"{k}={v}" for k, v in run.params.items()) or "no overrides"
            raise locate(sweep.doc, run.where, f"run {run.run_id} ({run.base}, seed {run.seed}, {shown}): "
                                               f"the scenario it makes is refused: {detail}") from None
        texts[run.run_id] = text
    h = hashlib.sha256(json.dumps({"metrics": list(sweep.metrics), "runs": texts}, sort_keys=True).encode())
    return Plan(sweep, texts, h.hexdigest())


# -- the results folder ----------------------------------------------------------------------------
def _write_atomic(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def check_results(out: Path) -> None:
    """Refuse a results folder that is neither new, empty nor a previous sweep's (nothing of the user's is lost)."""
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise UserError(f"--out {out}: exists and is not a folder; refusing to use it")
    if out.exists() and any(out.iterdir()) and not (out / SWEEP_MARKER).is_file():
        raise UserError(f"--out {out}: exists and is not a sweep's results folder (no {SWEEP_MARKER}); "
                        "name a new folder")


def prepare(sweep: Sweep, spec: Any, out: Path) -> Plan:
    """Check every run's scenario, then set up (or, for a resumed sweep, recognise) the results folder."""
    check_results(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=".scenarios.", dir=out))
    except OSError as exc:
        raise UserError(f"--out {out}: cannot create the results folder ({exc.strerror})") from None
    try:
        p = plan(sweep, spec, staging)
        marker = out / SWEEP_MARKER
        if marker.is_file():
            try:
                previous = json.loads(marker.read_text()).get("plan")
            except (ValueError, AttributeError):
                previous = None
            if previous != p.digest:
                raise UserError(f"--out {out}: holds the results of a different sweep (the sweep file, its "
                                "scenarios or the toolkit changed); name a new folder")
        else:
            _write_atomic(marker, json.dumps({"sweep": sweep.path, "plan": p.digest}) + "\n")
        if not (out / "scenarios").is_dir():
            os.replace(staging, out / "scenarios")
        (out / "rows").mkdir(exist_ok=True)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        if out.is_dir() and not any(out.iterdir()):
            out.rmdir()
    return p


def finished_rows(out: Path, plan_: Plan) -> dict[str, dict[str, Any]]:
    """The rows of runs already finished (a row file that does not parse, or of another plan, does not count)."""
    done: dict[str, dict[str, Any]] = {}
    for f in sorted((out / "rows").glob("r*.json")):
        try:
            row = json.loads(f.read_text())
        except ValueError:
            continue
        if isinstance(row, dict) and row.get("run_id") == f.stem and f.stem in plan_.texts:
            done[f.stem] = row
    return done


# -- one run: a Dask task --------------------------------------------------------------------------


def _value(v: Any) -> Any:
    """A metric as a table cell: scalars as they are, lists and mappings as JSON text."""
    return v if v is None or isinstance(v, (bool, int, float, str)) else json.dumps(v, sort_keys=True)


def run_task(run_id: str, scenario_file: str, metrics: list[str], failed_dir: str) -> dict[str, Any]:
    """Run one effective scenario; its row (metrics, pass/fail per expectation, trace hash). Failing runs write
    the usual outputs to `failed_dir`."""
    from sim2d import runner

    try:
        outcome = runner.run(scenario_file, None, runner.load_spec_once())
    except UserError as exc:
        return {"run_id": run_id, "passed": False, "failed": "error", "error": str(exc), "trace_hash": None,
                "metrics": {m: None for m in metrics}, "expect": {}}
    m = outcome.result.metrics
    row = {"run_id": run_id, "passed": not outcome.failed, "failed": ", ".join(n for n, _, _ in outcome.failed),
           "error": None, "trace_hash": m["trace_hash"], "metrics": {p: _value(lookup(m, p)) for p in metrics},
           "expect": {n: ok for n, ok, _ in outcome.expectations}}
    if outcome.failed:
        runner.write_outputs(outcome, failed_dir, force=False)
    return row


# -- the table -------------------------------------------------------------------------------------
def table_rows(sweep: Sweep, rows: dict[str, dict[str, Any]], out: Path) -> list[dict[str, Any]]:
    """Flat rows, sorted by run id: run, base scenario, seed, parameters, metrics, expectations, verdict, replay."""
    names = sorted({n for r in rows.values() for n in r["expect"]})
    flat = []
    for run in sweep.runs:
        r = rows[run.run_id]
        flat.append({"run_id": run.run_id, "scenario": run.base, "seed": run.seed,
                     **{f"param.{p}": run.params.get(p) for p in sweep.params},
                     **{f"metric.{m}": r["metrics"].get(m) for m in sweep.metrics},
                     **{f"expect.{n}": r["expect"].get(n) for n in names},
                     "passed": r["passed"], "failed": r["failed"], "error": r["error"], "trace_hash": r["trace_hash"],
                     "replay": replay_command(out, run)})
    return flat


def replay_command(out: Path, run: RunSpec) -> str:
    return f"arachnae sim run {out / 'scenarios' / (run.run_id + '.yaml')} --seed {run.seed} --out {out / 'replay' / run.run_id}"


def _column(values: list[Any]) -> Any:
    """A typed Arrow column: bool, int64, float64, else text (JSON for anything mixed)."""
    import pyarrow as pa

    present = [v for v in values if v is not None]
    if all(isinstance(v, bool) for v in present):
        return pa.array(values, pa.bool_())
    if all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return pa.array(values, pa.int64())
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
        return pa.array([None if v is None else float(v) for v in values], pa.float64())
    return pa.array([None if v is None else v if isinstance(v, str) else json.dumps(v) for v in values], pa.string())


def write_table(flat: list[dict[str, Any]], path: Path) -> None:
    """results.parquet, written beside and renamed into place when complete."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = list(flat[0]) if flat else ["run_id"]
    table = pa.table({c: _column([r.get(c) for r in flat]) for c in columns})
    fd, tmp = tempfile.mkstemp(prefix=".results.", suffix=".parquet", dir=path.parent)
    os.close(fd)
    try:
        pq.write_table(table, tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# -- execution on Dask -----------------------------------------------------------------------------
@dataclass(frozen=True)
class SweepResult:
    table: Path
    runs: int
    ran: int                        # runs executed now (the rest were finished before: a resumed sweep)
    failed: int
    dashboard: str | None = None    # the Dask dashboard's address while the runs ran (None: nothing ran)


def client_for(scheduler: str | None, workers: int | None) -> Any:
    """A client of the cluster at `scheduler`, or of a new local cluster with `workers` processes.

    The local cluster serves Dask's dashboard (bokeh) on :8787, or on a free port when that one is taken."""
    import logging

    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.ERROR)
    if scheduler:
        try:
            return Client(scheduler, timeout="15s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise UserError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
    cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                           dashboard_address=":8787", silence_logs=logging.ERROR)
    return Client(cluster)


def execute(sweep: Sweep, spec: Any, out: Path, scheduler: str | None = None, workers: int | None = None,
            stop_after: int | None = None, progress: bool = True) -> SweepResult:
    """Run the runs not finished yet on Dask, persisting each row as it completes, then write the table.

    `stop_after`: stop once that many runs have finished in this call (tests: an interrupted sweep)."""
    from tqdm import tqdm

    out = out.resolve() if out.exists() else out.absolute()
    p = prepare(sweep, spec, out)
    done = finished_rows(out, p)
    todo = [r for r in sweep.runs if r.run_id not in done]
    ran = 0
    dashboard = None
    if todo:
        from distributed import as_completed

        client = client_for(scheduler, workers)
        try:
            dashboard = getattr(client, "dashboard_link", None)
            if dashboard and progress:
                print(f"dashboard: {dashboard}", file=sys.stderr)
            futures = [client.submit(run_task, r.run_id, str(out / "scenarios" / f"{r.run_id}.yaml"),
                                     list(sweep.metrics), str(out / "failed" / r.run_id),
                                     key=f"arachnae-run-{p.digest[:12]}-{r.run_id}", pure=False) for r in todo]
            bar = tqdm(total=len(sweep.runs), initial=len(done), desc=f"sweep {sweep.name}", unit="run",
                       file=sys.stderr, disable=not progress)
            for fut in as_completed(futures):
                row = fut.result()
                _write_atomic(out / "rows" / f"{row['run_id']}.json", json.dumps(row, sort_keys=True) + "\n")
                done[row["run_id"]] = row
                ran += 1
                bar.update(1)
                if stop_after is not None and ran >= stop_after:
                    for f in futures:
                        f.cancel()
                    break
            bar.close()
        finally:
            cluster = getattr(client, "cluster", None) if not scheduler else None
            client.close()
            if cluster is not None:
                cluster.close()
    if len(done) < len(sweep.runs):
        return SweepResult(out / "results.parquet", len(sweep.runs), ran, -1, dashboard)
    flat = table_rows(sweep, done, out)
    write_table(flat, out / "results.parquet")
    return SweepResult(out / "results.parquet", len(flat), ran, sum(not r["passed"] for r in flat), dashboard)


def read_table(out: Path) -> list[dict[str, Any]]:
    """results.parquet as rows (dicts), or a one-line error."""
    import pyarrow.parquet as pq

    path = Path(out) / "results.parquet"
    if not path.is_file():
        raise UserError(f"{out}: no results.parquet (not a finished sweep's results folder)")
    try:
        return pq.read_table(path).to_pylist()
    except Exception as exc:             # pyarrow's ArrowInvalid and kin
        raise UserError(f"{path}: cannot read the table ({exc})") from None

