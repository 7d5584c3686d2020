"""issue 5: behaviours are firmware logic: they import the generated package, never the simulator or the spec loader."""
from __future__ import annotations

import ast
from pathlib import Path

from arachnae_proto.skeletons import SKELETONS, skeleton_class

import behaviours

ROOT = Path(__file__).resolve().parents[2] / "behaviours"


def test_no_behaviour_module_imports_sim2d_or_codegen():
    for path in sorted(ROOT.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            for name in names:
                assert name.split(".")[0] not in ("sim2d", "codegen", "pymunk"), f"{path.name} imports {name}"


def test_every_role_has_a_behaviour_on_its_generated_skeleton():
    assert set(behaviours.ROLES) == set(SKELETONS)
    for role, cls in behaviours.ROLES.items():
        assert issubclass(cls, skeleton_class(role)), role
