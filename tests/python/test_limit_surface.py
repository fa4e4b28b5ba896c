"""lugrip.LimitSurface against the independent reference, the tables and closed forms of
docs/model.md; vectorization and shapes; parity and monotonicity."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lugrip

REF_KS = (1.5, 2.0, 3.0, 4.0, 6.0, 8.0, math.inf)

# docs/model.md 3.4 (k = 4): c~, f~*, tau~*, G, sigma_LS (gamma = 0.254)
SPEC_TABLE = np.array([
    [0.0, 0.0, 1.0, 0.63540981, 0.0],
    [0.1, -0.1059068333, 0.9916725251, 0.64070914, 0.060379],
    [0.25, -0.2626505930, 0.9485788612, 0.66839897, 0.197164],
    [0.5, -0.5094317274, 0.8037455127, 0.76542365, 0.534032],
    [0.75, -0.7203649578, 0.5978502942, 0.92015366, 1.108609],
    [1.0, -0.8640993375, 0.4029076144, 1.12011079, 2.066547],
    [1.5, -0.9460703579, 0.2496260446, 1.57772038, 3.736957],
    [2.0, -0.9704899177, 0.1838373829, 2.05779191, 5.239055],
    [5.0, -0.9954017542, 0.0722525720, 5.02291876, 13.760578],
    [10.0, -0.9988545171, 0.0360408313, 10.01144587, 27.706458],
])


@pytest.mark.parametrize(
    "k",
    list(REF_KS),
    ids=lambda k: f"k={k:g}",
)
def test_reference_every_k(k, ls_reference, lsk):
    """ft_star/tau_star/G within 1e-6 of the independent quadrature over c~ in [-1000, 1000]."""
    ref = ls_reference[k]
    assert len(ref["c"]) >= 30
    ls = lsk(k)
    c = ref["c"]
    err_f = np.abs(ls.ft_star(c) - ref["ft"])
    err_t = np.abs(ls.tau_star(c) - ref["tau"])
    np.testing.assert_array_equal(ls.ft_star(-c), -ls.ft_star(c))
    np.testing.assert_array_equal(ls.tau_star(-c), ls.tau_star(c))
    worst = max(err_f.max(), err_t.max())
    print(f"k = {k:g}: max |LS - reference| = {worst:.2e} at c~ = {c[np.argmax(np.maximum(err_f, err_t))]:g}")
    assert worst <= 1e-6
    assert np.all(np.abs(ls.G(c) - ref["G"]) <= 1e-6 * (1 + c))


def test_reference_includes_the_rim_and_the_tail(ls_reference):
    """The reference grid is dense around c~ = 1 and reaches 1000."""
    for k in REF_KS:
        c = ls_reference[k]["c"]
        for needed in (0.0, 0.999, 1.0, 1.001, 20.0, 50.0, 200.0, 1000.0):
            assert needed in c


def test_spec_table_k4(lsk):
    """docs/model.md 3.4 values (10 decimals) within the 1e-6 accuracy target; integrate() to 1e-9."""
    ls = lsk(4.0)
    c, ft, tau, G, sig = SPEC_TABLE.T
    np.testing.assert_allclose(ls.ft_star(c), ft, atol=1e-6, rtol=0)
    np.testing.assert_allclose(ls.tau_star(c), tau, atol=1e-6, rtol=0)
    np.testing.assert_allclose(ls.G(c), G, atol=2e-6, rtol=0)
    np.testing.assert_allclose(ls.sigma_ls(c, 0.254), sig, rtol=2e-5, atol=6e-7)
    for ci, fi, ti in zip(c, ft, tau):
        F, T, dF, dT = ls.integrate(ci)
        assert abs(-F - fi) <= 1e-9 and abs(T - ti) <= 1e-9
    np.testing.assert_allclose(ls.sigma_ls([0.3, 0.4], 0.254), [0.25237, 0.37946], atol=6e-6)


def test_hertz_closed_form(lsk):
    """k = 2, |c~| <= 1: f~* = -(3 pi/8) c (1 - c^2/4), tau~* = 1 - c^2 + 3/8 c^4 (<= 1e-9)."""
    ls = lsk(2.0)
    c = np.linspace(-1.0, 1.0, 4001)
    np.testing.assert_allclose(ls.ft_star(c), -3 * np.pi / 8 * c * (1 - c**2 / 4), atol=1e-9, rtol=0)
    np.testing.assert_allclose(ls.tau_star(c), 1 - c**2 + 0.375 * c**4, atol=1e-9, rtol=0)
    np.testing.assert_allclose(ls.dft_star(c), -3 * np.pi / 8 * (1 - 0.75 * c**2), atol=1e-7, rtol=0)
    np.testing.assert_allclose(ls.dtau_star(c), -2 * c + 1.5 * c**3, atol=1e-7, rtol=0)


def test_shape_factor():
    """xi(k) table of docs/model.md 2.3 and Appendix A."""
    table = {2: 0.58904862, 3: 0.62024501, 4: 0.63540981, 6: 0.64951905, 8: 0.65578547,
             10: 0.65913446, 20: 0.66442651, 100: 0.66656163, math.inf: 2 / 3}
    for k, xi in table.items():
        assert lugrip.shape_factor(k) == pytest.approx(xi, abs=6e-9)
    assert lugrip.shape_factor(2) == pytest.approx(3 * math.pi / 16, abs=1e-15)
    assert lugrip.shape_factor(4) == pytest.approx(0.6354098136, abs=6e-11)
    assert lugrip.LimitSurface(math.inf).xi == 2 / 3
    assert lugrip.ContactParams.table1().xi == lugrip.shape_factor(4.0)


@pytest.mark.parametrize("k", [0.2, 1e-9, -1.0, -math.inf, math.nan])
def test_invalid_k_raises(k):
    with pytest.raises(ValueError, match="k"):
        lugrip.LimitSurface(k)


class TestShapes:
    """Numpy in, numpy out: every method keeps the input's shape."""

    METHODS = ("ft_star", "tau_star", "dft_star", "dtau_star", "G")

    @pytest.mark.parametrize("method", METHODS)
    def test_scalar_gives_0d(self, method, lsk):
        ls = lsk(4.0)
        out = getattr(ls, method)(0.7)
        assert np.ndim(out) == 0
        assert isinstance(float(out), float)
        assert float(out) == getattr(ls, method)(np.array([0.7]))[0]
        assert np.ndim(getattr(ls, method)(np.float64(0.7))) == 0
        assert np.ndim(getattr(ls, method)(np.array(0.7))) == 0

    @pytest.mark.parametrize("method", METHODS)
    @pytest.mark.parametrize("shape", [(0,), (5,), (3, 4), (2, 0), (2, 3, 2)])
    def test_nd_shapes_preserved(self, method, shape, lsk):
        ls = lsk(4.0)
        rng = np.random.default_rng(1)
        c = rng.uniform(-5, 5, size=shape)
        out = getattr(ls, method)(c)
        assert isinstance(out, np.ndarray)
        assert out.shape == shape
        assert out.dtype == np.float64
        flat = getattr(ls, method)(c.ravel())
        np.testing.assert_array_equal(out.ravel(), flat)
        for idx in np.ndindex(shape):
            assert out[idx] == getattr(ls, method)(float(c[idx]))

    def test_non_contiguous_lists_ints_float32(self, lsk):
        ls = lsk(4.0)
        c = np.linspace(-3, 3, 24).reshape(4, 6)
        np.testing.assert_array_equal(ls.ft_star(c.T), ls.ft_star(c).T)
        np.testing.assert_array_equal(ls.tau_star(c[:, ::2]), ls.tau_star(c)[:, ::2])
        np.testing.assert_array_equal(ls.ft_star([0.5, 1, 2]), ls.ft_star(np.array([0.5, 1.0, 2.0])))
        assert ls.tau_star(1) == ls.tau_star(1.0)
        c32 = np.array([0.25, 0.5], dtype=np.float32)
        np.testing.assert_array_equal(ls.ft_star(c32), ls.ft_star(c32.astype(np.float64)))
        # input is not modified
        before = c.copy()
        ls.G(c)
        np.testing.assert_array_equal(c, before)

    def test_sigma_ls_shape_and_formula(self, lsk):
        ls = lsk(4.0)
        c = np.linspace(0, 20, 60).reshape(3, 20)
        s = ls.sigma_ls(c, 0.254)
        assert s.shape == (3, 20)
        F, T = np.abs(ls.ft_star(c)), ls.tau_star(c)
        np.testing.assert_allclose(s, F**1.254 / T, rtol=1e-14, atol=0)
        assert np.ndim(ls.sigma_ls(0.3, 0.254)) == 0


@pytest.mark.parametrize("k", [2.0, 3.0, 4.0, 8.0, math.inf], ids=lambda k: f"k={k:g}")
def test_parity_signs_and_monotonicity(k, lsk):
    """f~* odd and opposite in sign to c~, tau~* even and positive; F up, T down, sigma_LS up."""
    ls = lsk(k)
    a = np.concatenate([np.linspace(1e-3, 3, 3000), np.geomspace(3.001, 1000, 2000)])
    f, t = ls.ft_star(a), ls.tau_star(a)
    assert np.all(f < 0) and np.all(ls.ft_star(-a) > 0)
    np.testing.assert_array_equal(ls.ft_star(-a), -f)
    np.testing.assert_array_equal(ls.tau_star(-a), t)
    assert np.all(t > 0) and np.all(t < 1) and np.all(-f < 1)
    assert np.all(np.diff(-f) > 0) and np.all(np.diff(t) < 0)
    for gamma in (0.254, 0.2569, 1 / 3):
        assert np.all(np.diff(ls.sigma_ls(a, gamma)) > 0)
    assert ls.ft_star(0.0) == 0.0 and ls.tau_star(0.0) == 1.0
    assert ls.ft_star(math.inf) == -1.0 and ls.tau_star(-math.inf) == 0.0


@pytest.mark.parametrize("k", [2.0, 4.0, 8.0, math.inf], ids=lambda k: f"k={k:g}")
def test_maximum_dissipation_and_torque_capacity(k, lsk):
    """d tau~*/dc~ = (c~/xi) d f~*/dc~ and G'(a) = F(a), from central differences of values."""
    ls = lsk(k)
    a = np.array([0.05, 0.3, 0.7, 1.3, 2.5, 8.0, 40.0])
    h = 1e-5
    df = (ls.ft_star(a + h) - ls.ft_star(a - h)) / (2 * h)
    dt = (ls.tau_star(a + h) - ls.tau_star(a - h)) / (2 * h)
    assert np.all(np.abs(dt - a / ls.xi * df) <= 5e-5 * (1 + a)), dt - a / ls.xi * df
    dG = (ls.G(a + h) - ls.G(a - h)) / (2 * h)
    np.testing.assert_allclose(dG, -ls.ft_star(a), atol=5e-5, rtol=0)
    assert ls.G(0.0) == pytest.approx(ls.xi, abs=1e-15)


def test_elliptic_limit_surface_closed_form():
    """k = 0 selects the ellipse (f~)^2 + (tau~)^2 = 1: against its closed form, written here
    from the maximum-dissipation rule (the ellipse's normal at (f~, tau~) is parallel to
    (c~/xi, 1)), with xi fixed at the k = 4 value; no pressure exponent reproduces it."""
    ls = lugrip.LimitSurface(0.0)
    assert ls.xi == lugrip.shape_factor(4.0) == lugrip.shape_factor(0.0)
    c = np.concatenate([-np.geomspace(1e-3, 50, 40), [0.0], np.geomspace(1e-3, 50, 40)])
    u = np.abs(c) / ls.xi
    np.testing.assert_allclose(np.abs(ls.ft_star(c)), u / np.sqrt(1 + u**2), atol=1e-14)
    np.testing.assert_allclose(ls.tau_star(c), 1 / np.sqrt(1 + u**2), atol=1e-14)
    assert np.all(np.sign(ls.ft_star(c[c != 0])) == -np.sign(c[c != 0]))
    np.testing.assert_allclose(ls.G(c), ls.xi * np.sqrt(1 + u**2), rtol=1e-13)  # xi T + a F
    # the pressure family lies inside the ellipse (>= 1.5 % somewhere) for every k
    a = np.geomspace(0.05, 5, 200)
    for k in (0.5, 1.0, 2.0, 4.0, 8.0, math.inf):
        pk = lugrip.LimitSurface(k)
        radius = np.hypot(pk.ft_star(a), pk.tau_star(a))
        assert radius.min() < 0.985, k
    params = lugrip.ContactParams.table1().replace(k=0.0)
    assert params.xi == ls.xi
    model = lugrip._core.ContactModel(params.to_core())
    tau2 = float(np.asarray(model.tau_max(np.array([2.0])))[0])
    assert tau2 == pytest.approx(params.mu * ls.xi * params.delta * 2.0 ** (1 + params.gamma), rel=1e-12)


def test_patch_plant_refuses_the_ellipse():
    """The pressure patch needs a pressure distribution; k = 0 (no pressure law) is refused
    with a message naming the reason, while the contact model accepts it."""
    from lugrip.sim import PatchContact

    p = lugrip.ContactParams.table1().replace(k=0.0)
    with pytest.raises(ValueError, match="elliptic limit surface"):
        PatchContact(p)
    PatchContact(p.replace(k=0.5))
