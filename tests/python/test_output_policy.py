"""The output policy of every command (python/lugrip/commands/_output.py, docs/reliability.md):
an output that is an input, a device, a FIFO or a directory is refused even with --force; an
existing file is replaced only with --force and then atomically; a result folder holding an
earlier run's files is refused without --force; nothing is left behind. Every case checks the
user's files byte for byte (SHA-256 before and after)."""

from __future__ import annotations

import hashlib
import os
import signal
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from lugrip.cli import main
from lugrip.commands._output import (
    OutputError,
    atomic_write_text,
    check_dir,
    check_file,
    staged_path,
)

CAMPAIGN = Path(__file__).resolve().parents[2] / "campaigns" / "patch_blocks.yaml"
_LOG_HEAD = "t,f_n,f_t,tau,omega,maneuver\n"


def _sha(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _log(path: Path, n: int = 400) -> Path:
    """A small sliding log (a slow rotation at 500 Hz) written by the test itself."""
    rows = [_LOG_HEAD]
    for i in range(n):
        t = 0.002 * i
        rows.append(f"{t!r},5.0,0.2,{-0.001 * min(i, 200) / 200!r},{0.0 if i < 200 else 0.05},0\n")
    path.write_text("".join(rows))
    return path



def _leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir()
                  if p.name.startswith(".") and (".part" in p.name or "probe" in p.name
                                                 or p.name.endswith(".tmp")))


# --- an output that is an input -----------------------------------------------------------

def test_identify_refuses_its_own_input_even_with_force(exit_2, tmp_path):
    """`identify x.csv --out x.csv --force` (the log became an 8 KB YAML): exit 2, the log
    unchanged; also through a symbolic link, a '..' path and a hard link."""
    log = _log(tmp_path / "x.csv")
    before = _sha(log)
    (tmp_path / "link.csv").symlink_to(log)
    os.link(log, tmp_path / "hard.csv")
    (tmp_path / "sub").mkdir()
    for out in (log, tmp_path / "link.csv", tmp_path / "sub" / ".." / "x.csv",
                tmp_path / "hard.csv"):
        err = exit_2(["identify", log, "--out", out, "--force", "--quiet",
                               "--max-iterations", "1"])
        assert "replace the input" in err and "--out" in err
    assert _sha(log) == before
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("command", ["observe", "replay"])
def test_observe_and_replay_refuse_their_input(exit_2, tmp_path, command):
    log = _log(tmp_path / "x.csv")
    before = _sha(log)
    extra = ["--preset", "table1"]
    err = exit_2([command, log, *extra, "--out", log, "--force"])
    assert "replace the input" in err
    assert _sha(log) == before


def test_identify_rubbing_refuses_params0_as_output(exit_2, tmp_path, capsys):
    """The --params0 file is an input too: `--out` naming it is refused."""
    p0 = tmp_path / "p0.yaml"
    assert main(["params", "--preset", "table1"]) == 0
    p0.write_text(capsys.readouterr().out)
    log = _log(tmp_path / "x.csv")
    before = _sha(p0)
    err = exit_2(["identify", log, "--rubbing", "--params0", p0, "--out", p0,
                           "--force"])
    assert "p0.yaml" in err and "replace the input" in err
    assert _sha(p0) == before


# --- special files --------------------------------------------------------------------------

def test_special_files_are_refused_even_with_force(exit_2, tmp_path):
    """A FIFO, a symbolic link to a FIFO, a character device (/dev/null) and a directory are
    not regular files: exit 2 with --force, and they stay what they were."""
    log = _log(tmp_path / "x.csv")
    fifo = tmp_path / "f.csv"
    os.mkfifo(fifo)
    link = tmp_path / "l.csv"
    link.symlink_to(fifo)
    folder = tmp_path / "d.csv"
    folder.mkdir()
    cases = [
        (["observe", log, "--preset", "table1", "--out", fifo, "--force"], "a FIFO"),
        (["observe", log, "--preset", "table1", "--out", link, "--force"], "a FIFO"),
        (["observe", log, "--preset", "table1", "--out", folder, "--force"], "a directory"),
        (["simulate-sliding", "--out", fifo, "--maneuvers", "1", "--force"], "a FIFO"),
        (["identify", log, "--out", "/dev/null", "--force", "--quiet"], "character device"),
        (["ls", "--k", "4", "--no-plot", "--csv", "/dev/null", "--force"], "character device"),
    ]
    for argv, kind in cases:
        err = exit_2(argv)
        assert kind in err and "regular file" in err or kind == "a directory" and kind in err, err
    assert stat.S_ISFIFO(os.stat(fifo).st_mode) and os.path.islink(link)
    assert folder.is_dir() and not any(folder.iterdir())
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert _leftovers(tmp_path) == []


def test_check_file_refuses_a_dangling_link_and_a_file_as_parent(tmp_path):
    (tmp_path / "dangling.csv").symlink_to(tmp_path / "nowhere.csv")
    with pytest.raises(OutputError, match="missing file"):
        check_file(tmp_path / "dangling.csv", force=True)
    (tmp_path / "plain").write_text("x")
    with pytest.raises(OutputError, match="not a directory"):
        check_file(tmp_path / "plain" / "out.csv", force=True, create_parent=True)
    with pytest.raises(OutputError, match="does not exist"):
        check_file(tmp_path / "missing" / "out.csv", force=True)


# --- --force: atomic replacement of a regular file ---------------------------------------

def test_existing_output_needs_force_and_is_replaced_atomically(exit_2, tmp_path, capsys):
    log = _log(tmp_path / "x.csv")
    out = tmp_path / "e.csv"
    out.write_text("the user's file\n")
    os.chmod(out, 0o600)
    before = _sha(out)
    err = exit_2(["observe", log, "--preset", "table1", "--out", out])
    assert "exists; pass --force" in err and _sha(out) == before
    inode = os.stat(out).st_ino
    assert main(["observe", str(log), "--preset", "table1", "--out", str(out), "--force"]) == 0
    capsys.readouterr()
    assert out.read_text().startswith("t,omega_hat")
    assert os.stat(out).st_ino != inode  # a new file renamed over the old one
    assert stat.S_IMODE(os.stat(out).st_mode) == 0o600  # the permissions kept
    assert _leftovers(tmp_path) == []


def test_force_through_a_link_replaces_the_link_target(tmp_path):
    target = tmp_path / "real.txt"
    target.write_text("old")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    atomic_write_text(link, "new", force=True)
    assert link.is_symlink() and target.read_text() == "new"


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    out = tmp_path / "o.csv"
    out.write_text("old contents\n")
    before = _sha(out)
    with pytest.raises(RuntimeError), staged_path(out, force=True) as tmp:
        tmp.write_text("half")
        raise RuntimeError("disk full")
    assert _sha(out) == before and _leftovers(tmp_path) == []


def test_disk_full_names_the_output_and_keeps_the_old_file(tmp_path):
    """ENOSPC while writing: one line naming the output (not the temporary), the old file
    intact, no temporary left."""
    import errno

    out = tmp_path / "o.csv"
    out.write_text("old\n")
    before = _sha(out)

    def body(fh):
        fh.write(b"partial")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    from lugrip.commands._output import atomic_write

    with pytest.raises(OutputError, match=r"cannot write .*o\.csv: No space left on device"):
        atomic_write(out, body, force=True)
    assert _sha(out) == before and _leftovers(tmp_path) == []


def test_a_file_created_during_the_work_is_not_replaced_without_force(tmp_path):
    out = tmp_path / "o.csv"
    check_file(out, force=False)
    with pytest.raises(OutputError, match="exists"), staged_path(out, force=False) as tmp:
        tmp.write_text("ours")
        out.write_text("someone else's")  # appears between the check and the rename
    assert out.read_text() == "someone else's" and _leftovers(tmp_path) == []


def test_writability_is_checked_before_the_work(exit_2, tmp_path):
    """An output below a regular file (cannot exist): exit 2 at once, before the fit."""
    log = _log(tmp_path / "x.csv")
    (tmp_path / "file").write_text("x")
    err = exit_2(["identify", log, "--out", tmp_path / "file" / "p.yaml"])
    assert "--out" in err


def _make_unwritable(folder: Path):
    """Make ``folder`` unwritable for this process; returns the undo. Root writes in a folder
    of mode 0555, so as root the folder is made immutable (chattr +i, which binds root too);
    skips when the file system or the container does not allow that."""
    if os.geteuid() != 0:
        folder.chmod(0o555)
        return lambda: folder.chmod(0o755)
    try:
        subprocess.run(["chattr", "+i", str(folder)], check=True, capture_output=True)
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("root, and chattr +i is not available here")
    return lambda: subprocess.run(["chattr", "-i", str(folder)], check=True)


def test_an_unwritable_folder_is_refused_before_the_work(exit_2, tmp_path):
    """A folder the process cannot create files in (mode 0555; as root an immutable folder):
    exit 2 naming the option and the folder, before the fit; nothing is left in the folder."""
    log = _log(tmp_path / "x.csv")
    ro = tmp_path / "ro"
    ro.mkdir()
    undo = _make_unwritable(ro)
    try:
        with pytest.raises(OSError):  # the folder really is unwritable for this process
            (ro / "probe").write_text("x")
        err = exit_2(["identify", log, "--out", ro / "p.yaml", "--quiet"])
        assert "--out: cannot write in" in err and str(ro) in err
    finally:
        undo()
    assert list(ro.iterdir()) == []


# --- folder outputs ---------------------------------------------------------------------------

def test_simulate_refuses_a_folder_with_earlier_results(exit_2, tmp_path):
    """report.md / metrics.json / experiments.md of an earlier run (or the user's) in --out:
    exit 2 without --force, before any scenario runs; the files unchanged."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "metrics.json").write_text('{"mine": 1}\n')
    (out / "experiments.md").write_text("# my notes\n")
    sums = {p.name: _sha(p) for p in out.iterdir()}
    err = exit_2(["simulate", "exp1_big_resin_block", "--out", out])
    assert "experiments.md" in err and "metrics.json" in err and "--force" in err
    assert {p.name: _sha(p) for p in out.iterdir()} == sums
    # a result name that is a directory is refused even with --force
    (out / "mujoco.md").mkdir()
    err = exit_2(["simulate", "exp1_big_resin_block", "--out", out, "--force"])
    assert "mujoco.md" in err and "a directory" in err


def test_check_dir_accepts_foreign_files_and_new_folders(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("kept")
    check_dir(out, force=False, results=("report.md", "report.json"))
    check_dir(tmp_path / "new" / "deeper", force=False, results=("report.md",))
    assert not (tmp_path / "new").exists()  # checked, not created
    (out / "report.json").write_text("{}")
    with pytest.raises(OutputError, match="report.json"):
        check_dir(out, force=False, results=("report.md", "report.json"))
    check_dir(out, force=True, results=("report.md", "report.json"))
    (tmp_path / "afile").write_text("x")
    with pytest.raises(OutputError, match="not a directory"):
        check_dir(tmp_path / "afile", force=True)


def test_campaign_refuses_report_files_of_another_folder(exit_2, tmp_path):
    """A folder that is not this campaign's and holds report.md: exit 2 without --force (the
    runs are not started); runs without a campaign.json: refused even with --force."""
    src = CAMPAIGN
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.md").write_text("# my report\n")
    before = _sha(out / "report.md")
    err = exit_2(["campaign", src, "--runs", "1", "--out", out, "--quiet"])
    assert "report.md" in err and "--force" in err
    assert _sha(out / "report.md") == before and sorted(os.listdir(out)) == ["report.md"]
    (out / "results.parquet").write_bytes(b"PAR1")
    err = exit_2(["campaign", src, "--runs", "1", "--out", out, "--quiet", "--force"])
    assert "results.parquet" in err and "campaign.json" in err


@pytest.mark.parametrize("runs", ["1e9", "1000000000", "99999999999999999999999"])
def test_campaign_run_count_is_refused_before_any_list(exit_2, tmp_path, runs):
    src = CAMPAIGN
    err = exit_2(["campaign", src, "--runs", runs, "--out", tmp_path / "o"])
    assert "--runs" in err
    assert not (tmp_path / "o").exists()


def test_demo_and_ls_refuse_earlier_results(exit_2, tmp_path, capsys):
    (tmp_path / "report.md").write_text("mine\n")
    before = _sha(tmp_path / "report.md")
    err = exit_2(["demo", "--out", tmp_path, "--only", "ls"])
    assert "report.md" in err and _sha(tmp_path / "report.md") == before
    assert main(["ls", "--k", "4", "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    err = exit_2(["ls", "--k", "4", "--out", tmp_path])
    assert "fig03_limit_surface_curves.png" in err
    assert main(["ls", "--k", "4", "--out", str(tmp_path), "--force"]) == 0


# --- temporaries on every exit path ------------------------------------------------------

def test_sigterm_during_a_write_removes_the_temporary(tmp_path):
    """A lugrip process killed with SIGTERM while its output is staged: the temporary file is
    removed, the old output is intact, exit code 143."""
    out = tmp_path / "o.txt"
    out.write_text("old\n")
    before = _sha(out)
    code = (
        "import sys, time\n"
        "from lugrip.cli import main\n"
        "from lugrip.commands import _output\n"
        "import lugrip.commands.ls as ls\n"
        "def slow(self, path):\n"
        "    open(path, 'w').write('partial')\n"
        "    print('staged', flush=True); time.sleep(30)\n"
        "ls.LsTable.write_csv = slow\n"
        f"sys.exit(main(['ls', '--k', '4', '--no-plot', '--csv', {str(out)!r}, '--force']))\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        for line in proc.stdout:
            if line.startswith("staged"):
                break
        assert len(_leftovers(tmp_path)) == 1  # the staged temporary exists now
        proc.send_signal(signal.SIGTERM)
        rc = proc.wait(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert rc == 143, proc.stderr.read()
    assert _sha(out) == before and _leftovers(tmp_path) == []


def test_report_files_are_replaced_atomically(tmp_path, monkeypatch):
    """The library's report writer (campaign report, demo report, identify --report):
    permissions kept, and a failure before the rename leaves the old file and no temporary."""
    from lugrip._atomic import write_text_atomic

    path = tmp_path / "report.md"
    path.write_text("old\n")
    os.chmod(path, 0o640)
    write_text_atomic(path, "new\n")
    assert path.read_text() == "new\n" and stat.S_IMODE(os.stat(path).st_mode) == 0o640

    def fail(src, dst):
        raise OSError(28, "No space left on device")

    fifo = tmp_path / "fifo.md"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="not a regular file"):
        write_text_atomic(fifo, "x")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OSError):
        write_text_atomic(path, "newer\n")
    assert path.read_text() == "new\n" and _leftovers(tmp_path) == []


def test_a_failed_figure_keeps_the_old_one(tmp_path):
    """lugrip.plot.save writes through a temporary: a figure that fails to render leaves the
    earlier file and no temporary."""
    from lugrip import plot

    fig, ax = plot.new_figure(1, 1)
    ax.plot([0, 1], [0, 1])
    path = plot.save(fig, tmp_path / "f.png")
    before = _sha(path)
    ax.plot([0, 1], [1, 0])

    def broken(*args, **kwargs):
        raise RuntimeError("renderer failed")

    fig.savefig = broken
    with pytest.raises(RuntimeError):
        plot.save(fig, path)
    assert _sha(path) == before and _leftovers(tmp_path) == []
