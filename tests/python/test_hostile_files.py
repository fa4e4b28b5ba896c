"""Hostile parameter files through the CLI: every case exits with code 2 and one line on
stderr naming the file (and the field when there is one), without a traceback and without
echoing the value; the expensive ones (alias bomb, deep nesting, oversized file) run in a
child process whose CPU time and peak memory are measured (<= 5 s, <= 500 MB).

Invariant tests: no plant involved; the files are generated here.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lugrip.cli import main

GOOD = {"mu": 0.5, "beta_a": 1.0e7, "sigma0": 16.0, "sigma_z": 2.0, "delta": 0.0018, "gamma": 0.25}
GOOD_TEXT = "contact:\n" + "".join(f"  {k}: {v!r}\n" for k, v in GOOD.items())


def alias_bomb(levels: int = 9, width: int = 9) -> str:
    """Nested aliases: `levels` levels of `width` references each (width**levels values)."""
    names = [f"a{i}" for i in range(levels + 1)]
    lines = [f"{names[0]}: &{names[0]} [" + ", ".join(['"xxxxxxxx"'] * width) + "]"]
    for prev, name in zip(names, names[1:]):
        lines.append(f"{name}: &{name} [" + ", ".join([f"*{prev}"] * width) + "]")
    lines.append(f"contact: *{names[-1]}")
    return "\n".join(lines) + "\n"


HUGE_DIGITS = "7" * 400

# (name, file content, words the one-line error must contain besides the file name)
CASES = [
    ("contact_scalar", "contact: 5\n", ["contact", "mapping"]),
    ("contact_null", "contact: null\n", ["contact", "mapping"]),
    ("contact_list", "contact: [1, 2]\n", ["contact", "mapping"]),
    ("top_list", "- 1\n- 2\n", ["mapping"]),
    ("empty", "", ["empty"]),
    ("huge_integer", GOOD_TEXT.replace("mu: 0.5", f"mu: {HUGE_DIGITS}"), ["contact.mu", "too large"]),
    ("boolean", GOOD_TEXT.replace("mu: 0.5", "mu: true"), ["contact.mu", "boolean"]),
    ("text", GOOD_TEXT.replace("mu: 0.5", "mu: slippery"), ["contact.mu", "not a number"]),
    ("nested_value_list", GOOD_TEXT.replace("mu: 0.5", "mu: {value: [1, 2]}"), ["contact.mu.value"]),
    ("observer_inf", GOOD_TEXT + "observer: {max_invalid: .inf}\n", ["observer.max_invalid"]),
    ("observer_gain", GOOD_TEXT + "observer: {gain_mode: fixed, gain: -1}\n", ["observer.gain"]),
    ("observer_integrator", GOOD_TEXT + "observer: {integrator: 5}\n", ["observer.integrator"]),
    ("observer_unknown", GOOD_TEXT + "observer: {bogus: 1}\n", ["observer.bogus", "unknown"]),
    ("observer_scalar", GOOD_TEXT + "observer: 3000\n", ["observer", "mapping"]),
    ("observer_substeps", GOOD_TEXT + "observer: {substeps: 100000000, max_substeps: 100000000}\n",
     ["observer.max_substeps"]),
    ("unknown_key", GOOD_TEXT + "  friction: 3\n", ["contact.friction"]),
    ("syntax", "contact: [unclosed\n", ["YAML"]),
    ("deep_small", "[" * 40 + "]" * 40 + "\n", ["nested deeper"]),
    ("aliases_small", alias_bomb(4, 20), ["aliases"]),
]


@pytest.fixture(scope="module")
def log_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("log") / "log.csv"
    assert main(["simulate-sliding", "--out", str(path), "--maneuvers", "2", "--seed", "1"]) == 0
    return path


def _one_error_line(err: str, path) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert str(path) in lines[0]
    return lines[0]


@pytest.mark.parametrize("name, content, words", CASES, ids=[c[0] for c in CASES])
def test_params_check_rejects_hostile_file(name, content, words, tmp_path, capsys):
    path = tmp_path / f"{name}.yaml"
    path.write_text(content)
    assert main(["params", "--check", str(path)]) == 2
    line = _one_error_line(capsys.readouterr().err, path)
    for word in words:
        assert word in line, line
    assert HUGE_DIGITS not in line and "slippery" not in line  # values are not echoed


@pytest.mark.parametrize("name, content, words", [c for c in CASES if c[0].startswith("observer")
                                                  or c[0] in ("huge_integer", "boolean", "contact_null")],
                         ids=lambda c: c if isinstance(c, str) else "")
def test_observe_rejects_the_same_files(name, content, words, tmp_path, capsys, log_file):
    """`observe --params` and `params --check` agree (the observer block is checked alike)."""
    path = tmp_path / f"{name}.yaml"
    path.write_text(content)
    assert main(["observe", str(log_file), "--params", str(path), "--out",
                 str(tmp_path / "obs.csv")]) == 2
    line = _one_error_line(capsys.readouterr().err, path)
    for word in words:
        assert word in line, line


def test_encodings_and_binary(tmp_path, capsys):
    cases = {
        "utf16.yaml": (GOOD_TEXT.encode("utf-16"), "UTF-16"),
        "binary.yaml": (bytes(range(256)) * 8, "UTF-8"),
        "nul.yaml": (GOOD_TEXT.encode() + b"\x00\x01", "NUL"),
    }
    for name, (data, word) in cases.items():
        path = tmp_path / name
        path.write_bytes(data)
        assert main(["params", "--check", str(path)]) == 2, name
        assert word in _one_error_line(capsys.readouterr().err, path)


def test_missing_file_and_directory(tmp_path, capsys):
    assert main(["params", "--check", str(tmp_path / "nope.yaml")]) == 2
    _one_error_line(capsys.readouterr().err, tmp_path / "nope.yaml")
    assert main(["params", "--check", str(tmp_path)]) == 2
    _one_error_line(capsys.readouterr().err, tmp_path)


def test_debug_keeps_the_traceback(tmp_path, monkeypatch):
    path = tmp_path / "b.yaml"
    path.write_text("contact: 5\n")
    monkeypatch.setenv("LUGRIP_DEBUG", "1")
    with pytest.raises(ValueError, match="contact"):
        main(["params", "--check", str(path)])


def test_good_file_still_passes(tmp_path, capsys):
    path = tmp_path / "good.yaml"
    path.write_text(GOOD_TEXT + "observer: {integrator: rk4, gain_mode: fixed, gain: 300}\n")
    assert main(["params", "--check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "mu" in out and "observer settings (valid)" in out and "rk4" in out


# --- the expensive files, in a child process with measured CPU time and memory ---------------

_HWM_MARK = "lugrip-test-peak-rss-kB "

# The child reports its own peak resident set (VmHWM of the process image after exec): the
# ru_maxrss that wait4 returns also counts the pages of the forking parent (pytest, which holds
# hundreds of MB late in a full run), and would measure the test runner instead of lugrip.
_CHILD = (
    "import atexit, runpy, sys\n"
    "def _peak():\n"
    "    for line in open('/proc/self/status'):\n"
    "        if line.startswith('VmHWM:'):\n"
    f"            sys.stderr.write('\\n{_HWM_MARK}' + line.split()[1] + '\\n')\n"
    "atexit.register(_peak)\n"
    "sys.argv = ['lugrip'] + sys.argv[1:]\n"
    "runpy.run_module('lugrip', run_name='__main__')\n"
)


def _run_measured(args: list[str]) -> tuple[int, str, float, float]:
    """Runs `python -m lugrip ARGS`; returns (exit code, stderr, CPU seconds, peak RSS MB)."""
    proc = subprocess.Popen([sys.executable, "-c", _CHILD, *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, env={**os.environ, "LUGRIP_DEBUG": ""})
    start = time.monotonic()
    err = proc.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    assert time.monotonic() - start < 60
    body, mark, peak = err.rpartition(_HWM_MARK)
    assert mark, err
    return (proc.returncode, body.rstrip("\n") + "\n", usage.ru_utime + usage.ru_stime,
            float(peak) / 1024.0)


@pytest.mark.parametrize("name", ["alias_bomb", "nesting_100000", "oversized"])
def test_expensive_files_are_refused_quickly(name, tmp_path):
    path = tmp_path / f"{name}.yaml"
    if name == "alias_bomb":  # 1 KB on disk, 9**9 values expanded
        path.write_text(alias_bomb())
        assert path.stat().st_size < 1100
    elif name == "nesting_100000":
        path.write_text("[" * 100000 + "]" * 100000 + "\n")
    else:  # 2 MB of comments around a valid document
        path.write_text(GOOD_TEXT + ("# " + "x" * 98 + "\n") * 20000)
    code, err, cpu, rss = _run_measured(["params", "--check", str(path)])
    assert code == 2, err
    line = _one_error_line(err, path)
    assert len(line) < 600
    assert cpu <= 5.0, f"{cpu:.1f} s CPU"
    assert rss <= 500.0, f"{rss:.0f} MB"


# --- generated documents ------------------------------------------------------------------------

_scalars = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-(10**400), max_value=10**400),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=30),
    st.sampled_from([".inf", "-.inf", ".nan", "1e-3", "1e400", "0x10", "rk4", "fixed"]))
_values = st.recursive(_scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=10), inner, max_size=4)),
    max_leaves=12)
_fields = st.sampled_from(list(GOOD) + ["k", "c_max", "friction", ""])
_observer_keys = st.sampled_from(["gain", "gain_mode", "integrator", "max_invalid", "substeps",
                                  "max_substeps", "dt", "filter_force", "f_n_min", "torque_limit",
                                  "bogus"])


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(contact=st.dictionaries(_fields, _values, max_size=8),
       keep_good=st.booleans(),
       observer=st.one_of(st.none(), _values, st.dictionaries(_observer_keys, _values, max_size=4)),
       top=st.one_of(st.none(), _values))
def test_generated_documents(contact, keep_good, observer, top, tmp_path, capsys):
    """Random documents: exit 0 with valid parameters, or exit 2 with one line naming the
    file, never a traceback or another exit code."""
    body = {"contact": {**(GOOD if keep_good else {}), **contact}}
    if observer is not None:
        body["observer"] = observer
    doc = body if top is None else (top if not isinstance(top, dict) else {**top, **body})
    path = tmp_path / "gen.yaml"
    path.write_text(yaml.safe_dump(doc, allow_unicode=True))
    code = main(["params", "--check", str(path)])
    captured = capsys.readouterr()
    assert code in (0, 2), captured.err
    if code == 2:
        _one_error_line(captured.err, path)
    else:
        assert captured.err == ""


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(cut=st.integers(min_value=0, max_value=len(GOOD_TEXT)), junk=st.binary(max_size=40),
       at=st.integers(min_value=0, max_value=len(GOOD_TEXT)))
def test_mutated_bytes(cut, junk, at, tmp_path, capsys):
    """A valid file truncated and with random bytes spliced in: exit 0 or one line, exit 2."""
    data = GOOD_TEXT.encode()[:cut]
    data = data[:at] + junk + data[at:]
    path = tmp_path / "mut.yaml"
    path.write_bytes(data)
    code = main(["params", "--check", str(path)])
    captured = capsys.readouterr()
    assert code in (0, 2)
    if code == 2:
        _one_error_line(captured.err, path)


# --- logs and the catch-all of the entry point ----------------------------------------------------

def test_hostile_logs_give_one_line_naming_the_file(tmp_path, capsys, log_file):
    rows = log_file.read_text().splitlines()
    cases = {
        "utf16.csv": ("\n".join(rows).encode("utf-16"), "UTF-8"),
        "binary.csv": (bytes(range(256)) * 64, "UTF-8"),
        "bigcell.csv": (("\n".join(rows[:3]) + "\n" + "1" * 200_000 + "," + "\n".join(rows[3:9]) + "\n")
                        .encode(), "CSV"),
    }
    for name, (data, word) in cases.items():
        path = tmp_path / name
        path.write_bytes(data)
        code = main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "o.csv")])
        err = capsys.readouterr().err
        assert code == 2, (name, err)
        assert word in _one_error_line(err, path), name


def test_unexpected_exception_is_one_line_exit_1(monkeypatch, tmp_path, capsys):
    """A defect (an exception that is not a user error) is named in one line, exit code 1;
    LUGRIP_DEBUG=1 re-raises it."""
    import lugrip.commands.params as params_cmd

    def broken(args):
        raise TypeError("x" * 10_000)

    monkeypatch.setattr(params_cmd, "run", broken)
    assert main(["params", "--list"]) == 1
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "internal error: TypeError" in lines[0] and len(lines[0]) < 700
    assert "LUGRIP_DEBUG=1" in lines[0]
    monkeypatch.setenv("LUGRIP_DEBUG", "1")
    with pytest.raises(TypeError):
        main(["params", "--list"])


@pytest.mark.parametrize("exc, word", [(RecursionError("deep"), "nested"),
                                       (OverflowError("int too large"), "out of range"),
                                       (MemoryError(), "out of memory")])
def test_input_errors_are_exit_2(exc, word, monkeypatch, capsys):
    import lugrip.commands.params as params_cmd

    def raising(args):
        raise exc

    monkeypatch.setattr(params_cmd, "run", raising)
    assert main(["params", "--list"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and word in lines[0]
