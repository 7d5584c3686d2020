"""Shared tools of the hostile-spec tests: a spec copy to break, the CLI, snapshots, build and import.

Every refusal must be one `file:line: message` line per problem on stderr, a non-zero
exit and no change on disk; every acceptance must generate C that compiles with the
strict flags and Python that imports.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SPEC = REPO / "spec"
N, M = "nodes.yaml", "messages.yaml"
STRICT = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Wsign-conversion", "-pedantic", "-Werror"]
ARACHNAE = REPO / ".venv" / "bin" / "arachnae"


def spec_copy(tmp: Path) -> Path:
    """A private copy of the shipped spec, in tmp/spec."""
    target = tmp / "spec"
    target.mkdir()
    for name in (N, M):
        shutil.copy(SPEC / name, target / name)
    return target


def replace(spec_dir: Path, file: str, old: str, new: str, count: int = 1) -> Path:
    """Replace `old` (which must occur exactly `count` times, 0: any number >= 1) in one spec file."""
    path = spec_dir / file
    text = path.read_text(encoding="utf-8")
    found = text.count(old)
    assert found == count if count else found >= 1, f"{old!r} occurs {found} times in {file}"
    path.write_text(text.replace(old, new), encoding="utf-8")
    return path


# CHOICE: the spec commands run in this process, through the function the installed command calls
# (arachnae/__main__.py: SystemExit(main())), with what a process would show: its exit code, its stdout, its
# stderr (an escaping exception as a Traceback there). A fresh interpreter per call (~1 s of start-up and
# imports, ~150 calls in tests/hostile) is what made these files a fifth of the suite. `check` keeps the real
# command: its searches may fork, and output from another process would escape the capture.
IN_PROCESS = {"spec", "codegen", "timing"}


def _in_process(argv: list[str]) -> subprocess.CompletedProcess:
    """`arachnae ARGV` as the entry point runs it, cwd REPO, stdout and stderr captured."""
    import contextlib
    import io
    import traceback

    from arachnae.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.chdir(REPO), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:               # argparse; Python prints a non-integer code and exits 1
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            if not isinstance(exc.code, int) and exc.code is not None:
                print(exc.code, file=sys.stderr)
        except Exception:                       # noqa: BLE001 - an uncaught exception, as the interpreter shows it
            traceback.print_exc()
            code = 1
    return subprocess.CompletedProcess(["arachnae", *argv], code, out.getvalue(), err.getvalue())


def cli(*args: str | Path) -> subprocess.CompletedProcess:
    """The `arachnae` command, as a user runs it (the spec commands in process: IN_PROCESS says why)."""
    argv = [str(a) for a in args]
    if argv and argv[0] in IN_PROCESS:
        return _in_process(argv)
    cmd = [str(ARACHNAE)] if ARACHNAE.exists() else [sys.executable, "-m", "arachnae"]
    return subprocess.run(cmd + argv, capture_output=True, text=True, cwd=REPO, timeout=300)


def snapshot(*roots: Path) -> dict[str, tuple[int, str]]:
    """Every file and folder under the roots: (mode, sha256 of the content; '' for folders)."""
    state: dict[str, tuple[int, str]] = {}
    for root in roots:
        for path in [root, *sorted(root.rglob("*"))] if root.exists() else []:
            if "__pycache__" in path.parts:
                continue
            st = path.lstat()
            digest = hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else ""
            state[str(path)] = (st.st_mode, digest)
    return state


def assert_refused(run: subprocess.CompletedProcess, file: Path, expect: str = "") -> list[str]:
    """Non-zero exit, no traceback, every stderr line `file:line: ...`, one of them containing `expect`."""
    lines = run.stderr.strip().splitlines()
    assert run.returncode != 0, f"accepted: {run.stdout}{run.stderr}"
    assert "Traceback" not in run.stderr, run.stderr
    assert lines, "no diagnostic"
    pattern = re.compile(rf"^{re.escape(str(file))}:\d+: \S")
    assert all(pattern.match(line) for line in lines), run.stderr
    assert any(expect in line for line in lines), f"wanted {expect!r} in\n{run.stderr}"
    return lines


def compile_c(c_dir: Path, syntax_only: bool = True, work: Path | None = None) -> None:
    """Every generated .c (arachnae.h and the node headers with it) through gcc with the strict flags."""
    sources = sorted(str(p) for p in c_dir.glob("*.c"))
    flags = ["-fsyntax-only"] if syntax_only else ["-c", "-O1"]
    res = subprocess.run(["gcc", *STRICT, *flags, f"-I{c_dir}", *sources], capture_output=True, text=True,
                         cwd=work or c_dir)
    assert res.returncode == 0, res.stderr[-4000:]


def import_python(py_dir: Path, check: str = "") -> str:
    """Import every generated module in a fresh interpreter; run `check` (Python code) after; return stdout."""
    code = ("import importlib, pkgutil, arachnae_proto, arachnae_proto.skeletons as s\n"
            "for m in ('errors', 'network', 'enums', '_tables', 'convert', 'messages', 'frame'):\n"
            "    importlib.import_module('arachnae_proto.' + m)\n"
            "for info in pkgutil.iter_modules(s.__path__):\n"
            "    importlib.import_module('arachnae_proto.skeletons.' + info.name)\n"
            "for role in s.SKELETONS:\n"
            "    s.skeleton_class(role)\n" + check)
    env = {**os.environ, "PYTHONPATH": str(py_dir), "PYTHONDONTWRITEBYTECODE": "1"}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=py_dir, env=env)
    assert res.returncode == 0, res.stderr[-4000:]
    return res.stdout


def generate(spec_dir: Path, out: Path) -> None:
    """`arachnae codegen --spec spec_dir --out out`, which must succeed."""
    run = cli("codegen", "--spec", spec_dir, "--out", out)
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr


def rename(spec_dir: Path, word: str, new: str) -> None:
    """Rename a spec name everywhere it occurs as a whole word, so every reference still resolves."""
    for name in (N, M):
        path = spec_dir / name
        text = path.read_text(encoding="utf-8")
        path.write_text(re.sub(rf"(?<![\w(]){re.escape(word)}(?![\w(])", new, text), encoding="utf-8")


_LAST_SENSOR_MESSAGE = 'doc: "Both whiskers touched together."}\n'


def add_message(spec_dir: Path, name: str = "EXTRA", rest: str = 'doc: "x"') -> Path:
    """Append a message after OBJ_BOTH with the free opcode 0x5F; `rest` completes its mapping."""
    line = f'  - {{name: {name}, opcode: 0x5F, section: "3.2.12", from: [TPSC], to: [SPU], {rest}}}\n'
    return replace(spec_dir, M, _LAST_SENSOR_MESSAGE, _LAST_SENSOR_MESSAGE + line)


def refused_everywhere(tmp: Path, spec_dir: Path, file: str, expect: str,
                       commands: tuple[tuple[str, ...], ...] = (("spec", "check"), ("codegen",))) -> None:
    """Each command refuses the spec with file:line errors and leaves the spec and an output tree untouched."""
    out = tmp / "generated"
    if not out.exists():
        shutil.copytree(REPO / "generated", out, ignore=shutil.ignore_patterns("__pycache__"))
    before = snapshot(spec_dir, out)
    for command in commands:
        extra = ("--out", out) if command == ("codegen",) else ()
        assert_refused(cli(*command, "--spec", spec_dir, *extra), spec_dir / file, expect)
    assert snapshot(spec_dir, out) == before
