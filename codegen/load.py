"""`load_spec`: read, check and model the spec, the one way every part gets it.

Apart from codegen.model because the checks (codegen.lint) need the model's types and the targets'
names (codegen.generate): model <- lint <- load, with no import going back up.
"""
from __future__ import annotations

from pathlib import Path

from codegen.lint import check_documents, check_targets
from codegen.model import SPEC_DIR, SPEC_FILES, Spec, build, spec_digest


def load_spec(spec_dir: Path | str | None = None) -> Spec:
    """Load, check and model the spec; raises arachnae.errors.UserError listing every problem."""
    directory = Path(spec_dir) if spec_dir is not None else SPEC_DIR
    paths = tuple(directory / name for name in SPEC_FILES)
    nodes_doc, messages_doc = check_documents(paths[0], paths[1])
    spec = build(nodes_doc, messages_doc, paths, spec_digest(paths))
    check_targets(spec, (paths[0], paths[1]), (nodes_doc, messages_doc))
    return spec
