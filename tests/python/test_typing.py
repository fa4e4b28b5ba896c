"""Type stubs of the compiled module: generated at build time by nanobind's stubgen and
installed beside ``lugrip._core`` with ``py.typed``; mypy checks a user's script against them
(the examples pass, a wrong type is caught). No plant is involved."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
#: user scripts that must type-check against the installed lugrip (its stubs included)
TYPED_EXAMPLES = ("examples/01_limit_surface.py", "examples/04_robot_loop.py")


def _package_dir() -> Path:
    import lugrip

    return Path(lugrip.__file__).resolve().parent


def test_stubs_and_marker_are_installed_beside_the_module():
    """_core.pyi and py.typed sit in the installed package; the stub names every public
    attribute of the compiled module (classes, functions, constants)."""
    from lugrip import _core

    pkg = _package_dir()
    assert (pkg / "py.typed").is_file()
    stub = (pkg / "_core.pyi").read_text()
    declared = set(re.findall(r"^(?:class|def) (\w+)|^(\w+)\s*:", stub, re.MULTILINE))
    names = {a or b for a, b in declared}
    public = {n for n in dir(_core) if not n.startswith("_")}
    assert public and public <= names, sorted(public - names)


def _mypy(*paths: str | Path) -> subprocess.CompletedProcess:
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed (the [test] extra brings it)")
    return subprocess.run(
        [sys.executable, "-m", "mypy", "--follow-imports=silent", "--no-incremental",
         "--python-version", f"{sys.version_info[0]}.{sys.version_info[1]}", *map(str, paths)],
        capture_output=True, text=True, cwd=Path(paths[0]).parent, check=False)


def test_user_scripts_type_check():
    """The robot-loop and limit-surface examples: mypy reports no error."""
    run = _mypy(*(REPO / p for p in TYPED_EXAMPLES))
    assert run.returncode == 0, run.stdout + run.stderr
    assert "Success: no issues found in 2 source files" in run.stdout


def test_a_wrong_type_is_caught_through_the_stub(tmp_path):
    """A float from the compiled module assigned to a str: mypy reads the stub and refuses."""
    script = tmp_path / "user.py"
    script.write_text("from lugrip import _core\n\nxi: str = _core.shape_factor(4.0)\n")
    run = _mypy(script)
    assert run.returncode == 1, run.stdout + run.stderr
    assert 'expression has type "float", variable has type "str"' in run.stdout
