"""A user's own data (docs/own_data.md): a table with other column names (--columns), a log
without maneuver ids (found from the motion by default), hints that name the option fixing an
error, a scenario whose plant contact is an identified parameter file, a figure for any
scenario, and `simulate`'s one-line summaries without NaN. The logs are lugrip's synthetic
slider (``simulate_maneuvers``): what is checked is that renamed or unmarked files give the
same numbers as the standard layout, so the plant does not matter here."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from lugrip import ContactParams, LogError, read_log, write_log
from lugrip.cli import main
from lugrip.io import find_maneuvers
from lugrip.sliding import simulate_maneuvers

RENAME = {"t": "time", "f_n": "Fz", "f_x": "Fx", "f_y": "Fy", "tau": "Mz [N mm]", "omega": "wz"}


@pytest.fixture(scope="module")
def data():
    """Five Table 1 maneuvers with ground truth, separated by unloaded rests."""
    return simulate_maneuvers(ContactParams.table1(), 5, seed=23)


def _renamed_csv(path, log, *, maneuver: bool):
    """The log as a user's logger writes it: other names, tau in N mm, maybe no maneuver."""
    cols = ["t", "f_n", "f_x", "f_y", "tau", "omega"] + (["maneuver"] if maneuver else [])
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([RENAME.get(c, c) for c in cols])
        for i in range(len(log)):
            row = [log.t[i], log.f_n[i], log.f_x[i], log.f_y[i], log.tau[i] * 1e3, log.omega[i]]
            w.writerow([repr(float(v)) for v in row] + ([int(log.maneuver[i])] if maneuver
                                                        else []))
    return path


def test_column_mapping_reads_the_standard_log(tmp_path, data):
    """columns= maps the file's names (with a [unit] in the header) onto the format: the same
    samples as the standard file, to rounding of the N mm conversion."""
    log = data.log
    path = _renamed_csv(tmp_path / "user.csv", log, maneuver=True)
    mapping = {k: v.split(" [")[0] for k, v in RENAME.items()}
    got = read_log(path, columns=mapping)
    for name in ("t", "f_n", "f_x", "f_y", "omega"):
        np.testing.assert_array_equal(getattr(got, name), getattr(log, name))
    np.testing.assert_allclose(got.tau, log.tau, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(got.maneuver, log.maneuver)
    assert got.meta["columns"]["f_n"] == "Fz"


def test_missing_columns_hint_names_the_option(tmp_path, data, capsys):
    """Without a mapping the missing-column error says how to map (--columns on the command
    line, columns= in Python); a mapping naming an absent column or a name outside the
    format is one line naming --columns."""
    path = _renamed_csv(tmp_path / "user.csv", data.log, maneuver=False)
    with pytest.raises(LogError, match=r"columns=\{'t': 'time'"):
        read_log(path)
    rc = main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "e.csv")])
    err = capsys.readouterr().err
    assert rc == 2 and "--columns t=time,f_n=Fz" in err and len(err.strip().splitlines()) == 1
    rc = main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "e.csv"),
               "--columns", "t=time,f_n=Fz,f_x=Fx,f_y=Fy,tau=Torque"])
    err = capsys.readouterr().err
    assert rc == 2 and "--columns maps 'tau' to 'Torque'" in err and "Mz [N mm]" in err
    rc = main(["observe", str(path), "--preset", "table1", "--columns", "force=Fz"])
    err = capsys.readouterr().err
    assert rc == 2 and "--columns" in err and "'force'" in err


def test_column_mapping_applies_to_tables_only(tmp_path, data):
    """A ROS recording's columns are topics: columns= is refused, naming the topic options."""
    pytest.importorskip("mcap")
    pytest.importorskip("rosbags")
    path = write_log(data.log, tmp_path / "x.mcap")
    with pytest.raises(LogError, match="omega_topic="):
        read_log(path, columns={"f_n": "Fz"})


def test_maneuvers_found_from_the_motion_by_default(tmp_path, data, capsys):
    """A table without a maneuver column: `lugrip observe` (default --maneuvers auto) finds
    the maneuvers from the motion, the same ids as find_maneuvers, one per designed maneuver;
    --maneuvers file keeps a single maneuver; a table with the column keeps its ids."""
    log = data.log
    path = _renamed_csv(tmp_path / "user.csv", log, maneuver=False)
    cols = ["--columns", "t=time,f_n=Fz,f_x=Fx,f_y=Fy,tau=Mz,omega=wz"]
    found = find_maneuvers(read_log(path, columns={k: v.split(" [")[0]
                                                   for k, v in RENAME.items()}))
    assert len(np.unique(found)) == len(np.unique(log.maneuver)) == 5
    for spec, expect in ((None, found), ("file", np.zeros(len(log), dtype=np.int64))):
        out = tmp_path / f"est_{spec}.csv"
        rc = main(["observe", str(path), "--preset", "table1", "--out", str(out), *cols,
                   *([] if spec is None else ["--maneuvers", spec])])
        assert rc == 0, capsys.readouterr().err
        with open(out, newline="") as fh:
            rows = list(csv.DictReader(fh))
        np.testing.assert_array_equal([int(r["maneuver"]) for r in rows], expect)
    marked = _renamed_csv(tmp_path / "marked.csv", log, maneuver=True)
    got = read_log(marked, columns={k: v.split(" [")[0] for k, v in RENAME.items()},
                   maneuvers="auto")
    np.testing.assert_array_equal(got.maneuver, log.maneuver)
    assert "maneuvers_from" not in got.meta


def test_observe_without_ground_truth_says_how_to_add_it(tmp_path, data, capsys):
    """No omega: observe runs, and says which option brings the ground truth."""
    log = data.log
    bare = type(log)(t=log.t, f_n=log.f_n, f_t=log.f_t, f_x=log.f_x, f_y=log.f_y, tau=log.tau,
                     maneuver=log.maneuver)
    path = write_log(bare, tmp_path / "bare.csv")
    rc = main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "e.csv")])
    out = capsys.readouterr().out
    assert rc == 0 and "RMSE not computed" in out and "--columns omega=" in out


def test_bag_topic_errors_name_the_option_and_the_fitting_topics(tmp_path, data):
    """A wrong --omega-topic: the message names the option (CLI syntax in cli_message) and
    the recording's topics of a fitting type."""
    pytest.importorskip("mcap")
    pytest.importorskip("rosbags")
    path = write_log(data.log, tmp_path / "x.mcap", omega_topic="/mocap/twist")
    with pytest.raises(LogError) as info:
        read_log(path, omega_topic="/mocap/pose")
    assert "of a fitting type: /mocap/twist" in str(info.value)
    assert "(--omega-topic)" in info.value.cli_message
    with pytest.raises(LogError) as info:
        read_log(path, omega_topic="/lugrip/wrench")
    assert "--omega-topic must be one of" in info.value.cli_message
    assert "geometry_msgs/PoseStamped" in info.value.cli_message


def _scenario_text(contact: str) -> str:
    from lugrip.sim.scenarios import find_scenario

    text = find_scenario("exp2_small_resin_block").read_text()
    assert "  contact: small_resin_block\n" in text
    return (text.replace("name: exp2_small_resin_block", "name: my_block")
            .replace("  contact: small_resin_block\n", f"  contact: {contact}\n"))


def test_scenario_plant_contact_may_be_a_parameter_file(tmp_path):
    """plant.contact: fit.yaml reads the file next to the scenario (the parameters, not a
    preset); a file that is not there is named with where it was looked for."""
    from lugrip.sim.scenarios import load_scenario

    params = ContactParams.preset("small_resin_block").replace(mu=0.41, beta_a=1.3e7)
    params.to_yaml(tmp_path / "fit.yaml")
    path = tmp_path / "my_block.yaml"
    path.write_text(_scenario_text("fit.yaml"))
    s = load_scenario(path)
    assert s.plant_config().contact == params
    path.write_text(_scenario_text("missing_fit.yaml"))
    with pytest.raises(ValueError, match=r"plant.contact parameter file 'missing_fit.yaml' "
                                         r"not found \(looked in"):
        load_scenario(path)


def test_own_scenario_gets_a_figure_and_simulate_prints_no_nan(tmp_path, capsys):
    """`lugrip simulate my_block.yaml` writes my_block.png (a scenario without a paper
    figure) and lists it in experiments.md; a fault scenario (no steady window) prints '—'
    with the reason, never 'nan'."""
    ContactParams.preset("small_resin_block").to_yaml(tmp_path / "fit.yaml")
    path = tmp_path / "my_block.yaml"
    path.write_text(_scenario_text("fit.yaml"))
    out = tmp_path / "sim"
    rc = main(["simulate", str(path), "--short", "--no-baselines", "--out", str(out)])
    printed = capsys.readouterr()
    assert rc == 0, printed.err
    assert (out / "my_block.png").stat().st_size > 20_000
    assert "](my_block.png)" in (out / "experiments.md").read_text()
    assert "steady" in printed.out and "nan" not in printed.out
    rc = main(["simulate", "fault_spikes", "--short", "--no-baselines", "--no-plots", "--out",
               str(tmp_path / "f")])
    printed = capsys.readouterr()
    assert rc == 0, printed.err
    assert "nan" not in printed.out.lower()
    assert "steady      —" in printed.out and "no steady_window" in printed.out


def test_simulate_help_says_where_scenarios_come_from(capsys):
    """--help names every place a scenario name is looked up, the installed copy included."""
    assert main(["simulate", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    for part in ("$LUGRIP_SCENARIOS", "./scenarios", "installed with lugrip", "--list"):
        assert part in text, part


def test_identify_without_omega_topic_names_the_candidates(tmp_path, data, capsys):
    """A bag whose ground truth is on a topic the reader was not told about: identify's
    one-line error names --omega-topic and the recording's topics that could be it; observe
    runs and says the same."""
    pytest.importorskip("rosbags")
    from test_io_ros import write_two_finger_bag

    bag = write_two_finger_bag(tmp_path / "bag", data.log, ros1=False, with_maneuvers=False)
    rc = main(["identify", str(bag), "--wrench-topic", "/finger0/wrench", "--out",
               str(tmp_path / "fit.yaml")])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert "--omega-topic" in err and "(this recording has: /truth/twist)" in err
    rc = main(["observe", str(bag), "--wrench-topic", "/finger0/wrench", "--preset", "table1",
               "--out", str(tmp_path / "e.csv")])
    out = capsys.readouterr().out
    assert rc == 0 and "this recording has: /truth/twist" in out
