"""lugrip.estimate_cor: round trips (inside, outside, degenerate), sign rule, C++/Python
parity, an independent brentq oracle, vectorized contact quantities, and hypothesis
bad-input tests."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy.optimize import brentq

import lugrip
from lugrip import _core

STATUS_VALUES = {int(s) for s in lugrip.Status}
FIELDS = ("c_tilde", "c", "g", "sigma_1", "y", "ft_tilde", "tau_tilde", "sigma")


def ls_wrench(p, ls, f_n, c_tilde):
    """Sensor wrench on the LS at f_n for the signed CoR c~ (f_t >= 0, sign(tau) = -sign(c~))."""
    c_tilde = np.asarray(c_tilde, float)
    f_t = p.mu * f_n * np.abs(ls.ft_star(c_tilde))
    tau = -np.where(c_tilde < 0, -1.0, 1.0) * p.mu * ls.xi * p.delta * f_n ** (p.gamma + 1) * ls.tau_star(c_tilde)
    return f_t, tau


def assert_finite(est):
    for name in FIELDS:
        v = np.asarray(getattr(est, name))
        assert np.all(np.isfinite(v)), (name, v)


# ------------------------------------------------------------------------------ API shape ----

def test_unpacks_as_c_tilde_and_inside(table1, lsk):
    """`c, inside = estimate_cor(...)` and attribute access give the same arrays."""
    f_t, tau = ls_wrench(table1, lsk(4.0), 2.0, np.array([0.3, -0.8]))
    est = lugrip.estimate_cor(table1, 3.0, f_t, tau)
    c, inside = est
    assert c is est.c_tilde and inside is est.inside
    assert len(est) == 2 and est[0] is est.c_tilde and est[1] is est.inside
    np.testing.assert_allclose(c, [0.3, -0.8], atol=1e-8)
    assert inside.dtype == np.bool_ and inside.all()
    assert est.status.shape == (2,) and set(est.status.tolist()) == {int(lugrip.Status.OK)}
    for name in FIELDS + ("saturated", "iterations"):
        assert getattr(est, name).shape == (2,)


def test_shapes_and_broadcasting(table1):
    """Inputs broadcast; 0-d in gives 0-d out; 2-D shapes are preserved."""
    est = lugrip.estimate_cor(table1, 5.0, 1.0, -2e-3)
    assert np.ndim(est.c_tilde) == 0 and np.ndim(est.inside) == 0 and np.ndim(est.status) == 0
    ft = np.linspace(0.1, 2.0, 12).reshape(3, 4)
    est2 = lugrip.estimate_cor(table1, np.array([[1.0], [5.0], [10.0]]), ft, -1e-3)
    assert est2.c_tilde.shape == (3, 4) and est2.inside.shape == (3, 4)
    for i in range(3):
        for j in range(4):
            one = lugrip.estimate_cor(table1, [1.0, 5.0, 10.0][i], ft[i, j], -1e-3)
            assert one.c_tilde == est2.c_tilde[i, j]
    empty = lugrip.estimate_cor(table1, np.zeros(0), np.zeros(0), np.zeros(0))
    assert empty.c_tilde.shape == (0,)


def test_accepts_preset_name_and_dict(table1):
    a = lugrip.estimate_cor("table1", 5.0, 1.0, -2e-3)
    b = lugrip.estimate_cor(table1.to_dict(), 5.0, 1.0, -2e-3)
    c = lugrip.estimate_cor(table1, 5.0, 1.0, -2e-3)
    assert a.c_tilde == b.c_tilde == c.c_tilde
    with pytest.raises(TypeError):
        lugrip.estimate_cor(42, 5.0, 1.0, -2e-3)
    with pytest.raises(ValueError, match="f_n_min"):
        lugrip.estimate_cor(table1, 5.0, 1.0, -2e-3, f_n_min=-1.0)
    with pytest.raises(ValueError, match="zero_torque"):
        lugrip.estimate_cor(table1, 5.0, 1.0, -2e-3, zero_torque=math.nan)


def test_status_enum_matches_core():
    pairs = {"OK": "Ok", "SATURATED": "Saturated", "DEGENERATE": "Degenerate", "NO_CONTACT": "NoContact",
             "INVALID_SAMPLE": "InvalidSample", "SENSOR_FAULT": "SensorFault", "REINITIALIZED": "Reinitialized"}
    for py, cpp in pairs.items():
        assert int(lugrip.Status[py]) == getattr(_core.Status, cpp).value
        assert lugrip.Status[py].description
    assert len({s.description for s in lugrip.Status}) == len(lugrip.Status)


# ------------------------------------------------------------------------------ round trips ----

@pytest.mark.parametrize("k", [4.0, 2.0, math.inf], ids=lambda k: f"k={k:g}")
def test_inside_round_trip(k, table1, lsk):
    """A wrench on the LS at f_n0, evaluated at a larger f_n, gives the same c~ and inside;
    slightly below f_n0 it is outside (docs/model.md 5.2-5.3)."""
    p = table1.replace(k=k)
    ls = lsk(k)
    a = np.array([0.01, 0.1, 0.3, 0.5, 0.9, 1.0, 1.1, 1.45])
    c_true = np.concatenate([a, -a])
    for f_n0 in (0.1, 2.0, 12.0):
        f_t, tau = ls_wrench(p, ls, f_n0, c_true)
        for ratio in (1.0001, 1.5, 4.0, 50.0):
            est = lugrip.estimate_cor(p, f_n0 * ratio, f_t, tau)
            np.testing.assert_allclose(est.c_tilde, c_true, atol=2e-8 * 2.5, rtol=0)
            assert est.inside.all()
            assert (est.status == lugrip.Status.OK).all()
        below = lugrip.estimate_cor(p, f_n0 * (1 - 1e-4), f_t, tau)
        assert not below.inside.any()
        np.testing.assert_allclose(below.c_tilde, c_true, atol=1e-3)


@pytest.mark.parametrize("preset", ["table1", "big_resin_block", "aluminium_can"])
def test_outside_round_trip_with_viscous_excess(preset, lsk, phys):
    """Eqs. 9-10 with omega != 0 (K from the parameters): c~ comes back, flagged outside, for
    both signs of omega and of f_t; |omega| = 2 xi (t - T(a)) / K is recovered (docs/model.md 5.4)."""
    p = lugrip.ContactParams.preset(preset)
    ls = lsk(p.k)
    xi = ls.xi
    a = np.array([0.02, 0.3, 0.7, 1.0, 1.3, 1.45])
    lam = np.array([1e-4, 1e-2, 0.3, 3.0])
    A, L, SW = np.meshgrid(a, lam, [1.0, -1.0], indexing="ij")
    for f_n in (0.3, 5.0, 16.0):
        K = phys.viscous_ratio(p, f_n)
        omega = SW * L * 2 * xi / K
        c_true = SW * A
        ft_n = -SW * ls.ft_star(c_true) + K * omega * c_true   # eq. 9
        tau_n = -SW * ls.tau_star(c_true) - K / (2 * xi) * omega  # eq. 10
        f_t = ft_n * p.mu * f_n
        tau = tau_n * phys.tau_max(p, f_n)
        assert (f_t > 0).all() and (np.sign(tau) == -np.sign(omega)).all()
        for s in (1.0, -1.0):
            est = lugrip.estimate_cor(p, f_n, s * f_t, tau)
            np.testing.assert_allclose(est.c_tilde, s * c_true, atol=1e-8 * 2.5, rtol=0)
            assert not est.inside.any()
            assert (est.status == lugrip.Status.OK).all()
            speed = 2 * xi * (np.abs(est.tau_tilde) - ls.tau_star(est.c_tilde)) / K
            np.testing.assert_allclose(speed, np.abs(omega), rtol=1e-6, atol=1e-12)


def test_degenerate_cases_in_a_batch(table1, lsk):
    """tau = 0 -> |c~| = c_max (saturated); f_t = 0 -> c~ = 0; zero wrench -> previous c~ held
    (samples are processed in order)."""
    f_t, tau = ls_wrench(table1, lsk(4.0), 2.0, -0.6)
    f_n = np.array([3.0, 5.0, 5.0, 5.0, 5.0, 5.0])
    ft = np.array([f_t, 0.0, 1.0, 0.0, 1e-9, 0.0])
    tq = np.array([tau, 0.0, 0.0, 2e-3, 0.0, 0.0])
    est = lugrip.estimate_cor(table1, f_n, ft, tq)
    S = lugrip.Status
    assert est.status.tolist() == [S.OK, S.DEGENERATE, S.SATURATED, S.OK, S.DEGENERATE, S.DEGENERATE]
    assert est.c_tilde[0] == pytest.approx(-0.6, abs=1e-8)
    assert est.c_tilde[1] == est.c_tilde[0]       # held
    assert est.c_tilde[2] == -1.5                  # saturated, side held from the previous sample
    assert est.saturated[2]
    assert est.c_tilde[3] == 0.0                   # pure rotation
    assert est.c_tilde[4] == est.c_tilde[5] == 0.0  # held (the previous was 0)
    assert_finite(est)


def test_bad_samples_hold_previous(table1, lsk):
    f_t, tau = ls_wrench(table1, lsk(4.0), 2.0, 0.45)
    nan, inf = math.nan, math.inf
    f_n = np.array([3.0, nan, 3.0, 3.0, inf, -3.0, 0.0, 0.01, 1e5, 3.0, 3.0])
    ft = np.array([f_t, f_t, nan, f_t, f_t, f_t, f_t, f_t, f_t, -inf, 1e300])
    tq = np.array([tau, tau, tau, -inf, tau, tau, tau, tau, tau, tau, tau])
    est = lugrip.estimate_cor(table1, f_n, ft, tq)
    S = lugrip.Status
    assert est.status.tolist() == [S.OK, S.INVALID_SAMPLE, S.INVALID_SAMPLE, S.INVALID_SAMPLE, S.INVALID_SAMPLE,
                                   S.NO_CONTACT, S.NO_CONTACT, S.NO_CONTACT, S.INVALID_SAMPLE, S.INVALID_SAMPLE,
                                   S.INVALID_SAMPLE]
    assert (est.c_tilde == est.c_tilde[0]).all() and (est.g == est.g[0]).all()
    assert (est.iterations[1:] == 0).all()
    assert_finite(est)


def test_sign_rule_and_mirrored_loads(table1):
    """sign(c~) = -sign(f_t) sign(tau); mirrored loads give mirrored CoRs."""
    rng = np.random.default_rng(5)
    n = 2000
    f_n = rng.uniform(0.1, 20, n)
    f_t = table1.mu * f_n * rng.uniform(1e-3, 2, n)
    tau = 1e-3 * f_n ** 1.254 * rng.uniform(1e-2, 2, n)
    pp = lugrip.estimate_cor(table1, f_n, f_t, tau)
    np_ = lugrip.estimate_cor(table1, f_n, -f_t, tau)
    pn = lugrip.estimate_cor(table1, f_n, f_t, -tau)
    nn = lugrip.estimate_cor(table1, f_n, -f_t, -tau)
    assert (pp.c_tilde < 0).all() and (nn.c_tilde < 0).all()
    assert (np_.c_tilde > 0).all() and (pn.c_tilde > 0).all()
    np.testing.assert_array_equal(np_.c_tilde, -pp.c_tilde)
    np.testing.assert_array_equal(pn.c_tilde, -pp.c_tilde)
    np.testing.assert_array_equal(nn.c_tilde, pp.c_tilde)
    np.testing.assert_array_equal(pn.inside, pp.inside)
    np.testing.assert_array_equal(pn.g, pp.g)


def test_translational_slip_threshold(table1):
    """c_max = 1.5: a pure translational load is at the LS (|y|/g = 1) at f_t/(mu f_n) = 1.0518."""
    f_n = 5.0
    r = np.array([0.5, 1.0, 1.0518134, 1.1])
    est = lugrip.estimate_cor(table1, f_n, r * table1.mu * f_n, 0.0)
    assert (np.abs(est.c_tilde) == 1.5).all() and est.saturated.all()
    S = np.abs(est.y) / est.g
    np.testing.assert_allclose(S, r / 1.05181348, rtol=1e-7)
    wide = lugrip.estimate_cor(table1.replace(c_max=10.0), f_n, 1.0011 * table1.mu * f_n, 0.0)
    assert abs(wide.y) / wide.g == pytest.approx(1.0, abs=5e-5)


# ------------------------------------------------------------------------------ parity ----

def _random_samples(rng, n, with_bad=True):
    f_n = 10 ** rng.uniform(-1.5, 2, n)  # >= 0.0316 N: above f_n_min
    f_t = rng.choice([-1, 1], n) * 0.47 * f_n * 3 * rng.uniform(0, 1, n) ** 2
    tau = rng.choice([-1, 1], n) * 8e-4 * f_n ** 1.254 * 3 * rng.uniform(0, 1, n) ** 2
    if with_bad:
        bad = rng.uniform(0, 1, n)
        f_n[bad < 0.03] = np.nan
        f_t[(bad > 0.03) & (bad < 0.05)] = np.inf
        f_n[(bad > 0.05) & (bad < 0.08)] = -1.0
        f_t[(bad > 0.08) & (bad < 0.1)] = 0.0
        tau[(bad > 0.09) & (bad < 0.12)] = 0.0
        f_n[(bad > 0.12) & (bad < 0.13)] = 1e300
    return f_n, f_t, tau


def test_step_by_step_equals_batch_exactly(table1):
    """_core.CorEstimator.step, one sample at a time, reproduces the batch result bit for bit."""
    rng = np.random.default_rng(11)
    f_n, f_t, tau = _random_samples(rng, 3000)
    batch = lugrip.estimate_cor(table1, f_n, f_t, tau)
    est = _core.CorEstimator(_core.ContactModel(table1.to_core()), _core.CorSettings())
    for i in range(len(f_n)):
        o = est.step(float(f_n[i]), float(f_t[i]), float(tau[i]))
        for name in FIELDS:
            assert getattr(o, name) == getattr(batch, name)[i], (i, name)
        assert o.inside == batch.inside[i] and o.saturated == batch.saturated[i]
        assert o.iterations == batch.iterations[i] and o.status.value == batch.status[i]


def oracle(p, ls, f_n, f_t, tau, zero=1e-4):
    """Slow independent CoR estimate (docs/model.md 5.7) with brentq on LimitSurface values."""
    xi = ls.xi
    ft_n = f_t / (p.mu * f_n)
    tau_n = tau / (p.mu * xi * p.delta * f_n ** (p.gamma + 1))
    f, t = abs(ft_n), abs(tau_n)
    assert f >= zero and t >= zero
    F = lambda a: float(-ls.ft_star(a))  # noqa: E731
    T = lambda a: float(ls.tau_star(a))  # noqa: E731
    sigma = f ** (p.gamma + 1) / t
    g = lambda a: (p.gamma + 1) * math.log(F(a)) - math.log(T(a)) - math.log(sigma)  # noqa: E731
    a_s = brentq(g, 1e-12, 1e7, xtol=1e-15, rtol=1e-15, maxiter=500)
    inside = f * f + t * t < F(a_s) ** 2 + T(a_s) ** 2
    if inside:
        a = a_s
    else:
        h = lambda x: f - F(x) - 2 * xi * x * (t - T(x))  # noqa: E731
        a = p.c_max if h(p.c_max) > 0 else brentq(h, 0.0, p.c_max, xtol=1e-15, rtol=1e-15, maxiter=500)
    a = min(a, p.c_max)
    return -math.copysign(1, f_t) * math.copysign(1, tau) * a, inside


@pytest.mark.parametrize("preset,k", [("table1", 4.0), ("plastic_bottle", 2.0), ("table1", math.inf)])
def test_agrees_with_brentq_oracle(preset, k, lsk):
    p = lugrip.ContactParams.preset(preset).replace(k=k)
    ls = lsk(k)
    rng = np.random.default_rng(3)
    f_n, f_t, tau = _random_samples(rng, 300, with_bad=False)
    xi = ls.xi
    keep = (np.abs(f_t / (p.mu * f_n)) >= 1e-4) & (np.abs(tau / (p.mu * xi * p.delta * f_n ** (p.gamma + 1))) >= 1e-4)
    f_n, f_t, tau = f_n[keep], f_t[keep], tau[keep]
    est = lugrip.estimate_cor(p, f_n, f_t, tau)
    n_out = 0
    for i in range(len(f_n)):
        c_ref, inside_ref = oracle(p, ls, f_n[i], f_t[i], tau[i])
        assert est.c_tilde[i] == pytest.approx(c_ref, abs=1e-9, rel=0), i
        assert bool(est.inside[i]) == inside_ref
        n_out += not inside_ref
    assert 0 < n_out < len(f_n)  # both branches exercised


# ------------------------------------------------------------------------------ contact quantities ----

def test_vectorized_contact_quantities(table1, lsk):
    p = table1
    f_n = np.array([[0.2], [5.0], [16.0]])
    c = np.array([-1.5, 0.0, 0.4, 1.5])
    rho = p.delta * f_n ** p.gamma
    np.testing.assert_allclose(lugrip.contact_radius(p, f_n), rho, rtol=1e-15)
    G = lsk(4.0).G(c)
    gv = lugrip.g(p, f_n, c)
    assert gv.shape == (3, 4)
    np.testing.assert_allclose(gv, p.mu * f_n * rho * G, rtol=1e-13)
    s1 = lugrip.sigma_1(p, f_n, c)
    np.testing.assert_allclose(s1, np.pi * p.beta_a * rho**4 * (c**2 + 0.5), rtol=1e-13)
    ft_n, tau_n = lugrip.normalized_wrench(p, f_n, np.array([0.5, 1.0, 2.0, 3.0]), 1e-3)
    assert ft_n.shape == tau_n.shape == (3, 4)
    np.testing.assert_allclose(ft_n, np.array([0.5, 1.0, 2.0, 3.0]) / (p.mu * f_n), rtol=1e-15)
    np.testing.assert_allclose(tau_n, np.broadcast_to(1e-3 / (p.mu * p.xi * rho * f_n), (3, 4)), rtol=1e-13)
    assert np.ndim(lugrip.g(p, 5.0, 0.3)) == 0
    # Magnitudes of docs/model.md 6 at f_n = 5 N, Table 1: rho 2.709 mm, tau_max = g(0) 4.045 N mm.
    assert lugrip.contact_radius(p, 5.0) * 1e3 == pytest.approx(2.709, abs=5e-4)
    assert lugrip.g(p, 5.0, 0.0) * 1e3 == pytest.approx(4.045, abs=5e-4)
    assert lugrip.g(p, 5.0, 1.5) * 1e3 == pytest.approx(10.04, abs=5e-3)


# ------------------------------------------------------------------------------ hypothesis ----

ANY_FLOAT = st.floats(allow_nan=True, allow_infinity=True)
PHYSICAL = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False)
PRESETS = st.sampled_from(lugrip.PRESETS)


def _check_outputs(p, est):
    assert_finite(est)
    status = np.atleast_1d(est.status)
    assert set(status.tolist()) <= STATUS_VALUES
    assert np.all(np.abs(est.c_tilde) <= p.c_max)
    it = np.atleast_1d(est.iterations)
    assert np.all((it >= 0) & (it <= 62))
    valid = np.isin(status, [lugrip.Status.OK, lugrip.Status.SATURATED])
    assert np.all(np.atleast_1d(est.g)[valid] > 0)


@given(preset=PRESETS, data=st.lists(st.tuples(ANY_FLOAT, ANY_FLOAT, ANY_FLOAT), min_size=1, max_size=30))
def test_arbitrary_floats_never_raise_never_nonfinite(preset, data):
    """NaN, Inf, negative/zero f_n, huge and tiny values: a status per sample, finite outputs."""
    p = lugrip.ContactParams.preset(preset)
    f_n, f_t, tau = (np.array(x, dtype=float) for x in zip(*data))
    est = lugrip.estimate_cor(p, f_n, f_t, tau)
    _check_outputs(p, est)
    bad = ~(np.isfinite(f_n) & np.isfinite(f_t) & np.isfinite(tau))
    assert np.all(est.status[bad] == lugrip.Status.INVALID_SAMPLE)
    low = ~bad & (f_n < 0.03) & (np.abs(f_t) <= 1e4) & (np.abs(tau) <= 1e3) & (np.abs(f_n) <= 1e4)
    assert np.all(est.status[low] == lugrip.Status.NO_CONTACT)


@given(
    f_n=st.one_of(st.just(0.0), st.floats(max_value=0.0), st.floats(min_value=0.03, max_value=1e4), ANY_FLOAT),
    f_t=st.one_of(PHYSICAL, ANY_FLOAT, st.just(0.0)),
    tau=st.one_of(st.floats(min_value=-1.0, max_value=1.0), ANY_FLOAT, st.just(0.0), st.just(-0.0)),
    c_max=st.sampled_from([0.5, 1.5, 10.0, 1000.0]),
)
def test_scalar_inputs_any_value(f_n, f_t, tau, c_max):
    p = lugrip.ContactParams.table1().replace(c_max=c_max)
    est = lugrip.estimate_cor(p, f_n, f_t, tau)
    assert np.ndim(est.c_tilde) == 0
    _check_outputs(p, est)
    assert lugrip.Status(int(est.status)) in lugrip.Status
    if not (math.isfinite(f_n) and math.isfinite(f_t) and math.isfinite(tau)):
        assert est.status == lugrip.Status.INVALID_SAMPLE
    elif f_n < 0.03 and abs(f_n) <= 1e4 and abs(f_t) <= 1e4 and abs(tau) <= 1e3:
        assert est.status == lugrip.Status.NO_CONTACT


@given(arrays=hnp.arrays(np.float64, st.integers(1, 40).map(lambda n: (3, n)),
                         elements=st.floats(min_value=-50, max_value=50, allow_nan=False)))
def test_random_physical_batches(arrays):
    """Bounded physical batches: valid status, sign rule when both loads are well defined."""
    p = lugrip.ContactParams.table1()
    f_n, f_t, tau = arrays[0], arrays[1], arrays[2] * 1e-3
    est = lugrip.estimate_cor(p, f_n, f_t, tau)
    _check_outputs(p, est)
    ok = np.isin(est.status, [lugrip.Status.OK, lugrip.Status.SATURATED])
    well = ok & (np.abs(est.ft_tilde) >= 1e-4) & (np.abs(est.tau_tilde) >= 1e-4)
    expected = -np.sign(f_t[well]) * np.sign(tau[well])
    assert np.all(np.sign(est.c_tilde[well]) == expected)


VALID_PARAMS = st.builds(
    lugrip.ContactParams,
    mu=st.floats(min_value=1e-300, max_value=10.0),
    beta_a=st.floats(min_value=0.0, max_value=1e300),
    sigma0=st.just(16.66),
    sigma_z=st.just(2.0),
    delta=st.floats(min_value=1e-300, max_value=0.999),
    gamma=st.floats(min_value=1e-12, max_value=0.3333),
    k=st.sampled_from([1.0, 2.0, 3.0, 4.0, 8.0, 1e6, math.inf]),
    c_max=st.floats(min_value=1e-3, max_value=1000.0),
)


@settings(max_examples=40)  # each new parameter set builds its LS tables (~60 ms)
@given(
    p=VALID_PARAMS,
    f_n_min=st.sampled_from([5e-324, 1e-300, 0.03, 1.0]),
    limit=st.sampled_from([1e3, 1e300, 1.7e308]),
    data=st.lists(st.tuples(ANY_FLOAT, ANY_FLOAT, ANY_FLOAT), min_size=1, max_size=20),
)
def test_any_valid_parameters_and_settings(p, f_n_min, limit, data):
    """Whatever validate() accepts, bad or extreme samples give a status and finite outputs."""
    f_n, f_t, tau = (np.array(x, dtype=float) for x in zip(*data))
    est = lugrip.estimate_cor(p, f_n, f_t, tau, f_n_min=f_n_min, force_limit=limit, torque_limit=limit,
                              zero_force=1e-4, zero_torque=1e-4)
    _check_outputs(p, est)


@pytest.mark.parametrize("k", [0.5, 0.75, 1.0, 1.5])
def test_every_validated_k_builds_a_model(k):
    """The smallest exponents validate() accepts (k >= 0.5) build a working model."""
    p = lugrip.ContactParams.table1().replace(k=k)
    est = lugrip.estimate_cor(p, 5.0, 1.0, -1e-3)
    _check_outputs(p, est)


# ------------------------------------------------------------- the elliptic limit surface ----

def test_round_trip_on_elliptic_wrenches():
    """Consistency (plant = the ellipse written here in closed form, not through lugrip's
    curves): wrenches on the ellipse (f_t/(mu f_n))^2 + (tau/tau_max)^2 = 1 at its
    maximum-dissipation point for c~ (f~ = u/sqrt(1+u^2), tau~ = 1/sqrt(1+u^2), u = c~/xi),
    and inside it at a virtual normal force s f_n (f_t scaled by s, tau by s^(gamma+1)), give
    back c~; on the surface the capacity g is mu f_n rho (xi tau~ + |c~| f~)."""
    p = lugrip.ContactParams.table1().replace(k=0.0)
    xi = p.xi
    assert xi == pytest.approx(0.6354098136, abs=1e-10)
    c_t = np.array([-1.4, -0.9, -0.3, -0.05, 0.02, 0.2, 0.6, 1.0, 1.45])
    f_n = np.linspace(1.0, 12.0, c_t.size)
    u = np.abs(c_t) / xi
    F, T = u / np.sqrt(1 + u**2), 1 / np.sqrt(1 + u**2)
    tau_max = p.mu * xi * p.delta * f_n ** (1 + p.gamma)
    for s in (1.0, 0.6, 0.2):
        f_t = s * p.mu * f_n * F
        tau = -np.sign(c_t) * s ** (1 + p.gamma) * tau_max * T
        est = lugrip.estimate_cor(p, f_n, f_t, tau)
        np.testing.assert_allclose(np.asarray(est.c_tilde), c_t, atol=1e-7, err_msg=f"s = {s}")
        if s == 1.0:
            rho = p.delta * f_n**p.gamma
            g_closed = p.mu * f_n * rho * (xi * T + np.abs(c_t) * F)
            np.testing.assert_allclose(np.asarray(est.g), g_closed, rtol=1e-7)


def test_elliptic_outside_points_clip_and_stay_finite():
    """Consistency: wrenches 20 % beyond the ellipse (sliding with a viscous excess) give a
    finite estimate with |c~| <= c_max and the sign rule sign(c~) = -sign(tau)."""
    p = lugrip.ContactParams.table1().replace(k=0.0)
    c_t = np.linspace(-3.0, 3.0, 13)
    c_t = c_t[c_t != 0]
    u = np.abs(c_t) / p.xi
    f_n = np.full(c_t.size, 4.0)
    f_t = 1.2 * p.mu * f_n * u / np.sqrt(1 + u**2)
    tau = -np.sign(c_t) * 1.2 * p.mu * p.xi * p.delta * f_n ** (1 + p.gamma) / np.sqrt(1 + u**2)
    est = lugrip.estimate_cor(p, f_n, f_t, tau)
    c = np.asarray(est.c_tilde)
    assert np.all(np.isfinite(c)) and np.all(np.abs(c) <= p.c_max + 1e-12)
    assert np.all(np.sign(c) == np.sign(c_t))
