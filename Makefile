# Every target wraps the `arachnae` command; `make setup` runs once per machine.
VENV     := .venv
PY       := $(VENV)/bin/python
ARACHNAE := $(VENV)/bin/arachnae
# pytest-xdist workers for make test's pytest suite (one per core)
PYTEST_WORKERS ?= auto
STAMP    := $(VENV)/.setup-stamp

.PHONY: setup run test scenarios sweep-suite codegen docs spec-check check timing bench firmware size fuzz clean

setup: $(STAMP)

$(STAMP): pyproject.toml scripts/setup.sh scripts/apt-packages.txt
	./scripts/setup.sh
	touch $@

## The main job: the default scenario, outputs in runs/default/.
run: setup
	$(ARACHNAE) sim run scenarios/default.yaml --out runs/default

## All tests, as CI runs them: unit tests, scenarios, model checking, firmware matrix and fuzzing.
test: setup
	$(ARACHNAE) spec check
	$(ARACHNAE) codegen --check
	$(PY) -m pytest -n $(PYTEST_WORKERS) --dist loadfile
	$(MAKE) scenarios check firmware size fuzz

## Prove the spec's protocols; the seed's arbitration rule must yield its counterexample (exit 1).
check: setup
	$(ARACHNAE) check all --quiet
	$(ARACHNAE) check arbitration --variant seed --bus sensor --size 2 --quiet; test $$? -eq 1

## Worst-case POST, whisker-to-STOP and scan times against the seed's bounds.
timing: setup
	$(ARACHNAE) timing

## The scenario library, seeds 1-2 each (issue 17: CI runs seeds 1-2 of every scenario; seeds 1-5 no longer fit the
## 20-minute budget of issue 14: 27 min 23 s idle with them, twelfth session; the 1-20 sweep is sweep-suite), every
## expectation must hold.
## A passing run keeps trace.tsv and metrics.json; a failing one every output (report.html, pictures, capture).
scenarios: setup
	$(ARACHNAE) sim batch $(filter-out scenarios/bench_60s.yaml,$(wildcard scenarios/*.yaml)) --seeds 1-2 -j 2 --out runs/batch --outputs failed

## The scenario library over seeds 1-20 on a local Dask cluster, then pass rates (issue 14; not run in CI).
sweep-suite: setup
	$(ARACHNAE) sim sweep scenarios/sweeps/suite.yaml --out runs/sweep-suite
	$(ARACHNAE) sweep report runs/sweep-suite

codegen: setup
	$(ARACHNAE) codegen

## The message reference from the spec (seed 7.3 final report): build/docs/index.html, viewable offline.
docs: setup
	$(ARACHNAE) docs --out build/docs

spec-check: setup
	$(ARACHNAE) spec check

## Firmware-grade C (issue 6): build matrix, size table, bounded fuzz campaign.
firmware: setup
	$(MAKE) -C firmware all PYTHON=$(abspath $(PY))

size: setup
	$(MAKE) -C firmware size PYTHON=$(abspath $(PY))

fuzz: setup
	$(MAKE) -C firmware fuzz PYTHON=$(abspath $(PY))

## Benchmarks print figures next to references measured in the same run.
bench: setup
	-$(PY) -m pip install -q pymavlink  # reference for the codec figures; optional
	@for b in bench/*_bench.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
