"""Check, and repair if needed, the MuJoCo installed in this Python environment.

MuJoCo 4.0 split the single ``mujoco`` wheel into ``mujoco`` (a thin package), ``mujoco-core``
(the bindings) and ``mujoco-studio``, all writing into the same ``mujoco/`` directory. pip
upgrading a 3.x environment in place installs the new ``mujoco-core`` first and then removes
the old ``mujoco``'s files, among them files ``mujoco-core`` had just written: ``import mujoco``
then fails ("core bindings ... missing or corrupted") or, with stale files left, reports the old
version. A fresh environment is not affected. This script imports MuJoCo in a subprocess and,
when the import fails or its version differs from the installed distribution's, reinstalls the
distributions of that version without dependencies (what MuJoCo's own message advises).

Usage: python .ci/mujoco_install.py   (exit 0: MuJoCo imports at the installed version)
"""

from __future__ import annotations

import subprocess
import sys
from importlib import metadata

_PROBE = "import mujoco; print(mujoco.__version__)"


def _imported_version() -> str | None:
    run = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True,
                         check=False)
    return run.stdout.strip() if run.returncode == 0 else None


def main() -> int:
    try:
        want = metadata.version("mujoco")
    except metadata.PackageNotFoundError:
        print("mujoco is not installed", file=sys.stderr)
        return 1
    got = _imported_version()
    if got == want:
        return 0
    parts = ["mujoco"]
    if int(want.split(".")[0]) >= 4:
        parts += ["mujoco-core", "mujoco-studio"]
    print(f"MuJoCo {want} is installed but imports as {got or 'nothing (broken)'}: "
          f"reinstalling {', '.join(parts)} {want}", file=sys.stderr)
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--force-reinstall",
                    "--no-deps", *(f"{p}=={want}" for p in parts)], check=True)
    got = _imported_version()
    if got != want:
        print(f"MuJoCo still imports as {got}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
