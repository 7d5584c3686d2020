"""Issue 6.3: the committed seed corpus, the libFuzzer campaign and its regressions, the Python fuzz."""
from __future__ import annotations

import subprocess
import sys

from tests.firmware.conftest import REPO, make

FUZZ = REPO / "fuzz"


def test_seed_corpus_matches_the_shared_vectors():
    r = subprocess.run([sys.executable, str(FUZZ / "make_corpus.py"), "--check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    names = {p.name for p in (FUZZ / "corpus" / "frame").iterdir()}
    assert any(n.startswith("msg_") for n in names) and any(n.startswith("bad_") for n in names)


def test_libfuzzer_replays_seeds_and_kept_crashes_then_runs_a_bounded_campaign():
    """Every committed seed and every input in fuzz/regressions/ replays clean under ASan+UBSan
    and the target's oracles; then a fixed-size campaign (FUZZ_RUNS) finds nothing new."""
    r = make("fuzz", FUZZ_RUNS="200000")
    out = r.stdout + r.stderr
    assert "Done 200000 runs" in out, out[-2000:]
    crashes = list((REPO / "firmware" / "build" / "fuzz" / "crashes").glob("*"))
    assert not crashes, f"crash inputs: {crashes} (copy them to fuzz/regressions/ once fixed)"


def test_python_codec_fuzz_agrees_with_its_parser_and_the_c_codec():
    r = subprocess.run([sys.executable, str(FUZZ / "python_fuzz.py"), "--examples", "5000"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "agree" in r.stdout
