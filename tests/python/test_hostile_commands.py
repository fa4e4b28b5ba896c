"""Bad command-line values and scenario files end in exit 2 with one line naming the field
(no traceback): cases the file readers alone do not cover."""

from __future__ import annotations

import re
import pytest

from lugrip._data import data_dir
from lugrip.cli import main


def _one_line_exit_2(capsys, argv) -> str:
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    return err


@pytest.mark.parametrize("count", ["0", "-3", "1", "x"])
def test_identify_bootstrap_count_is_checked(tmp_path, capsys, count):
    """--bootstrap 0 / -3 / 1 / x: refused before any work (was an IndexError traceback)."""
    log = tmp_path / "log.csv"
    log.write_text("t,f_n,f_t,tau,omega\n0,1,0.1,0.0,0\n0.002,1,0.1,0.0,0\n")
    err = _one_line_exit_2(capsys, ["identify", log, "--uncertainty", "bootstrap",
                                    "--bootstrap", count, "--out", tmp_path / "p.yaml"])
    assert "--bootstrap" in err


def _scenario_text() -> str:
    return (data_dir("scenarios") / "exp1_big_resin_block.yaml").read_text()


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda s: re.sub(r"^duration:.*$", "duration: abc", s, flags=re.M), "duration"),
        (lambda s: re.sub(r"^  model: patch$", "  model: [patch]", s, flags=re.M), "plant.model"),
        (lambda s: re.sub(r"^plant:\n(  .*\n)+", "plant: 5\n", s, flags=re.M), "plant"),
        (lambda s: re.sub(r"^steady_window:.*$", "steady_window: [1]", s, flags=re.M),
         "steady_window"),
    ],
    ids=["duration-text", "model-list", "plant-number", "steady-window-short"],
)
def test_bad_scenario_fields_are_named(tmp_path, capsys, edit, field):
    """A scenario with a bad field: exit 2, one line naming the file and the field."""
    text = _scenario_text()
    bad = edit(text)
    assert bad != text  # the edit applied
    path = tmp_path / "bad.yaml"
    path.write_text(bad)
    err = _one_line_exit_2(capsys, ["simulate", path, "--out", tmp_path / "out"])
    assert str(path) in err and field in err
