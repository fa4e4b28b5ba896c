"""Data shipped with the package: the scenarios and object files are found from any working
directory (the installed copy under lugrip/data, or the repository's top-level directories
in a source tree), and the wheel configuration maps exactly those directories."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from lugrip._data import DATA_KINDS, data_dir
from lugrip.sim.scenarios import find_scenario, list_scenarios, scenario_dir

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("kind", DATA_KINDS)
def test_data_found_from_another_directory(tmp_path, monkeypatch, kind):
    """From an empty directory, data_dir() finds the shipped files, same names as the
    repository's."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("LUGRIP_SCENARIOS", raising=False)
    d = data_dir(kind)
    assert d is not None
    assert sorted(p.name for p in d.glob("*.yaml")) == \
        sorted(p.name for p in (REPO / kind).glob("*.yaml"))
    with pytest.raises(ValueError, match="unknown data kind"):
        data_dir("nonsense")


def test_scenarios_resolve_by_name_outside_the_repository(tmp_path, monkeypatch):
    """`lugrip simulate exp1_big_resin_block` and the demo look scenarios up by name: that
    works from a directory without scenarios/."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("LUGRIP_SCENARIOS", raising=False)
    assert scenario_dir() is not None
    names = list_scenarios()
    assert "exp1_big_resin_block" in names
    assert find_scenario("exp1_big_resin_block").is_file()


def test_wheel_maps_the_data_directories():
    """pyproject.toml puts scenarios/ and objects/ into the wheel as lugrip/data/<kind>."""
    if sys.version_info < (3, 11):
        pytest.skip("tomllib needs Python 3.11")
    import tomllib

    cfg = tomllib.loads((REPO / "pyproject.toml").read_text())
    packages = cfg["tool"]["scikit-build"]["wheel"]["packages"]
    assert packages["lugrip"] == "python/lugrip"
    for kind in DATA_KINDS:
        assert packages[f"lugrip/data/{kind}"] == kind
