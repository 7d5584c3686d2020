"""Generation is deterministic, committed, headed with the spec hash, and checked at import."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from codegen.generate import render, stale


def test_rendering_twice_gives_the_same_bytes(spec) -> None:
    assert render(spec) == render(spec)


def test_committed_generated_files_are_up_to_date(spec) -> None:
    assert stale(render(spec)) == []


def test_every_generated_file_names_its_source_and_spec_hash(spec) -> None:
    for path, data in render(spec).items():
        head = data.decode().splitlines()[:2]
        assert "spec/nodes.yaml, spec/messages.yaml" in head[0], path
        assert head[1].endswith(f"spec sha256: {spec.hash}"), path


def test_python_package_refuses_mixed_generations(tmp_path: Path, repo: Path) -> None:
    pkg = tmp_path / "arachnae_proto"
    shutil.copytree(repo / "generated" / "python" / "arachnae_proto", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    init = pkg / "__init__.py"
    init.write_text(init.read_text().replace('SPEC_HASH = "', 'SPEC_HASH = "0'))
    run = subprocess.run([sys.executable, "-c", "import arachnae_proto.messages"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode != 0 and "generated from another spec" in run.stderr


def test_generated_python_uses_only_the_standard_library(repo: Path) -> None:
    allowed = set(sys.stdlib_module_names) | {"arachnae_proto"}
    for path in (repo / "generated" / "python").rglob("*.py"):
        for line in path.read_text().splitlines():
            words = line.split()
            if words[:1] in (["import"], ["from"]):
                assert words[1].split(".")[0] in allowed, f"{path}: {line}"
