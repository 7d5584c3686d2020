"""Language-neutral conformance vectors, shared by the C and the Python tests."""
from __future__ import annotations

from codegen.generate import Output
from codegen.model import Spec
from codegen.vectors import vector_text

OUT_DIR = "generated/vectors"
COMMENT = "#"
FILTERS: dict = {}


def outputs(spec: Spec) -> list[Output]:
    return [Output("vectors.txt", text=vector_text(spec))]
