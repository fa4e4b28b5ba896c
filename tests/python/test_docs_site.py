"""The documentation site (mkdocs.yml, docs/): it builds with --strict (no warning, no broken
page link or anchor), every public Python name and every C++ public header is in its API
reference, and every page is in its navigation. No plant is involved."""

from __future__ import annotations

import importlib
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "docs" / "hooks"))
import cpp_api  # the hook that writes the C++ reference

#: the modules whose ``__all__`` is lugrip's public Python API
PUBLIC_MODULES = ("lugrip", "lugrip.io", "lugrip.identification", "lugrip.sliding",
                  "lugrip.sim", "lugrip.sim.scenarios", "lugrip.sim.faults", "lugrip.campaign",
                  "lugrip.campaign.replay", "lugrip.rigs", "lugrip.plot", "lugrip.ros")


def test_every_public_subpackage_is_listed():
    """Each subpackage of lugrip without a leading underscore is one of PUBLIC_MODULES, and
    each of them has a `:::` block on the Python API page."""
    pkg = REPO / "python" / "lugrip"
    subs = {f"lugrip.{p.name}" for p in pkg.iterdir()
            if p.is_dir() and (p / "__init__.py").is_file() and not p.name.startswith("_")
            and p.name not in ("commands",)}  # the command line, documented by --help
    assert subs <= set(PUBLIC_MODULES), sorted(subs - set(PUBLIC_MODULES))
    page = (REPO / "docs" / "api" / "python.md").read_text()
    blocks = set(re.findall(r"^::: ([\w.]+)$", page, re.MULTILINE))
    assert set(PUBLIC_MODULES) <= blocks, sorted(set(PUBLIC_MODULES) - blocks)
    assert "lugrip._core" in blocks


def test_cpp_reference_has_every_header_and_type():
    """The generated C++ page has a section per public header and a heading per type declared
    at namespace scope (found here by a separate scan: unindented struct/class/enum lines)."""
    text = cpp_api.render()
    headers = cpp_api.public_headers()
    assert len(headers) >= 10
    for h in headers:
        assert f"## `lugrip/{h.name}`" in text, h.name
        for kind, name in re.findall(r"^(struct|class|enum class) (\w+)[^;]*$",
                                     h.read_text(), re.MULTILINE):
            kind = "enum" if kind == "enum class" else kind
            assert f"### {kind} `{name}`" in text, (h.name, name)
    assert "`f_max`" in text and "`ObserverSettings`" in text
    assert cpp_api.MARKER in (REPO / "docs" / "api" / "cpp.md").read_text()


def test_every_page_is_in_the_navigation():
    """Each docs/*.md (and api/*.md) is a page of the site's navigation."""
    nav = (REPO / "mkdocs.yml").read_text()
    pages = [p.relative_to(REPO / "docs").as_posix() for p in (REPO / "docs").rglob("*.md")]
    missing = [p for p in pages if f": {p}" not in nav]
    assert not missing, missing


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    if importlib.util.find_spec("mkdocs") is None:
        pytest.skip("mkdocs is not installed (the [docs] extra; make install brings it)")
    out = tmp_path_factory.mktemp("site")
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d",
                          str(out)], cwd=REPO, capture_output=True, text=True, check=False,
                         env={**__import__("os").environ, "NO_MKDOCS_2_WARNING": "1"})
    assert run.returncode == 0, run.stdout + run.stderr
    assert "WARNING" not in run.stderr, run.stderr
    return out


def test_site_builds_strict_with_every_python_name(site):
    """`mkdocs build --strict` (warnings, broken page links and anchors are errors) succeeds
    and the Python reference has an anchor for every name in every public module's __all__
    and every public attribute of the compiled module (from its stubs)."""
    html = (site / "api" / "python" / "index.html").read_text()
    ids = set(re.findall(r'id="([\w.]+)"', html))
    missing = []
    for name in PUBLIC_MODULES:
        module = importlib.import_module(name)
        missing += [f"{name}.{n}" for n in module.__all__ if f"{name}.{n}" not in ids]
    core = importlib.import_module("lugrip._core")
    missing += [f"lugrip._core.{n}" for n in dir(core)
                if not n.startswith("_") and f"lugrip._core.{n}" not in ids]
    assert not missing, missing
    cpp = (site / "api" / "cpp" / "index.html").read_text()
    for h in cpp_api.public_headers():
        assert f"lugrip/{h.name}" in cpp, h.name


def test_pages_cited_by_the_help_are_installed(capsys):
    """The wheel carries docs/ as lugrip/data/docs and `lugrip --help` says where the pages
    it cites are; every docs/<page>.md that a command's help names exists there."""
    from lugrip._data import docs_dir
    from lugrip.cli import main

    where = docs_dir()
    assert where is not None and (where / "sliding_log.md").is_file()
    if sys.version_info >= (3, 11):
        import tomllib

        cfg = tomllib.loads((REPO / "pyproject.toml").read_text())
        assert cfg["tool"]["scikit-build"]["wheel"]["packages"]["lugrip/data/docs"] == "docs"
    assert main(["--help"]) == 0
    assert "docs/*.md are in" in " ".join(capsys.readouterr().out.split())
    cited = set()
    for path in (REPO / "python" / "lugrip" / "commands").glob("*.py"):
        cited |= set(re.findall(r"docs/(\w+)\.md", path.read_text()))
    assert cited and all((where / f"{name}.md").is_file() for name in cited), cited
