"""Dependencies and import: the lower bounds `make test-oldest` installs are pyproject.toml's,
`import lugrip` leaves scipy.optimize (and the plotting and simulation stacks) unimported, and a
broken optional package is named with the reason it failed, not "install the extra". No plant
is involved."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _pyproject():
    if sys.version_info < (3, 11):
        pytest.skip("tomllib needs Python 3.11")
    import tomllib

    return tomllib.loads((REPO / "pyproject.toml").read_text())


def _oldest_pins() -> dict[str, str]:
    text = (REPO / "Makefile").read_text().replace("\\\n", " ")
    line = re.search(r"^OLDEST :=(.*)$", text, re.MULTILINE)
    assert line, "Makefile has no OLDEST list"
    return dict(item.split("==") for item in line.group(1).split())


def test_oldest_versions_are_the_lower_bounds():
    """Every package with a lower bound in [project] dependencies or the [io] extra is pinned
    by `make test-oldest` at a release of that bound's major.minor that the bound allows."""
    from packaging.requirements import Requirement

    cfg = _pyproject()["project"]
    pins = {k.lower(): v for k, v in _oldest_pins().items()}
    reqs = [Requirement(r) for r in cfg["dependencies"] + cfg["optional-dependencies"]["io"]]
    for req in reqs:
        lows = [s.version for s in req.specifier if s.operator == ">="]
        assert lows, f"{req} has no lower bound"
        name = req.name.lower()
        assert name in pins, f"make test-oldest does not pin {name}"
        assert req.specifier.contains(pins[name]), (name, pins[name], str(req.specifier))
        assert pins[name].split(".")[:2] == (lows[0].split(".") + ["0"])[:2], (name, pins[name])
    assert set(pins) == {r.name.lower() for r in reqs}


def test_mujoco_is_not_capped_below_4():
    """MuJoCo 4.x is allowed wherever MuJoCo is required."""
    from packaging.requirements import Requirement

    cfg = _pyproject()["project"]
    every = cfg["dependencies"] + [r for extra in cfg["optional-dependencies"].values()
                                   for r in extra]
    mujoco = [Requirement(r) for r in every if Requirement(r).name == "mujoco"]
    assert mujoco
    for req in mujoco:
        assert req.specifier.contains("4.0.0") and req.specifier.contains("4.5.0"), str(req)


def test_import_lugrip_leaves_heavy_modules_unimported():
    """A fresh interpreter's `import lugrip` imports neither scipy.optimize (identification
    imports it on first fit) nor matplotlib, mujoco or pyarrow."""
    code = ("import sys, lugrip; print(' '.join(m for m in ('scipy.optimize', 'matplotlib', "
            "'mujoco', 'pyarrow') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""


def _fake_package(tmp_path: Path, name: str, body: str) -> None:
    (tmp_path / name).mkdir()
    (tmp_path / name / "__init__.py").write_text(body)


def test_broken_package_is_named_with_its_reason(tmp_path, monkeypatch):
    """An installed package that raises while importing (as pyarrow 26 does under numpy 1.x)
    is reported as installed-but-broken with its exception, not as a missing extra."""
    from lugrip.io import MissingExtraError, need

    _fake_package(tmp_path, "lugrip_fake_broken",
                  'raise ImportError("lugrip_fake_broken requires NumPy 9.0 or newer")\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(MissingExtraError) as info:
        need("lugrip_fake_broken", "reading FAKE")
    text = str(info.value)
    assert "installed but failed to import" in text
    assert "requires NumPy 9.0 or newer" in text and "numpy" in text.lower()
    assert "pip install 'lugrip[io]'" not in text
    assert info.value.broken is not None


def test_missing_submodule_of_an_installed_package_is_broken(tmp_path, monkeypatch):
    """A package present without the submodule asked for is broken, not absent."""
    from lugrip.io import MissingExtraError, need

    _fake_package(tmp_path, "lugrip_fake_partial", "")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(MissingExtraError) as info:
        need("lugrip_fake_partial.writer", "writing FAKE")
    assert "installed but failed to import" in str(info.value)
    assert "lugrip_fake_partial.writer" in str(info.value)


def test_absent_package_names_the_extra():
    """A package that is not installed at all: the message says which extra installs it."""
    from lugrip.io import MissingExtraError, need

    with pytest.raises(MissingExtraError) as info:
        need("lugrip_fake_absent_package.sub", "reading FAKE")
    assert "pip install 'lugrip[io]'" in str(info.value)
    assert info.value.broken is None


def test_decoder_bare_assertion_reads_as_size_mismatch():
    """rosbags before 0.11.6 signals a payload longer than its type by a bare assert."""
    from lugrip.io._extras import decode_error_text

    assert "size mismatch" in decode_error_text(AssertionError())
    assert decode_error_text(ValueError("bad")) == "ValueError: bad"
