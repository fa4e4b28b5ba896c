"""Slip detection with static and kinetic friction levels, and omega_hat where the speed is not
observable (docs/model.md §7.5, §8.3 stage 7).

Plants: the synthetic wrench sequences below are written directly from eqs. 16-18 (no plant);
the identification tests use the grid of LuGre cells (lugrip.rigs.grid), an independent
plant written from contact mechanics with Stribeck friction, not lugrip's model.
"""

from __future__ import annotations

import math

import lugrip
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lugrip import ContactParams, Observer
from lugrip.rigs import RubbingDesign
from lugrip.rigs.grid import GridContactRig

WEAK = ContactParams.table1().replace(beta_a=1.0e4, sigma_z=1.0e-3)  # speed not observable


def _rotation_log(params: ContactParams, f_n: float, loads, dt: float = 0.002):
    """Pure rotation (f_t = 0, c~ = 0): tau = load x tau_max(f_n), one sample per entry."""
    tau_max = params.mu * params.xi * params.delta * f_n ** (1.0 + params.gamma)
    loads = np.asarray(loads, float)
    n = len(loads)
    return {"f_n": np.full(n, f_n), "f_t": np.zeros(n), "tau": loads * tau_max,
            "t": np.arange(n) * dt}


def test_default_ratios_keep_the_paper_indicator():
    """No plant (eqs. 16-18 wrenches). With static_ratio = kinetic_ratio = 1 S is sigma0 |z| / g
    on every sample, the kinetic flag never rises, and omega_hat is the state where the speed
    is observable (Table 1: everywhere on this log)."""
    p = ContactParams.table1()
    loads = np.concatenate([np.linspace(0.0, 1.3, 400), np.full(300, 1.3), np.linspace(1.3, 0.2, 300)])
    run = Observer(p).run(_rotation_log(p, 5.0, loads))
    S = np.asarray(run.S)
    ref = np.minimum(p.sigma0 * np.abs(np.asarray(run.z_hat)) / np.asarray(run.g), 1.0)
    assert np.array_equal(S, ref)
    assert not np.any(run.kinetic)
    obs = np.asarray(run.speed_observable)
    assert obs.all()
    assert np.array_equal(np.asarray(run.omega_hat), np.asarray(run.omega_state))
    assert S.max() > 0.999 and np.max(np.asarray(run.omega_state)) > 0.0  # it did slide


def test_omega_hat_is_zero_where_speed_is_not_observable():
    """No plant. beta_A so small that sigma_1 cannot resolve any speed: omega_hat, omega_object
    and v_slip are 0 on every unobservable sample while the state moves."""
    loads = np.concatenate([np.linspace(0.0, 1.2, 300), np.full(300, 1.2)])
    run = Observer(WEAK).run(_rotation_log(WEAK, 5.0, loads))
    off = ~np.asarray(run.speed_observable)
    assert off.all()
    for name in ("omega_hat", "omega_object", "v_slip"):
        assert np.all(np.asarray(getattr(run, name))[off] == 0.0)
    assert np.max(np.abs(np.asarray(run.omega_state))) > 1.0


def test_hysteresis_between_static_and_kinetic_levels():
    """No plant (eqs. 16-18 wrenches, c~ = 0). static_ratio 1.3, kinetic_ratio 0.9: in stick S is
    the load over 1.3 g; when the load reaches 0.9 g sliding has started and S is judged
    against 0.9 g; a load that stays above 0.8 x 0.9 g keeps that level, one below it returns
    to the static level."""
    p = WEAK.replace(static_ratio=1.3, kinetic_ratio=0.9)
    seg = [np.linspace(0.0, 0.6, 200), np.full(100, 0.6),  # stick, below the kinetic level
           np.linspace(0.6, 0.95, 100), np.full(200, 0.95),  # reaches it: sliding
           np.full(200, 0.8),  # above the release (0.72): still sliding
           np.linspace(0.8, 0.5, 100), np.full(200, 0.5)]  # stuck again
    loads = np.concatenate(seg)
    run = Observer(p).run(_rotation_log(p, 4.0, loads))
    S, kin = np.asarray(run.S), np.asarray(run.kinetic)
    i = np.cumsum([len(s) for s in seg])
    assert not kin[: i[1]].any()
    assert S[i[1] - 1] == pytest.approx(0.6 / 1.3, rel=0.02)
    assert kin[i[3] - 1] and S[i[3] - 1] == 1.0
    assert kin[i[4] - 1] and S[i[4] - 1] == pytest.approx(0.8 / 0.9, rel=0.02)
    assert not kin[i[6] - 1] and S[i[6] - 1] == pytest.approx(0.5 / 1.3, rel=0.02)


def test_stribeck_capacity_steady_sliding_speed():
    """No plant (eqs. 16-18 wrenches, pure rotation, Table 1). With stribeck_speed v_s the
    sliding update's capacity is g (1 + (r_s - 1) exp(-(v / v_s)^2)), v = |omega| rho / sqrt(2)
    at c~ = 0 (docs/model.md 7.5): a load that breaks away and then holds at that capacity plus
    sigma_1 omega* at a chosen omega* gives omega_state = omega* in steady sliding (here the
    capacity falls more slowly than sigma_1 omega rises, one root), where the observer without
    the curve reads the excess friction as speed."""
    p = ContactParams.table1().replace(static_ratio=1.3, kinetic_ratio=1.0)
    f_n = 5.0
    rho = p.delta * f_n ** p.gamma
    g = p.mu * p.xi * p.delta * f_n ** (1.0 + p.gamma)
    sigma_1 = p.beta_a * math.pi * rho ** 4 * 0.5
    v_s = 2.0e-5
    w_star = 0.01
    level = 1.0 + 0.3 * math.exp(-((w_star * rho / math.sqrt(2.0)) / v_s) ** 2)
    hold = (g * level + sigma_1 * w_star) / g  # the load over g at omega*
    loads = np.concatenate([np.linspace(0.0, 1.6, 300), np.linspace(1.6, hold, 100),
                            np.full(1500, hold)])
    log = _rotation_log(p, f_n, loads)
    curve = Observer(p.replace(stribeck_speed=v_s)).run(log)
    one = Observer(p).run(log)
    assert np.asarray(curve.kinetic)[-1]
    assert np.asarray(curve.omega_state)[-1] == pytest.approx(w_star, rel=1e-3)
    w_one = (hold - 1.0) * g / sigma_1  # one sliding level: the excess read as speed
    assert np.asarray(one.omega_state)[-1] == pytest.approx(w_one, rel=1e-3)
    assert w_one > 1.05 * w_star


@settings(max_examples=30, deadline=None)
@given(st.floats(0.5, 3.0), st.floats(0.5, 3.0))
def test_ratio_validation(rs, rk):
    """No plant. Ratios in [0.5, 3] with static >= kinetic are accepted, others refused, and a
    YAML round trip keeps them."""
    if rs >= rk:
        p = WEAK.replace(static_ratio=rs, kinetic_ratio=rk)
        q = ContactParams.from_dict(__import__("yaml").safe_load(p.to_yaml()))
        assert (q.static_ratio, q.kinetic_ratio) == (rs, rk)
    else:
        with pytest.raises(ValueError, match="static_ratio"):
            WEAK.replace(static_ratio=rs, kinetic_ratio=rk)


@pytest.mark.parametrize("bad", [0.4, 3.5, math.nan, math.inf])
def test_ratio_out_of_range(bad):
    """No plant. Out-of-range or non-finite ratios are refused with the field's name."""
    with pytest.raises(ValueError, match="kinetic_ratio"):
        WEAK.replace(kinetic_ratio=bad, static_ratio=3.0)


def test_default_params_yaml_has_no_ratio_fields():
    """No plant. Parameter files without a Stribeck term stay as before (no ratio lines)."""
    assert "ratio" not in ContactParams.table1().to_yaml()


@pytest.mark.parametrize(
    "mu_s, mu_k, stribeck",
    [(0.63, 0.45, True), (0.5, 0.5, False)],
)
def test_identification_and_detection_on_a_stribeck_grid(mu_s, mu_k, stribeck, tmp_path):
    """Independent plant: grid of LuGre cells (Hertzian pressure, Stribeck speed 1 mm/s), edge
    speeds 0.1-10 mm/s, CoR 0.05-20 rho. identify() finds a Stribeck term exactly when the
    plant has one; with the fitted YAML the observer flags S >= 0.9 on >= 95 % of the held-out
    samples in gross sliding at >= 98 % of the peak speed, on <= 5 % of stick samples below
    70 % of the static limit, and omega_hat (not observable) is no worse than zero."""
    rig = GridContactRig(name="t", mu_s=mu_s, mu_k=mu_k, v_s=1.0e-3, n_grid=21)
    design = RubbingDesign(edge_speed_range=(1e-4, 1e-2), hold_slip=3e-4)
    data = rig.simulate(design, n=75, seed=5)
    ids = np.unique(data.log.maneuver)
    train, test = (data.select_maneuvers(ids[ids % 5 != 4]),
                   data.select_maneuvers(ids[ids % 5 == 4]))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = lugrip.identify(train.log)
    p = r.params
    assert (p.static_ratio > p.kinetic_ratio) == stribeck
    # the user's path: the YAML `lugrip identify` writes, read back as `lugrip observe` does
    # (it carries the friction levels: a file without them judged S against one capacity)
    path = r.save_yaml(tmp_path / "fit.yaml")
    q = ContactParams.from_yaml(path)
    assert (q.static_ratio, q.kinetic_ratio) == (p.static_ratio, p.kinetic_ratio)
    run = Observer(q, **lugrip.read_observer_settings(path)).run(test.log)
    S = np.asarray(run.S)
    om = np.abs(np.asarray(test.log.omega))
    peak = np.zeros(len(om), bool)
    for m in np.unique(test.log.maneuver):
        sel = np.asarray(test.log.maneuver) == m
        peak[sel] = om[sel] >= 0.98 * om[sel].max()
    surely = peak & test.gross_sliding
    assert np.mean(S[surely] >= 0.9) >= 0.95
    st_ = test.stick_below(0.7)
    assert np.mean(S[st_] >= 0.9) <= 0.05
    off = ~np.asarray(run.speed_observable)
    wh = np.asarray(run.omega_hat)
    assert math.sqrt(np.mean((np.abs(wh[off]) - om[off]) ** 2)) <= math.sqrt(np.mean(om[off] ** 2))


def test_stribeck_curve_fitted_jointly_on_a_viscous_stribeck_grid(tmp_path, monkeypatch):
    """Independent plant: grid of LuGre cells (17 x 17, Hertzian pressure, mu_s 0.55 / mu_k
    0.45, Stribeck speed 0.5 mm/s, viscous shear 2e7 N s/m^3), edge speeds 0.1-10 mm/s, CoR
    0.05-20 rho, 120 training and 30 held-out maneuvers. Where the data carry a viscous term
    and a falling sliding friction, identify() puts a Stribeck curve into the observer
    (stribeck_speed > 0, the rest level static_ratio above the kinetic one) fitted by eq. 32
    together with mu, delta, gamma and beta_A; the fitted YAML carries it, and its observer's
    |omega| error over all held-out samples is at least 10 % below that of the parameters the
    same identification had before the joint fit (refined, with the friction levels: one
    sliding level), which is what that fit is for."""
    import warnings

    from lugrip.identification import _driver

    rig = GridContactRig(name="t", mu_s=0.55, mu_k=0.45, beta_a=2.0e7, n_grid=17)
    design = RubbingDesign(edge_speed_range=(1e-4, 1e-2), c_tilde_range=(0.05, 20.0),
                           hold_slip=3e-4)
    data = rig.simulate(design, n=150, seed=7)
    ids = np.unique(data.log.maneuver)
    train, test = (data.select_maneuvers(ids[ids % 5 != 4]),
                   data.select_maneuvers(ids[ids % 5 == 4]))
    before = {}
    joint_fit = _driver._stribeck_joint

    def spy(train_p, val_p, p_hat, *args, **kw):  # records the joint fit's start parameters
        before["params"] = p_hat
        return joint_fit(train_p, val_p, p_hat, *args, **kw)

    monkeypatch.setattr(_driver, "_stribeck_joint", spy)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = lugrip.identify(train.log)
    path = r.save_yaml(tmp_path / "fit.yaml")
    q = ContactParams.from_yaml(path)
    settings_ = lugrip.read_observer_settings(path)
    assert r.status == "converged"
    assert q.stribeck_speed > 0.0 and q.static_ratio > q.kinetic_ratio
    assert q == r.params
    assert before["params"].stribeck_speed == 0.0
    assert any("Stribeck curve in the observer" in s and s.endswith("kept")
               for s in r.identifiability)
    om = np.abs(np.asarray(test.log.omega))

    def rmse(p):
        e = np.abs(np.asarray(Observer(p, **settings_).run(test.log).omega_object)) - om
        return math.sqrt(float(np.mean(e * e)))

    assert rmse(q) <= 0.9 * rmse(before["params"])
