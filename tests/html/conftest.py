"""Shared by the HTML tests: one headless Chromium (Debian's, driven by playwright) and one short run."""
from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import pytest

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]

# 14 s: POST, a walk into a high block (12 cm: under the sonar head at 0.14 m, so the sonar does not steer round it
# first, as in scenarios/high_obstacle.yaml), one whisker reaction and the control layers taking turns, in a
# room with every kind of thing the report's legend knows (pit, light, heat, slope, a low and a high obstacle).
SCENARIO = """name: report_test
duration: 14
arena: {size: [4, 3], boundary_walls: true}
robot: {pose: [1.2, 1.5, 0]}
obstacles:
  - {polygon: [[1.75, 0.9], [1.95, 0.9], [1.95, 2.1], [1.75, 2.1]], height: 0.12}
  - {polygon: [[0.3, 0.3], [0.8, 0.3], [0.8, 0.5], [0.3, 0.5]], height: 0.03}
pits:
  - {polygon: [[3.2, 0.3], [3.7, 0.3], [3.7, 0.9], [3.2, 0.9]]}
lights:
  - {pos: [3.5, 2.6], intensity: 200}
heat:
  - {pos: [0.6, 2.4], temperature: 45, radius: 0.3}
slopes:
  - {polygon: [[2.4, 2.0], [3.2, 2.0], [3.2, 2.8], [2.4, 2.8]], incline_x: 10}
expect:
  post: OPERATIONAL
  max_reaction: 1.0
  stay_out: [[1.95, 0.9], [4.0, 0.9], [4.0, 2.1], [1.95, 2.1]]
"""


class Loaded(NamedTuple):
    page: object            # playwright Page
    errors: list[str]       # console errors and uncaught exceptions
    requests: list[str]     # every URL the page asked for


@pytest.fixture(scope="session")
def report_outcome(tmp_path_factory):
    """The run, as `sim run` makes it (sim2d.runner.run), kept for tests that look inside."""
    from sim2d import runner

    d = tmp_path_factory.mktemp("report_run")
    (d / "s.yaml").write_text(SCENARIO)
    return runner.run(str(d / "s.yaml"))


@pytest.fixture(scope="session")
def report_run(report_outcome, tmp_path_factory) -> Path:
    """Its output folder, written as `sim run` writes it (sim2d.runner.write_outputs)."""
    from sim2d import runner

    return runner.write_outputs(report_outcome, tmp_path_factory.mktemp("report_out") / "run")


@pytest.fixture(scope="session")
def browser(tmp_path_factory):
    """Headless Chromium with a fresh profile; one start for every HTML test (each start costs seconds)."""
    from playwright.sync_api import sync_playwright

    profile = tmp_path_factory.mktemp("chromium-profile")
    with sync_playwright() as p:
        context = p.chromium.launch_persistent_context(str(profile), executable_path=CHROMIUM, headless=True,
                                                       args=FLAGS, viewport={"width": 1300, "height": 900})
        yield context
        context.close()


def open_page(browser, path: Path) -> Loaded:
    page = browser.new_page()
    errors: list[str] = []
    requests: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("request", lambda r: requests.append(r.url))
    page.goto(path.as_uri(), wait_until="load")
    return Loaded(page, errors, requests)


def offline(urls: list[str]) -> bool:
    """Every request stayed on the disk or inside the page."""
    return all(u.startswith(("file:", "data:")) for u in urls)
