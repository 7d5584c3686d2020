"""One exception type for every mistake a user can make.

The CLI turns it into a single line on stderr and a non-zero exit, so no
user error ever ends in a traceback (DEVELOPERS.md, Standards).
"""
from __future__ import annotations


class UserError(Exception):
    """A user-caused problem; its text is the whole message, e.g. 'file:line: what'."""

    exit_code = 1


def located(path: str, line: int | None, message: str) -> str:
    """Format a diagnostic as 'file:line: message' (line omitted when unknown)."""
    return f"{path}:{line}: {message}" if line else f"{path}: {message}"
