"""The lugrip command line: ls, params, demo and error handling."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import lugrip
from lugrip.cli import main


def test_ls_writes_both_figures_and_a_table_matching_the_core(tmp_path, capsys):
    """`lugrip ls` draws Figures 3 and 7 and prints LimitSurface values."""
    csv = tmp_path / "ls.csv"
    assert main(["ls", "--k", "2", "4", "inf", "--out", str(tmp_path), "--csv", str(csv)]) == 0
    for name in ("fig03_limit_surface_curves.png", "fig07_limit_surface.png"):
        path = tmp_path / name
        assert path.stat().st_size > 20_000
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    data = np.genfromtxt(csv, delimiter=",", names=True)
    assert set(data["k"]) == {2.0, 4.0, np.inf}
    for k in (2.0, 4.0, np.inf):
        rows = data[data["k"] == k]
        ls = lugrip.LimitSurface(k)
        np.testing.assert_allclose(rows["xi"], ls.xi, rtol=1e-12)
        np.testing.assert_allclose(rows["ft_star"], ls.ft_star(rows["c_tilde"]), atol=1e-12)
        np.testing.assert_allclose(rows["tau_star"], ls.tau_star(rows["c_tilde"]), atol=1e-12)


def test_params_yaml_round_trip(tmp_path, capsys):
    """`lugrip params --preset X` prints YAML that reads back as the preset."""
    for name in lugrip.PRESETS:
        assert main(["params", "--preset", name]) == 0
        text = capsys.readouterr().out
        path = tmp_path / f"{name}.yaml"
        path.write_text(text)
        assert lugrip.ContactParams.from_yaml(path) == lugrip.ContactParams.preset(name)
        assert main(["params", "--check", str(path)]) == 0
        capsys.readouterr()


def test_params_check_names_the_bad_field(tmp_path, capsys):
    """--check on an invalid file exits 2 with a message naming the field."""
    text = lugrip.ContactParams.table1().to_yaml().replace("value: 0.254", "value: 0.5")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    assert main(["params", "--check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "gamma" in err and "Traceback" not in err


@pytest.mark.parametrize("k", ["0", "-1", "abc", "0.1"])
def test_bad_k_is_a_clean_error(k, tmp_path, capsys):
    assert main(["ls", "--k", k, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "k" in err and "Traceback" not in err


def test_module_entry_point_and_version():
    out = subprocess.run([sys.executable, "-m", "lugrip.cli", "--version"], capture_output=True,
                         text=True, check=True)
    assert lugrip.__version__ in out.stdout
