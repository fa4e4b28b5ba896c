"""The prescribed-motion rubbing design and the grid-of-cells LuGre plant (lugrip.rigs).

Kinds of test (see each docstring):

* independent physics: the grid plant against closed-form contact mechanics that does not
  come from lugrip's model (Hertzian load integrals, Coulomb/Stribeck limits, the LuGre
  bristle's small-displacement stiffness, the viscous shear integrated over a disc);
* numerical: convergence of the grid's integration against a halved step;
* design / bookkeeping: plan_maneuvers, labels, save/load, the CLI;
* consistency: the lumped and patch rigs are lugrip's own models driven by the same design;
  agreement between them and with the grid's signs shows consistency, not correctness.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from lugrip.cli import main
from lugrip.rigs import (
    GridContactRig,
    ManeuverPlan,
    RigTruth,
    RubbingData,
    RubbingDesign,
    make_rig,
    plan_maneuvers,
)
from lugrip.rigs.model_rigs import LumpedRig, PatchRig

F_N = 4.0  # [N] normal force of the single-maneuver tests
XI_HERTZ = 3.0 * math.pi / 16.0  # int p r dA / (f_n rho) for p ~ sqrt(1 - r^2/rho^2)


def _plan(cor, knots_t, knots_w, *, f_n=F_N, duration=None, dt=0.002) -> ManeuverPlan:
    """A noiseless, ripple-free plan with the given pad angular-velocity knots."""
    duration = knots_t[-1] if duration is None else duration
    t = np.arange(round(duration / dt) + 1) * dt
    return ManeuverPlan(
        index=0, t=t, knots_t=np.asarray(knots_t, float), knots_omega=np.asarray(knots_w, float),
        cor=np.asarray(cor, float), c_tilde=0.0, rho_nominal=1.0, f_n_nominal=f_n,
        approach=knots_t[1], motion_end=knots_t[-1], f_n_start=1.0, ripple=0.0, ripple_freq=1.0,
        ripple_phase=0.0, reversals=0, offset=np.zeros(4), noise=(0.0, 0.0), noise_seed=0)


def _translation(speed, *, ramp=0.05, hold=0.4):
    """Slider moving at ``speed`` [m/s] along -y of the finger frame relative to the
    fingertip... realised as a rotation about a CoR 1 m away on +x (omega = speed / 1 m)."""
    w = speed / 1.0
    return _plan([1.0, 0.0], [0.0, 0.05, 0.05 + ramp, 0.05 + ramp + hold], [0, 0, -w, -w])


def _rotation(omega, *, ramp=0.05, hold=0.4):
    """Slider turning at ``omega`` [rad/s] relative to the fingertip about the patch centre."""
    return _plan([0.0, 0.0], [0.0, 0.05, 0.05 + ramp, 0.05 + ramp + hold], [0, 0, -omega, -omega])


def _displacement(plan: ManeuverPlan, t: float) -> float:
    """Angle [rad] the slider has turned relative to the fingertip by time t (fine quadrature
    of the prescribed profile)."""
    tt = np.linspace(0.0, t, 20001)
    return float(np.trapezoid(-plan.omega_pad_at(tt), tt))


@pytest.fixture(scope="module")
def stribeck():
    return GridContactRig.stribeck()


@pytest.fixture(scope="module")
def ci_set():
    """A CI-sized set of the viscous plant (10 maneuvers)."""
    return GridContactRig.viscous().simulate(RubbingDesign(), 10, seed=3)


# -- grid geometry and load ----------------------------------------------------------------


def test_cells_carry_the_normal_load_with_hertzian_pressure(stribeck):
    """Independent physics: the cell loads sum to f_n, are centred, follow sqrt(1 - r^2), and
    their first and second radial moments match the continuous Hertzian integrals
    (int p r dA = 3 pi/16 f_n rho, int p r^2 dA = 2/5 f_n rho^2) to 0.1 %."""
    u, w, area = stribeck.cells()
    r = np.hypot(u[:, 0], u[:, 1])
    assert w.sum() == pytest.approx(1.0, abs=1e-12)
    assert np.all(r < 1.0)
    assert np.abs(w @ u).max() < 1e-12
    ratio = w / np.sqrt(1.0 - r**2)
    assert np.ptp(ratio) < 1e-12 * ratio.mean()
    assert w @ r == pytest.approx(XI_HERTZ, rel=1e-3)
    assert w @ r**2 == pytest.approx(0.4, rel=1e-3)
    assert len(w) * area == pytest.approx(math.pi, rel=0.02)
    run = stribeck.run([_rotation(1.0)])[0]
    assert np.allclose(run.f_n, F_N)


def test_truth_tau_max_is_the_hertzian_capacity(stribeck):
    """Independent physics: the plant's stated torsional capacity at kinetic friction equals
    mu_k (3 pi/16) rho f_n of the continuous Hertzian disc within 0.1 % (2 N and 8 N)."""
    tr = stribeck.truth()
    for f in (2.0, 8.0):
        ref = 0.45 * XI_HERTZ * 2.2e-3 * f ** 1.22
        assert tr.tau_max(f) == pytest.approx(ref, rel=1e-3)
    assert (tr.mu_static, tr.mu_kinetic, tr.mu, tr.beta_a, tr.viscous) == (
        0.55, 0.45, 0.45, None, False)
    v = GridContactRig.viscous().truth()
    assert v.viscous and v.beta_a == 2e7


# -- sliding limits ------------------------------------------------------------------------


def test_pure_translation_slides_at_kinetic_friction_along_the_slider_motion(stribeck):
    """Independent physics: full sliding in translation at 20 mm/s (40 Stribeck speeds)
    gives f_t = mu_k f_n (0.1 %), in the direction the slider moves relative to the fingertip
    (here -y: the object drags the fingertip along), and no moment about the centre."""
    run = stribeck.run([_translation(0.02)])[0]
    assert math.hypot(run.f_x[-1], run.f_y[-1]) == pytest.approx(0.45 * F_N, rel=1e-3)
    assert run.f_y[-1] < 0.0 and abs(run.f_x[-1]) < 1e-9
    assert abs(run.tau[-1]) < 1e-3 * 0.45 * F_N * float(stribeck.rho(F_N))
    assert run.sliding[-2] and not run.sliding[:25].any()


def test_pure_rotation_torque_is_the_hertzian_capacity_with_the_sensor_sign(stribeck):
    """Independent physics: in pure rotation at 2 rad/s the moment tends to
    mu_k int p r dA = (3 pi/16) mu_k rho f_n (within 0.2 %), with no net force; the sign
    follows docs/sliding_log.md: the slider turning counter-clockwise relative to the
    fingertip (omega > 0) drags it counter-clockwise (tau > 0), and vice versa."""
    ref = XI_HERTZ * 0.45 * float(stribeck.rho(F_N)) * F_N
    for omega in (2.0, -2.0):
        run = stribeck.run([_rotation(omega)])[0]
        assert run.tau[-1] == pytest.approx(math.copysign(ref, omega), rel=2e-3)
        assert math.hypot(run.f_x[-1], run.f_y[-1]) < 1e-6 * F_N


def test_stribeck_static_plateau_above_kinetic(stribeck):
    """Independent physics: rubbing at 0.1 mm/s (a fifth of the Stribeck speed) the friction
    settles near mu_k + (mu_s - mu_k) exp(-0.04) = 0.546, then falls to mu_k = 0.45 when the
    speed rises to 20 mm/s: the static level is well above the kinetic one."""
    plan = _plan([1.0, 0.0], [0.0, 0.05, 0.35, 0.8, 0.9, 1.2],
                 [0, 0, -1e-4, -1e-4, -0.02, -0.02])
    run = stribeck.run([plan])[0]
    ratio = np.hypot(run.f_x, run.f_y) / F_N
    plateau = ratio[np.searchsorted(plan.t, 0.78)]
    assert plateau == pytest.approx(0.45 + 0.1 * math.exp(-0.04), abs=0.006)
    assert ratio[-1] == pytest.approx(0.45, rel=1e-3)
    assert ratio.max() > 0.53


def test_presliding_stiffness_matches_the_bristle_law():
    """Independent physics: for small displacements the wrench is elastic, sigma0 f_n x in
    translation and sigma0 f_n rho^2 (2/5) theta in torsion (Hertzian second moment), reduced
    by the LuGre bristle's saturation (1 - exp(-s))/s, s = sigma0 x / mu_s (x: cell slip):
    checked at about 1 um of slip, within 3 % (sigma1 = 0 to see the spring alone)."""
    rig = GridContactRig.stribeck(sigma1=0.0, substeps=4)
    rho = float(rig.rho(F_N))
    tr = _translation(0.02)
    run = rig.run([tr])[0]
    k = 28
    x = _displacement(tr, tr.t[k])  # [m]: the CoR is 1 m away
    s = rig.sigma0 * x / rig.mu_s
    expect = rig.sigma0 * F_N * x * (-math.expm1(-s) / s)
    assert 0.5e-6 < x < 3e-6
    assert math.hypot(run.f_x[k], run.f_y[k]) == pytest.approx(expect, rel=0.03)
    rot = _rotation(1.0)
    run = rig.run([rot])[0]
    theta = _displacement(rot, rot.t[k])
    assert theta * rho < 0.5e-6
    assert run.tau[k] == pytest.approx(0.4 * rig.sigma0 * F_N * rho**2 * theta, rel=0.03)


def test_viscous_shear_matches_the_uniform_shear_integrals():
    """Independent physics: the viscous variant's excess over the dry plant is the uniform
    shear beta_A v integrated over the disc: pi beta_A rho^2 v in translation and
    (pi/2) beta_A rho^4 omega in rotation, within 2 % (the grid's cells cover the disc only
    approximately)."""
    dry, wet = GridContactRig.stribeck(), GridContactRig.viscous()
    rho = float(dry.rho(F_N))
    tr, rot = _translation(0.002), _rotation(1.0)
    (a_tr, a_rot), (b_tr, b_rot) = dry.run([tr, rot]), wet.run([tr, rot])
    excess_f = math.hypot(b_tr.f_x[-1], b_tr.f_y[-1]) - math.hypot(a_tr.f_x[-1], a_tr.f_y[-1])
    assert excess_f == pytest.approx(math.pi * 2e7 * rho**2 * 0.002, rel=0.02)
    assert b_rot.tau[-1] - a_rot.tau[-1] == pytest.approx(0.5 * math.pi * 2e7 * rho**4, rel=0.02)


# -- numerics ------------------------------------------------------------------------------


def test_halving_the_internal_step_changes_little():
    """Numerical: a design maneuver mix (rotation, translation, reversal) integrated with 2
    and 4 internal steps per sample differs by < 0.5 % of the peak force and torque."""
    design = RubbingDesign(reverse_fraction=1.0, max_reversals=1)
    rig = GridContactRig.stribeck()
    plans = plan_maneuvers(design, 3, seed=5, radius=lambda f: float(rig.rho(f)))
    coarse = rig.run(plans, substeps=2)
    fine = rig.run(plans, substeps=4)
    for a, b in zip(coarse, fine):
        f_scale = np.hypot(b.f_x, b.f_y).max()
        t_scale = np.abs(b.tau).max()
        assert np.abs(a.f_x - b.f_x).max() < 5e-3 * f_scale
        assert np.abs(a.f_y - b.f_y).max() < 5e-3 * f_scale
        assert np.abs(a.tau - b.tau).max() < 5e-3 * t_scale


# -- the design ----------------------------------------------------------------------------


@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 12))
def test_plans_respect_the_design(seed, n):
    """Design: every plan has increasing sample times at the design rate, rest and approach
    phases with zero motion, c~ in range, |omega| <= 2 rad/s, patch-centre speed <= v_max,
    a positive normal force, and the same draws for the same seed."""
    d = RubbingDesign()
    plans = plan_maneuvers(d, n, seed)
    again = plan_maneuvers(d, n, seed)
    for p, q in zip(plans, again):
        assert np.array_equal(p.omega_pad, q.omega_pad) and np.array_equal(p.cor, q.cor)
        assert np.allclose(np.diff(p.t), 1.0 / d.sample_rate)
        w = p.omega_pad
        assert np.abs(w).max() <= 2.0 + 1e-12
        assert np.abs(w).max() * np.hypot(*p.cor) <= d.v_max * (1 + 1e-9)
        assert 0.05 <= p.c_tilde <= 20.0
        assert np.all(w[p.commanded_phase() != 1] == 0.0)
        assert np.any(w != 0.0)
        assert p.f_n.min() > 0.0 and p.motion_end < p.t[-1]


def test_design_rejects_bad_ranges():
    """Design: impossible ranges are errors, not silently clipped."""
    for bad in ({"c_tilde_range": (2.0, 1.0)}, {"f_n_range": (0.0, 5.0)},
                {"noise_force": -1.0}, {"sample_rate": 0.0}, {"ripple": 0.7},
                {"reverse_fraction": 1.5}, {"omega_range": (float("nan"), 1.0)}):
        with pytest.raises(ValueError):
            RubbingDesign(**bad)
    with pytest.raises(ValueError):
        plan_maneuvers(RubbingDesign(), 0, 1)


def test_design_spans_the_ranges_and_reverses_some_rubs():
    """Design: 40 maneuvers cover c~ from below 0.1 to above 10, f_n from < 2 N to > 9 N,
    and about 30 % reverse."""
    plans = plan_maneuvers(RubbingDesign(), 40, seed=1)
    c = np.array([p.c_tilde for p in plans])
    f = np.array([p.f_n_nominal for p in plans])
    assert c.min() < 0.1 and c.max() > 10.0
    assert f.min() < 2.0 and f.max() > 9.0
    assert 5 <= sum(p.reversals > 0 for p in plans) <= 20


# -- a generated set -----------------------------------------------------------------------


def test_generated_set_labels_are_physical(ci_set):
    """Bookkeeping + physics: in every maneuver the phases run approach -> motion -> rest;
    the true omega is zero outside the motion and nonzero in gross sliding; gross sliding is
    a large share of the data; in it the load ratio is at least mu_k/mu_s (0.82) minus noise
    and the moment has the sign of omega; before the motion the contact is unloaded;
    c_tilde_true has sign -sign(omega) and magnitude in the design range."""
    d = ci_set
    log = d.log
    for m in np.unique(log.maneuver):
        ph = d.phase[log.maneuver == m]
        assert ph[0] == 0 and ph[-1] == 3
        first_motion = np.flatnonzero(ph != 0)[0]
        assert np.all(ph[:first_motion] == 0)
        rest = np.flatnonzero(ph == 3)
        assert np.all(np.diff(rest) == 1) and rest[-1] == len(ph) - 1
    slide = d.gross_sliding
    assert 0.3 < slide.mean() < 0.8
    assert np.all(log.omega[d.phase == 0] == 0.0) and np.all(log.omega[d.phase == 3] == 0.0)
    assert np.all(log.omega[slide] != 0.0)
    assert np.percentile(d.load_ratio[slide], 1) > 0.8
    assert np.all(d.load_ratio[d.phase == 0] == 0.0)
    rotating = slide & (np.abs(d.c_tilde_true) < 0.3)
    assert rotating.sum() > 50
    assert np.mean(np.sign(log.tau[rotating]) == np.sign(log.omega[rotating])) > 0.99
    moving = log.omega != 0.0
    assert np.all(np.sign(d.c_tilde_true[moving]) == -np.sign(log.omega[moving]))
    assert 0.04 < np.abs(d.c_tilde_true).min() and np.abs(d.c_tilde_true).max() < 22.0
    stick = d.stick_below(0.7)
    assert stick.sum() > 0.05 * len(d) and not np.any(stick & slide)
    # presliding lasts from a few to a few hundred milliseconds
    dur = d.presliding_durations()
    assert dur.size > 0 and np.all((0.005 < dur) & (dur < 0.6)), dur


def test_same_seed_same_data_and_save_load_round_trip(tmp_path, ci_set):
    """Bookkeeping: the same (design, n, seed) reproduces the set bit for bit, another seed
    does not; save/load restores log, labels and truth."""
    again = GridContactRig.viscous().simulate(RubbingDesign(), 10, seed=3)
    assert np.array_equal(again.log.tau, ci_set.log.tau)
    assert np.array_equal(again.phase, ci_set.phase)
    other = GridContactRig.viscous().simulate(RubbingDesign(), 2, seed=4)
    assert not np.array_equal(other.log.tau[:100], ci_set.log.tau[:100])
    for fmt in ("csv", "parquet"):
        ci_set.save(tmp_path / fmt, format=fmt)
        back = RubbingData.load(tmp_path / fmt)
        assert np.array_equal(back.log.tau, ci_set.log.tau)
        assert np.array_equal(back.log.omega, ci_set.log.omega)
        assert np.array_equal(back.phase, ci_set.phase)
        assert np.array_equal(back.load_ratio, ci_set.load_ratio)
        assert back.truth == ci_set.truth
    with pytest.raises(FileExistsError):
        ci_set.save(tmp_path / "csv", format="csv")


def test_sensor_noise_and_offsets_are_the_designed_ones(ci_set):
    """Design: during the approach (no tangential load) the tangential channels read offset
    plus white noise of 0.01 N / 2e-5 N m."""
    d = ci_set
    app = d.phase == 0
    resid_f, resid_t = [], []
    for m in np.unique(d.log.maneuver):
        sel = app & (d.log.maneuver == m)
        resid_f.append(d.log.f_x[sel] - d.log.f_x[sel].mean())
        resid_t.append(d.log.tau[sel] - d.log.tau[sel].mean())
    assert np.std(np.concatenate(resid_f)) == pytest.approx(0.01, rel=0.15)
    assert np.std(np.concatenate(resid_t)) == pytest.approx(2e-5, rel=0.15)


def test_rig_truth_validation_and_interpolation():
    """Bookkeeping: RigTruth interpolates a power law exactly and rejects bad points."""
    pts = tuple((f, 1e-3 * f**1.25) for f in (0.5, 2.0, 16.0))
    tr = RigTruth("x", 0.5, 0.5, 0.5, None, False, 1e-3, 0.25, "uniform", pts)
    assert tr.tau_max(8.0) == pytest.approx(1e-3 * 8.0**1.25, rel=1e-12)
    assert tr.tau_max(40.0) == pytest.approx(1e-3 * 40.0**1.25, rel=1e-12)
    with pytest.raises(ValueError):
        RigTruth("x", 0.5, 0.5, 0.5, None, False, 1e-3, 0.25, "uniform", ((1.0, -1.0),))
    with pytest.raises(ValueError):
        tr.tau_max(0.0)


# -- the project's models under the same design (consistency) -----------------------------


def test_lumped_and_patch_rigs_agree_and_share_the_grid_signs():
    """Consistency (plants = lugrip's own models): the lumped model and the simulator's
    patch, driven by the same plans, agree on the sliding wrench (|f_t| and tau within 5 %
    at the median), their stated tau_max agree within 1 %, and their in-plane force points
    the same way as the grid plant's (cosine > 0.99) with tau of the sign of omega."""
    design = RubbingDesign()
    lumped, patch = LumpedRig(), PatchRig()
    p = lumped.contact()
    plans = plan_maneuvers(design, 4, seed=2, radius=lambda f: p.delta * f**p.gamma)
    a = lumped.simulate(design, plans=plans)
    b = patch.simulate(design, plans=plans)
    g = GridContactRig.stribeck().simulate(design, plans=plans)
    both = a.gross_sliding & b.gross_sliding & g.gross_sliding
    assert both.sum() > 200
    ratio_f = a.log.f_t[both] / b.log.f_t[both]
    big = np.abs(b.log.tau[both]) > 10 * 2e-5
    ratio_t = a.log.tau[both][big] / b.log.tau[both][big]
    assert np.median(ratio_f) == pytest.approx(1.0, abs=0.05)
    assert np.median(ratio_t) == pytest.approx(1.0, abs=0.05)
    assert a.truth.tau_max(2.0) == pytest.approx(b.truth.tau_max(2.0), rel=0.01)
    for d in (a, b):
        strong = both & (d.log.f_t > 0.1) & (g.log.f_t > 0.1)
        cos = (d.log.f_x * g.log.f_x + d.log.f_y * g.log.f_y)[strong] / (
            d.log.f_t * g.log.f_t)[strong]
        assert np.median(cos) > 0.99
        rot = d.gross_sliding & (np.abs(d.c_tilde_true) < 0.5) & (np.abs(d.log.tau) > 1e-3)
        if rot.any():
            assert np.mean(np.sign(d.log.tau[rot]) == np.sign(d.log.omega[rot])) > 0.99


# -- CLI -----------------------------------------------------------------------------------


def test_cli_writes_a_run(tmp_path, capsys):
    """CLI: `lugrip simulate-rubbing` writes a loadable run and reports the truth."""
    out = tmp_path / "run"
    assert main(["simulate-rubbing", "--plant", "grid-stribeck", "--maneuvers", "2",
                 "--seed", "1", "--out", str(out), "--format", "csv"]) == 0
    text = capsys.readouterr().out
    assert "mu_s 0.55" in text and "speed observable: no" in text
    data = RubbingData.load(out)
    assert len(np.unique(data.log.maneuver)) == 2 and data.truth.name == "grid-stribeck"
    assert main(["simulate-rubbing", "--plant", "lumped", "--maneuvers", "2",
                 "--out", str(out), "--force"]) == 0
    assert RubbingData.load(out).truth.name == "lumped"


@pytest.mark.parametrize("argv, words", [
    (["--plant", "grid-stribeck", "--maneuvers", "100000"], "at most 2000"),
    (["--plant", "grid-stribeck", "--maneuvers", "0"], "must be >= 1"),
    (["--plant", "nope"], "invalid choice"),
    (["--plant", "grid-viscous", "--preset", "table1"], "applies only to"),
    (["--plant", "patch", "--preset", "nope"], "unknown preset"),
])
def test_cli_bad_arguments_exit_2_with_one_line(tmp_path, capsys, argv, words):
    """CLI: bad arguments exit with code 2 and one line on stderr."""
    assert main(["simulate-rubbing", "--out", str(tmp_path / "x"), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1


def test_cli_refuses_to_overwrite(tmp_path, capsys):
    """CLI: an existing run is kept unless --force."""
    out = tmp_path / "run"
    assert main(["simulate-rubbing", "--plant", "lumped", "--maneuvers", "1",
                 "--out", str(out)]) == 0
    assert main(["simulate-rubbing", "--plant", "lumped", "--maneuvers", "1",
                 "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err


def test_unknown_plant_and_mujoco_messages():
    """Registry: unknown names and parameters on self-contained plants are errors; the mujoco
    plant either builds or says what is missing."""
    with pytest.raises(ValueError, match="unknown plant"):
        make_rig("gridd")
    with pytest.raises(ValueError, match="own physics"):
        make_rig("grid-stribeck", params="table1")
    try:
        rig = make_rig("mujoco")
    except ImportError as err:
        assert "mujoco" in str(err)
    else:
        assert hasattr(rig, "simulate")
