"""The lugrip command line: ls, params, demo and error handling."""

from __future__ import annotations

import io
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


def test_ls_stdout_table_matches_the_core_and_the_sign_convention(tmp_path, capsys):
    """The printed table holds LimitSurface values: f~* < 0 for c~ > 0, tau~* > 0, xi(k)."""
    assert main(["ls", "--k", "4", "2", "--c", "0", "0.5", "1", "-1", "--no-plot"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    xi_line = next(line for line in lines if line.strip().startswith("xi(k)"))
    np.testing.assert_allclose([float(v) for v in xi_line.split()[1:]],
                               [lugrip.shape_factor(4), lugrip.shape_factor(2)], atol=1e-8)
    rows = {}
    for line in lines:
        parts = line.split()
        try:
            values = [float(v) for v in parts]
        except ValueError:
            continue
        if len(values) == 5:
            rows[values[0]] = values[1:]
    assert sorted(rows) == [-1.0, 0.0, 0.5, 1.0]
    for c, (f4, t4, f2, t2) in rows.items():
        for k, f, t in ((4.0, f4, t4), (2.0, f2, t2)):
            ls = lugrip.LimitSurface(k)
            assert f == pytest.approx(float(ls.ft_star(c)), abs=1e-8)
            assert t == pytest.approx(float(ls.tau_star(c)), abs=1e-8)
    assert rows[1.0][0] == pytest.approx(-0.8640993375, abs=1e-8)  # docs/model.md 3.4
    assert rows[0.5][2] == pytest.approx(-0.5522330836, abs=1e-8)  # k = 2, docs/model.md 3.2
    assert rows[-1.0][0] == -rows[1.0][0] and rows[-1.0][1] == rows[1.0][1]
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("fmt, magic", [("pdf", b"%PDF-"), ("svg", b"<?xml")])
def test_ls_other_formats(fmt, magic, tmp_path, capsys):
    assert main(["ls", "--k", "4", "--c-max", "2", "--format", fmt, "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    for name in ("fig03_limit_surface_curves", "fig07_limit_surface"):
        assert (tmp_path / f"{name}.{fmt}").read_bytes().startswith(magic)


@pytest.mark.parametrize("argv, words", [
    (["ls", "--c-max", "-2"], ["--c-max", "-2"]),
    (["ls", "--format", "gif"], ["--format", "gif"]),
    (["ls", "--c", "1", "nan"], ["--c"]),
    (["params"], ["--preset", "--list", "--check"]),
    (["params", "--preset", "glass"], ["glass", "table1"]),
    (["params", "--list", "--preset", "table1"], ["not allowed"]),
    (["demo", "--only", "nothing"], ["nothing", "ls"]),
    ([], ["command"]),
    (["frobnicate"], ["frobnicate"]),
])
def test_usage_errors_exit_2_with_one_line(argv, words, tmp_path, capsys):
    """Bad arguments: exit code 2, one line on stderr naming the argument, no traceback."""
    assert main(argv + (["--out", str(tmp_path)] if argv[:1] in (["ls"], ["demo"]) else [])) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert err.startswith("lugrip")
    for word in words:
        assert word in err


def test_ls_out_must_be_a_directory(tmp_path, capsys):
    target = tmp_path / "file.png"
    target.write_text("x")
    assert main(["ls", "--k", "4", "--out", str(target)]) == 2
    assert str(target) in capsys.readouterr().err
    assert target.read_text() == "x"


@pytest.mark.parametrize("content, words", [
    ("contact:\n  mu: {value: 0.5}\n", ["missing", "beta_a"]),
    ("mu: 0.5\nbeta_a: 1e7\nsigma0: 16\nsigma_z: 2\ndelta: 0.0018\ngamma: 0.25\nfriction: 1\n",
     ["friction"]),
    ("mu: abc\nbeta_a: 1e7\nsigma0: 16\nsigma_z: 2\ndelta: 0.0018\ngamma: 0.25\n", ["mu", "not a number"]),
    ("mu: 0.5\nbeta_a: -1\nsigma0: 16\nsigma_z: 2\ndelta: 0.0018\ngamma: 0.25\n", ["beta_a"]),
    ("[1, 2, 3]\n", ["mapping"]),
    ("mu: [unclosed\n", ["YAML"]),
])
def test_params_check_rejects_bad_files(content, words, tmp_path, capsys):
    """--check names the file and the offending field; exit code 2."""
    path = tmp_path / "p.yaml"
    path.write_text(content)
    assert main(["params", "--check", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    for word in words:
        assert word in err


def test_params_check_missing_file(tmp_path, capsys):
    missing = tmp_path / "nope.yaml"
    assert main(["params", "--check", str(missing)]) == 2
    assert str(missing) in capsys.readouterr().err


def test_params_check_prints_derived_quantities(tmp_path, capsys):
    """--check prints xi, rho and tau_max at 1 and 5 N (Table 1: rho(1 N) = delta)."""
    path = tmp_path / "t1.yaml"
    path.write_text(lugrip.ContactParams.table1().to_yaml())
    assert main(["params", "--check", str(path)]) == 0
    out = capsys.readouterr().out
    p = lugrip.ContactParams.table1()
    assert f"{p.xi:.8f}" in out
    rows = [line.split() for line in out.splitlines() if line.split()[:1] in (["1"], ["5"])]
    assert len(rows) == 2
    for (fn, rho_mm, ftmax, taumax_nmm) in rows:
        fn = float(fn)
        rho = 0.0018 * fn**0.254
        assert float(rho_mm) == pytest.approx(rho * 1e3, rel=1e-4)
        assert float(ftmax) == pytest.approx(0.47 * fn, rel=1e-4)
        assert float(taumax_nmm) == pytest.approx(0.47 * p.xi * rho * fn * 1e3, rel=1e-4)


def test_params_list_names_every_preset(capsys):
    assert main(["params", "--list"]) == 0
    out = capsys.readouterr().out
    assert [line.split()[0] for line in out.splitlines()] == list(lugrip.PRESETS)


def test_objects_directory_is_what_lugrip_params_writes(capsys):
    """objects/*.yaml are exactly `lugrip params --preset NAME` (regenerate them if this fails)."""
    from pathlib import Path

    objects = Path(__file__).resolve().parents[2] / "objects"
    files = {"table1": "table1_cardboard.yaml", **{n: f"{n}.yaml" for n in lugrip.PRESETS[1:]}}
    for preset, name in files.items():
        assert main(["params", "--preset", preset]) == 0
        assert (objects / name).read_text() == capsys.readouterr().out, name
        assert lugrip.ContactParams.from_yaml(objects / name) == lugrip.ContactParams.preset(preset)


def test_demo_writes_report_and_figures(tmp_path, capsys):
    """`lugrip demo --only ls` writes the LS figures and report.md embedding them."""
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--only", "ls"]) == 0
    capsys.readouterr()
    report = (out / "report.md").read_text()
    assert report.startswith("# lugrip demo report")
    assert lugrip.__version__ in report
    for name in ("fig03_limit_surface_curves.png", "fig07_limit_surface.png"):
        assert f"]({name})" in report
        assert (out / name).stat().st_size > 20_000
    assert f"{lugrip.shape_factor(4):.8f}" in report and "| ls | ok |" in report


def test_demo_reports_a_failing_step_and_runs_the_others(tmp_path):
    """A failing step is recorded in the report and does not stop the next one."""
    from lugrip.commands.demo import DemoStep, run_demo

    def boom(out_dir):
        raise RuntimeError("step exploded")

    steps = [DemoStep("bad", "Bad step", boom),
             DemoStep("good", "Good step", lambda out_dir: "all fine")]
    log = io.StringIO()
    path, failed = run_demo(tmp_path, steps, log=log)
    report = path.read_text()
    assert failed == ["bad"]
    assert "step exploded" in report and "all fine" in report and "| bad | FAILED |" in report
    assert "bad: FAILED" in log.getvalue() and "good: ok" in log.getvalue()


def test_demo_chooses_the_gl_back_end_before_its_steps(tmp_path, monkeypatch):
    """With the mujoco step selected, `lugrip demo` picks the offscreen back end before any step
    runs (MuJoCo fixes it at import, and an earlier step imports MuJoCo); without it, never."""
    from lugrip.commands import demo
    from lugrip.sim import report

    calls = []
    monkeypatch.setattr(report, "choose_gl_backend", lambda: calls.append("gl") or "osmesa")
    fake = [demo.DemoStep("ls", "LS", lambda out_dir: calls.append("ls") or "ok"),
            demo.DemoStep("mujoco", "MuJoCo", lambda out_dir: calls.append("mujoco") or "ok",
                          renders=True)]
    monkeypatch.setattr(demo, "STEPS", fake)
    assert main(["demo", "--out", str(tmp_path / "a")]) == 0
    assert calls == ["gl", "ls", "mujoco"]
    calls.clear()
    assert main(["demo", "--out", str(tmp_path / "b"), "--only", "ls"]) == 0
    assert calls == ["ls"]


def test_every_registered_command_has_help(capsys):
    """Each module of lugrip.commands.COMMANDS registers a subcommand listed in --help."""
    import importlib

    from lugrip.commands import COMMANDS

    assert main(["--help"]) == 0
    top = capsys.readouterr().out
    for name in COMMANDS:
        module = importlib.import_module(f"lugrip.commands.{name}")
        assert callable(module.register) and callable(module.run)
        sub = name.replace("_", "-")
        assert sub in top
        assert main([sub, "--help"]) == 0
        assert f"usage: lugrip {sub}" in capsys.readouterr().out


def test_module_entry_point_runs_ls_and_reports_errors(tmp_path):
    """`python -m lugrip.cli` prints the table; a bad --k gives exit code 2 and one line."""
    ok = subprocess.run([sys.executable, "-m", "lugrip.cli", "ls", "--k", "4", "--c", "1",
                         "--no-plot"], capture_output=True, text=True, timeout=60)
    assert ok.returncode == 0, ok.stderr
    assert "-0.86409934" in ok.stdout and "0.40290761" in ok.stdout
    bad = subprocess.run([sys.executable, "-m", "lugrip.cli", "ls", "--k", "four", "--out",
                          str(tmp_path)], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2
    assert bad.stderr.strip().splitlines() == [
        "lugrip ls: error: argument --k: invalid value 'four': expected a positive number, "
        "'inf' or 'ellipse' (see 'lugrip ls --help')"]


def test_ls_lists_and_plots_the_ellipse(tmp_path, capsys):
    """`lugrip ls --k ellipse` prints the elliptic limit surface (k = 0): at c~ = xi the
    closed form gives f~* = -1/sqrt(2), tau~* = 1/sqrt(2); the figure is written."""
    xi = lugrip.shape_factor(4.0)
    assert main(["ls", "--k", "ellipse", "4", "--c", f"{xi!r}", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "k = ellipse" in out
    row = next(line.split() for line in out.splitlines() if line.split()[:1] == ["0.6354"])
    np.testing.assert_allclose([float(row[1]), float(row[2])], [-2**-0.5, 2**-0.5], atol=1e-6)
    assert any(tmp_path.iterdir())
