"""Issue 10's contract over generated bad inputs (tests/hostile/audit.py): per surface, no traceback, no
certainly-bad input accepted, every refusal one line. `python -m tests.hostile.audit --full` runs every
scenario and the whole spec and prints the table the issue's note quotes."""
from __future__ import annotations

from tests.hostile.audit import audit, table


def test_no_traceback_no_silent_acceptance():
    outcomes = audit(full=False)
    failures = [f"{o.kind}: [{o.probe.surface}] {o.probe.name} -> {o.detail[:200]}" for o in outcomes if o.failed]
    assert not failures, table(outcomes) + "\n" + "\n".join(failures)
    surfaces = {o.probe.surface for o in outcomes}
    assert surfaces == {"scenario", "sweep", "spec", "frame", "console", "cli", "run"}
    runs = [o for o in outcomes if o.probe.surface == "run"]
    assert len(runs) == 4 and all(o.kind == "accepted" for o in runs)     # started, ran and wrote a whole run
    assert sum(o.kind == "refused" for o in outcomes) > 500      # the probes reach the checks, not just argparse
