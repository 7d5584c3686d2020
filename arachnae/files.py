"""Writing a user-visible file whole or not at all (DEVELOPERS.md, Standards: nothing half-written)."""
from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterator

from arachnae.errors import UserError


@contextmanager
def atomic_open(path: str | Path, mode: str = "w") -> Iterator[IO]:
    """Open a temporary file beside `path`; it replaces `path` only if the block ends without an exception."""
    out = Path(path)
    fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=f".{out.name}.")
    try:
        with os.fdopen(fd, mode) as fh:
            yield fh
        os.chmod(tmp, 0o644)
        os.replace(tmp, out)
    except BaseException:
        os.unlink(tmp)
        raise



def ours(path: Path, mark: str) -> bool:
    """True when `path` is a regular file whose first 4 KiB carry `mark`: a file the toolkit wrote."""
    try:
        with path.open("rb") as fh:
            return mark.encode() in fh.read(4096)
    except OSError:
        return False


def refuse_foreign(path: Path, mark: str, writer: str, force: bool | None = None) -> None:
    """Refuse to replace `path` unless it is missing or carries `mark` (issue 10.1: a user's file is never clobbered).

    `writer` names the command in the one-line error. `force` is None where the command has no --force;
    True lets a foreign regular file be replaced. Symlinks and folders are never replaced."""
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise UserError(f"{path}: not a regular file; {writer} refuses to replace it")
    if path.exists() and not force and not ours(path, mark):
        hint = " (choose another name, or --force)" if force is not None else " (choose another name)"
        raise UserError(f"{path}: exists and was not written by {writer}; refusing to replace it{hint}")
