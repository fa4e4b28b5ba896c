"""Synthetic sliding maneuvers (lugrip.sliding): determinism, design coverage, physics of the
plant and the sensor wrench, the observer report's RMSE figure on a reduced set, slip-detection scoring on
hand-built cases, the sign of omega_hat through files, and the one-step RK4 divergence regime."""

from __future__ import annotations

import dataclasses
import math

import lugrip
import numpy as np
import pytest
from lugrip import ContactParams, Observer, read_log, write_log
from lugrip.sliding import (
    DEFAULT_NOISE,
    REGIMES,
    score,
    simulate_maneuvers,
    simulate_sliding,
    slip_detection,
)

TABLE1 = ContactParams.table1()
CAN = ContactParams.preset("aluminium_can")
DT = 0.002


@pytest.fixture(scope="module")
def table1_set():
    """The reduced observer-report set: 60 maneuvers, Table 1, default noise (~0.1 s to build)."""
    return simulate_maneuvers(TABLE1, 60, seed=11)


@pytest.fixture(scope="module")
def clean_set():
    """Noise-free Table 1 maneuvers for the physics checks."""
    return simulate_maneuvers(TABLE1, 30, seed=4, noise=(0.0, 0.0))


# ---------------------------------------------------------------------------------------------
# generator
# ---------------------------------------------------------------------------------------------


def test_same_seed_same_log_other_seed_other_log():
    """The generator is deterministic in its seed."""
    a = simulate_maneuvers(TABLE1, 8, seed=3)
    b = simulate_maneuvers(TABLE1, 8, seed=3)
    c = simulate_maneuvers(TABLE1, 8, seed=4)
    for name in ("t", "f_n", "f_x", "f_y", "tau", "omega", "maneuver"):
        np.testing.assert_array_equal(getattr(a.log, name), getattr(b.log, name))
    assert a.maneuvers == b.maneuvers
    assert len(c.log) != len(a.log) or not np.array_equal(c.log.tau, a.log.tau)
    log = simulate_sliding(TABLE1, 8, seed=3)
    np.testing.assert_array_equal(log.tau, a.log.tau)


def test_design_spans_forces_cors_and_kinds(table1_set):
    """Stratified designs: f_n covers 1-10 N, |c~| every regime from 0.02 to 2 c_max, stick
    and slide maneuvers, both load directions; the log is one contiguous block per maneuver."""
    ms = table1_set.maneuvers
    f_n = np.array([m.f_n for m in ms])
    c = np.array([m.c_tilde for m in ms])
    assert f_n.min() < 1.5 and f_n.max() > 9.5 and np.all((f_n >= 1) & (f_n <= 10))
    assert c.min() < 0.03 and c.max() > 2.8 and np.all((c >= 0.02) & (c <= 3.0))
    assert {m.regime for m in ms if m.kind == "slide"} == set(REGIMES)
    assert sum(m.kind == "stick" for m in ms) == 9  # 15 % of 60
    assert {m.direction for m in ms} == {-1, 1}
    log = table1_set.log
    assert np.all(np.diff(log.t) > 0)
    for m in ms:
        assert np.all(log.maneuver[m.start : m.stop] == m.index)
    assert ms[-1].stop == len(log)
    assert log.meta["maneuvers"][5]["c_tilde"] == ms[5].c_tilde


def test_sliding_maneuvers_reach_the_target_speed_and_full_utilisation(clean_set):
    """Plant physics: at the end of the hold a sliding maneuver slides steadily at the designed
    speed omega_peak = (tau_peak - g) / sigma_1 with the true utilisation S = 1, in the
    direction of the load; stick maneuvers stay in pre-sliding (|omega| < 2e-3 rad/s) with
    S_true <= the peak load ratio."""
    d = clean_set
    n_slide = 0
    for m in d.maneuvers:
        seg = slice(m.start, m.stop)
        w, s = d.log.omega[seg], d.slip[seg]
        if m.kind == "slide":
            n_slide += 1
            i_end = round((0.2 + m.ramp + m.hold) / DT) - 1  # last sample of the hold
            assert w[i_end] == pytest.approx(m.direction * m.omega_peak, rel=0.02)
            assert s[i_end] > 0.99  # z approaches g/sigma0 at the rate sigma0 |omega| / g
            # omega_0 = omega_peak sqrt(1 + 2 c~^2) lies in the default omega_range
            assert 0.05 <= m.omega_peak * math.sqrt(1 + 2 * m.c_tilde**2) <= 0.5 + 1e-12
            # the load ramps past the LS, holds and releases: below the slip threshold at the
            # end (only the bristles relax, omega = zdot)
            assert abs(w[-1]) < 0.005
        else:
            assert np.max(np.abs(w)) < 2e-3
            assert np.max(s) <= m.load_ratio + 1e-6
            assert m.load_ratio < 0.85 + 1e-12
    assert n_slide > 20
    # Table 1 loads are far outside the LS at these speeds (viscous >> dry capacity)
    ratios = [m.load_ratio for m in d.maneuvers if m.kind == "slide"]
    assert np.median(ratios) > 5.0


def test_sensor_wrench_is_the_object_on_fingertip_wrench(clean_set):
    """Noise-free sensor: tau has the sign of omega while sliding (object on fingertip,
    docs/model.md 7.2), f_t = |(f_x, f_y)| with a constant direction per maneuver, and the CoR
    estimate of the wrench recovers the designed |c~| (clipped at c_max) while sliding."""
    d = clean_set
    log = d.log
    moving = np.abs(log.omega) > 0.02
    assert np.all(np.sign(log.tau[moving]) == np.sign(log.omega[moving]))
    np.testing.assert_allclose(log.f_t, np.hypot(log.f_x, log.f_y))
    for m in d.maneuvers:
        seg = slice(m.start, m.stop)
        fx, fy = log.f_x[seg], log.f_y[seg]
        on = np.hypot(fx, fy) > 1e-9
        np.testing.assert_allclose(np.arctan2(fy[on], fx[on]), m.phi, atol=1e-9)
        sl = seg.start + np.flatnonzero(np.abs(log.omega[seg]) > 0.02)
        if m.kind == "slide" and sl.size:
            est = lugrip.estimate_cor(TABLE1, log.f_n[sl], log.f_t[sl], log.tau[sl])
            np.testing.assert_allclose(
                np.abs(est.c_tilde), min(m.c_tilde, TABLE1.c_max), rtol=1e-6, atol=1e-9
            )
            # sign rule of the sensor frame: sign(c~) = -sign(omega)
            assert np.all(np.sign(est.c_tilde) == -np.sign(log.omega[sl]))


def test_noise_has_the_requested_level():
    """White noise with the requested std on f_n, f_x, f_y and tau."""
    clean = simulate_maneuvers(TABLE1, 6, seed=9, noise=(0.0, 0.0))
    noisy = simulate_maneuvers(TABLE1, 6, seed=9, noise=(0.02, 4e-5))
    for name, std in (("f_n", 0.02), ("f_x", 0.02), ("f_y", 0.02), ("tau", 4e-5)):
        diff = getattr(noisy.log, name) - getattr(clean.log, name)
        assert np.std(diff) == pytest.approx(std, rel=0.05)
        assert abs(np.mean(diff)) < 5 * std / math.sqrt(diff.size)
    np.testing.assert_array_equal(noisy.log.omega, clean.log.omega)
    assert DEFAULT_NOISE == (0.005, 1e-5)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"n_maneuvers": 0}, "n_maneuvers"),
        ({"f_n_range": (5.0, 1.0)}, "f_n_range"),
        ({"c_range": (0.0, 1.0)}, "c_range"),
        ({"stick_load": (0.5, 1.2)}, "stick_load"),
        ({"stick_fraction": 1.5}, "stick_fraction"),
        ({"noise": (-1.0, 0.0)}, "noise"),
        ({"dt": 0.0}, "dt"),
        ({"J": -1.0}, "J"),
    ],
)
def test_bad_arguments_are_named(kwargs, match):
    """Invalid generator arguments raise ValueError naming the argument."""
    args = {"n_maneuvers": 2, **kwargs}
    with pytest.raises(ValueError, match=match):
        simulate_maneuvers(TABLE1, **args)


# ---------------------------------------------------------------------------------------------
# the observer report's acceptance figures on a reduced set
# ---------------------------------------------------------------------------------------------


def test_table1_rmse_at_most_the_papers_figure(table1_set):
    """Table 1, true parameters, default observer settings, default noise: RMSE of omega_hat
    over 60 maneuvers spanning every CoR regime <= 0.0222 rad/s (the paper's figure) and far
    below predicting zero; every slip detected, no false alarm in stick."""
    run = Observer(TABLE1).run(table1_set.log)
    sc = score(table1_set, run)
    assert sc.rms_omega > 0.05  # real sliding at tenths of rad/s
    assert sc.rmse <= 0.0222
    assert sc.rmse < 0.15 * sc.rms_omega
    assert set(sc.rmse_by_regime) == {*REGIMES, "stick"}
    for regime in ("rotation", "mixed", "translation"):
        assert sc.rmse_by_regime[regime] <= 0.0222
    assert sc.n_detected == sc.n_slide and sc.n_missed == 0
    assert sc.n_false_alarm == 0 and sc.false_alarm_rate == 0.0
    assert sc.diverged == 0
    # matches ObserverRun.rmse over the same samples
    assert sc.rmse == pytest.approx(run.rmse(table1_set.log.omega), rel=1e-12)


def test_table2_object_detects_slip_but_speed_is_poorly_observable():
    """Aluminium can (beta_A 230x smaller than Table 1): S still detects every slip that
    reaches 0.01 rad/s (within 0.3 s) without false alarms, while omega_hat is much worse
    relative to the motion than with Table 1 (speed only observable through viscous friction,
    docs/model.md 6-7)."""
    d = simulate_maneuvers(CAN, 40, seed=12)
    _run, sc = lugrip.sliding.evaluate(d)
    assert sc.n_slide > 25
    assert sc.n_detected >= sc.n_slide - 1
    assert sc.delay_p95 < 0.3
    assert sc.n_false_alarm == 0
    assert sc.rmse / sc.rms_omega > 0.2
    t1 = lugrip.sliding.evaluate(simulate_maneuvers(TABLE1, 40, seed=12))[1]
    assert sc.rmse / sc.rms_omega > 2.0 * t1.rmse / t1.rms_omega


def test_one_step_rk4_diverges_where_the_default_scheme_does_not():
    """Steady sliding at f_n = 1 N, |c~| = 0.1, omega = 0.3 rad/s (Table 1): one RK4 step per
    2 ms sample (the paper's scheme, l = 200) violates h sigma0 |omega| / g <= 2.785 (docs/model.md
    7.4) and diverges (the observer's guard re-initialises it, the RMSE explodes); the default
    (Rosenbrock) tracks omega within 2 %."""
    d = simulate_maneuvers(
        TABLE1,
        1,
        seed=0,
        f_n_range=(1.0, 1.0),
        c_range=(0.1, 0.1),
        omega_range=(0.3 * math.sqrt(1.02), 0.3 * math.sqrt(1.02)),
        stick_fraction=0.0,
    )
    m = d.maneuvers[0]
    g = m.g
    assert DT * TABLE1.sigma0 * m.omega_peak / g > 2.785  # outside RK4's stability interval
    rk4 = Observer(TABLE1, integrator="rk4", gain=200.0).run(d.log)
    default = Observer(TABLE1).run(d.log)
    assert rk4.diverged.any()
    assert not default.diverged.any()
    i_end = round((0.2 + m.ramp + m.hold) / DT) - 1
    assert default.omega_hat[i_end] == pytest.approx(d.log.omega[i_end], rel=0.02)
    assert default.rmse(d.log.omega) < 0.01
    assert rk4.rmse(d.log.omega) > 1.0


# ---------------------------------------------------------------------------------------------
# scoring
# ---------------------------------------------------------------------------------------------


def test_slip_detection_on_hand_built_cases():
    """Onset = first |omega| > threshold; detection = start of the S >= 0.9 run holding the
    onset, else the first alarm after it; stick maneuvers: any alarm is a false alarm."""
    t = np.arange(100) * 0.01
    omega = np.where(np.arange(100) >= 50, 0.1, 0.0)
    omega[20] = np.nan  # unknown sample: ignored
    late = np.where(np.arange(100) >= 55, 1.0, 0.5)
    r = slip_detection(t, omega, late)
    assert r["slides"] and not r["missed"] and not r["false_alarm"]
    assert r["onset"] == pytest.approx(0.50)
    assert r["delay"] == pytest.approx(0.05)
    early = np.where(np.arange(100) >= 45, 0.95, 0.1)
    early[30] = 0.92  # an isolated earlier alarm is not the run that holds the onset
    assert slip_detection(t, omega, early)["delay"] == pytest.approx(-0.05)
    never = np.full(100, 0.5)
    r = slip_detection(t, omega, never)
    assert r["missed"] and math.isnan(r["delay"])
    stick = np.zeros(100)
    r = slip_detection(t, stick, np.where(np.arange(100) == 70, 0.9, 0.2))
    assert not r["slides"] and r["false_alarm"] and r["alarm_fraction"] == pytest.approx(0.01)
    assert not slip_detection(t, stick, np.full(100, 0.89))["false_alarm"]
    with pytest.raises(ValueError):
        slip_detection(t, omega[:50], late)


def test_score_of_a_perfect_and_of_a_zero_estimate(table1_set):
    """RMSE 0 for omega_hat = omega and RMS(omega) for omega_hat = 0; the per-regime RMSEs
    combine to the overall one."""
    run = Observer(TABLE1).run(table1_set.log)
    omega = np.asarray(table1_set.log.omega)
    perfect = score(table1_set, dataclasses.replace(run, omega_hat=omega.copy()))
    assert perfect.rmse == 0.0
    zero = score(table1_set, dataclasses.replace(run, omega_hat=np.zeros_like(omega)))
    assert zero.rmse == pytest.approx(zero.rms_omega, rel=1e-12)
    sc = score(table1_set, run)
    n_by = {}
    for m in sc.maneuvers:
        key = m.regime if m.kind == "slide" else "stick"
        n_by[key] = n_by.get(key, 0) + m.n
    total = sum(sc.rmse_by_regime[k] ** 2 * n_by[k] for k in n_by)
    assert math.sqrt(total / sc.n_samples) == pytest.approx(sc.rmse, rel=1e-10)
    with pytest.raises(ValueError, match="omega"):
        score(dataclasses.replace(table1_set.log, omega=None), run)


# ---------------------------------------------------------------------------------------------
# sign of omega_hat through files
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_sign_of_omega_hat_through_a_file(tmp_path, suffix):
    """A log with known ground-truth signs (both load directions), written with write_log and
    read back: omega_hat has the sign of omega on every clearly sliding sample, and feeding the
    opposite wrench (fingertip on object) flips it."""
    pytest.importorskip("pyarrow")
    d = simulate_maneuvers(TABLE1, 10, seed=21, stick_fraction=0.0)
    assert {m.direction for m in d.maneuvers} == {-1, 1}
    back = read_log(write_log(d.log, tmp_path / f"signs{suffix}"))
    np.testing.assert_array_equal(back.omega, d.log.omega)
    run = Observer(TABLE1).run(back)
    moving = np.abs(back.omega) > 0.02
    assert moving.sum() > 1000
    assert np.all(np.sign(run.omega_hat[moving]) == np.sign(back.omega[moving]))
    flipped = dataclasses.replace(back, f_x=-back.f_x, f_y=-back.f_y, tau=-back.tau)
    run_f = Observer(TABLE1).run(flipped)
    assert np.all(np.sign(run_f.omega_hat[moving]) == -np.sign(back.omega[moving]))
