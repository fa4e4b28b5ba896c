"""Hostile log files and arguments: each is refused with one line naming the file (exit code 2
on the command line), quickly and without reading unbounded data into memory."""

from __future__ import annotations

import numpy as np
import pytest
from lugrip import LogError, SlidingLog, read_log, write_log
from lugrip.cli import main


def _small_log(n=50):
    t = np.arange(n) * 0.002
    return SlidingLog.from_arrays(t, np.full(n, 2.0), np.full(n, 1e-4), f_x=np.zeros(n),
                                  f_y=np.full(n, 0.3))


def _observe(tmp_path, capsys, log_path, *extra):
    rc = main(["observe", str(log_path), "--preset", "table1", "--out",
               str(tmp_path / "est.csv"), *extra])
    err = capsys.readouterr().err
    return rc, err


def test_utf16_and_binary_csv_name_the_file(tmp_path, capsys):
    """A UTF-16 export and a binary file with a .csv suffix: LogError naming the file."""
    text = "t,f_n,f_t,tau\n0,2,0.1,0.0001\n0.002,2,0.1,0.0001\n"
    u16 = tmp_path / "excel.csv"
    u16.write_bytes(text.encode("utf-16"))
    with pytest.raises(LogError, match="not UTF-8 text") as info:
        read_log(u16)
    assert info.value.file == str(u16)
    rc, err = _observe(tmp_path, capsys, u16)
    assert rc == 2 and str(u16) in err and len(err.strip().splitlines()) == 1
    binary = tmp_path / "image.csv"
    binary.write_bytes(bytes(range(256)) * 16)
    with pytest.raises(LogError, match=r"image\.csv: .*not UTF-8"):
        read_log(binary)
    latin = tmp_path / "latin.csv"
    latin.write_bytes("t,f_n,f_t,tau\n0,2,0.1,0.0001 \xb5\n".encode("latin-1"))
    with pytest.raises(LogError, match=r"latin\.csv: row 2: byte \d+ is not UTF-8"):
        read_log(latin)


def test_cell_over_the_csv_field_limit(tmp_path, capsys):
    """A 200 KiB cell (over the csv module's 128 KiB field limit) names the file and row."""
    path = tmp_path / "long.csv"
    path.write_text("t,f_n,f_t,tau\n0,2,0.1,0.0001\n0.002,2,\"" + "x" * 200_000 + "\",0.0\n")
    with pytest.raises(LogError, match=r"long\.csv: row 3: unreadable CSV \(field larger"):
        read_log(path)
    rc, err = _observe(tmp_path, capsys, path)
    assert rc == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_oversized_csv_is_refused_before_reading(tmp_path, monkeypatch):
    """A CSV over the size limit is refused from its size alone (limit lowered for the test)."""
    import lugrip.io._csv as csv_mod

    path = write_log(_small_log(200), tmp_path / "big.csv")
    monkeypatch.setattr(csv_mod, "MAX_CSV_BYTES", 1000)
    with pytest.raises(LogError, match=r"big\.csv: .*MiB a CSV log may hold"):
        read_log(path)


def test_parquet_with_too_many_rows_is_refused(tmp_path, monkeypatch):
    """The row count in a Parquet file's metadata is checked before the table is read (limit
    lowered for the test)."""
    pytest.importorskip("pyarrow")
    import lugrip.io._parquet as pq_mod

    path = write_log(_small_log(200), tmp_path / "big.parquet")
    monkeypatch.setattr(pq_mod, "MAX_PARQUET_ROWS", 100)
    with pytest.raises(LogError, match=r"big\.parquet: 200 rows, more than the 100"):
        read_log(path)


def test_topic_with_too_many_messages_is_refused(tmp_path, monkeypatch):
    """A topic with more messages than MAX_MESSAGES is refused with a message naming it."""
    pytest.importorskip("mcap")
    pytest.importorskip("rosbags")
    import lugrip.io._mcap as mcap_mod
    import lugrip.io._ros as ros_mod

    path = write_log(_small_log(100), tmp_path / "long.mcap")
    monkeypatch.setattr(ros_mod, "MAX_MESSAGES", 40)
    monkeypatch.setattr(mcap_mod, "MAX_MESSAGES", 40)
    with pytest.raises(LogError, match=r"topic '/lugrip/wrench' has 100 messages or more"):
        read_log(path)


def test_simulate_sliding_refuses_an_unbounded_request(tmp_path, capsys):
    """--maneuvers 1e9 is refused before anything is simulated: exit 2, one line."""
    rc = main(["simulate-sliding", "--out", str(tmp_path / "s.csv"), "--maneuvers",
               "1000000000"])
    err = capsys.readouterr().err
    assert rc == 2 and "may need up to" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "s.csv").exists()


def test_damaged_csv_over_the_line_reader_limit_names_the_file(tmp_path, monkeypatch):
    """A CSV the streaming reader cannot parse (a text cell) and too large for the line-by-line
    reader (limit lowered for the test) is refused with the streaming reader's words and the
    limit; under the limit the line reader names the row and column."""
    import lugrip.io._csv as csv_mod

    path = write_log(_small_log(200), tmp_path / "bad.csv")
    lines = path.read_text().splitlines()
    cells = lines[50].split(",")
    cells[1] = "abc"
    lines[50] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(LogError, match=r"bad\.csv: row 51, column 'f_n': 'abc' is not a number"):
        read_log(path)
    monkeypatch.setattr(csv_mod, "MAX_LINE_READER_BYTES", 1000)
    with pytest.raises(LogError, match=r"bad\.csv: the streaming CSV reader cannot read this file "
                                       r"\(.*abc.*\).*up to 0 MiB"):
        read_log(path)
