"""Shared fixtures: the repository, the loaded spec, the shared conformance vectors."""
from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def spec():
    from codegen.load import load_spec

    return load_spec()


@pytest.fixture(scope="session")
def vectors() -> list[list[str]]:
    """The language-neutral vectors as token lists, comments dropped."""
    text = (REPO / "generated" / "vectors" / "vectors.txt").read_text()
    return [line.split() for line in text.splitlines() if line.strip() and not line.startswith("#")]
