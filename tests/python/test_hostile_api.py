"""Hostile values through the Python API of the contact layer: each call gives a finite result
(or a documented non-finite marker) or a ValueError whose message names the field; never an
OverflowError, a TypeError from the bindings or a message that echoes a huge value.

Invariant tests: no plant involved.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import lugrip

FIELDS = ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma", "k", "c_max")
TABLE1 = lugrip.ContactParams.table1().to_dict()

hostile = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**500), max_value=10**500),
    st.booleans(), st.none(), st.text(max_size=20),
    st.lists(st.floats(), max_size=3), st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
    st.sampled_from([np.float32(1.5), np.int64(3), np.array(2.0), np.array([1.0, 2.0]), 1e400j]),
)


def _names_a_field(message: str, fields) -> bool:
    return any(f in message for f in fields)


@settings(max_examples=400, deadline=None)
@given(values=st.dictionaries(st.sampled_from(FIELDS), hostile, min_size=1, max_size=4))
def test_contact_params_hostile_fields(values):
    kwargs = {**TABLE1, **values}
    try:
        p = lugrip.ContactParams(**kwargs)
    except ValueError as err:
        msg = str(err)
        assert _names_a_field(msg, values), msg
        assert len(msg) < 2000
        return
    for name in FIELDS:  # accepted: plain floats that satisfy the documented ranges
        v = getattr(p, name)
        assert isinstance(v, float) and not math.isnan(v)
        assert math.isfinite(v) or name == "k"


@settings(max_examples=200, deadline=None)
@given(values=st.dictionaries(st.sampled_from(FIELDS), hostile, min_size=1, max_size=3),
       nested=st.booleans())
def test_from_dict_hostile_fields(values, nested):
    data = {**TABLE1, **values}
    if nested:
        data = {"contact": {k: {"value": v, "unit": "-"} for k, v in data.items()}}
    try:
        lugrip.ContactParams.from_dict(data)
    except ValueError as err:
        assert _names_a_field(str(err), values), str(err)


def test_named_cases():
    with pytest.raises(ValueError, match="ContactParams.mu.*boolean"):
        lugrip.ContactParams(**{**TABLE1, "mu": True})
    with pytest.raises(ValueError, match="ContactParams.beta_a.*too large") as info:
        lugrip.ContactParams(**{**TABLE1, "beta_a": 10**400})
    assert "0000" not in str(info.value)
    with pytest.raises(ValueError, match="contact: must be a mapping"):
        lugrip.ContactParams.from_dict({"contact": None})
    with pytest.raises(ValueError, match="f_n_min"):
        lugrip.estimate_cor("table1", 1.0, 0.1, 0.0, f_n_min="abc")
    with pytest.raises(ValueError, match="^k: "):
        lugrip.LimitSurface(10**400)
    with pytest.raises(ValueError, match="f_t: must be a number"):
        lugrip.estimate_cor("table1", [1.0, 2.0], ["a", None], 0.0)
    with pytest.raises(ValueError, match="shapes do not broadcast: f_n"):
        lugrip.estimate_cor("table1", [1.0, 2.0], [1.0, 2.0, 3.0], 0.0)


arrays = st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                            st.sampled_from([1e300, -1e300, 5e-324, 0.0, -0.0])),
                  min_size=1, max_size=30)


@settings(max_examples=150, deadline=None)
@given(f_n=arrays, f_t=arrays, tau=arrays)
def test_estimate_cor_outputs_finite_for_any_samples(f_n, f_t, tau):
    """The estimator's promise through the Python layer: outputs finite for any input, bad
    samples flagged INVALID_SAMPLE or NO_CONTACT."""
    n = min(len(f_n), len(f_t), len(tau))
    fn, ft, tq = (np.array(a[:n]) for a in (f_n, f_t, tau))
    r = lugrip.estimate_cor("aluminium_can", fn, ft, tq)
    for name in ("c_tilde", "c", "g", "sigma_1", "y", "ft_tilde", "tau_tilde"):
        assert np.all(np.isfinite(getattr(r, name))), name
    assert np.all(np.abs(r.c_tilde) <= 1.5)
    bad = ~(np.isfinite(fn) & np.isfinite(ft) & np.isfinite(tq))
    assert np.all(np.isin(r.status[bad], [lugrip.Status.INVALID_SAMPLE, lugrip.Status.NO_CONTACT]))


@settings(max_examples=50, deadline=None)
@given(k=hostile)
def test_limit_surface_and_shape_factor(k):
    for fn in (lugrip.LimitSurface, lugrip.shape_factor):
        try:
            out = fn(k)
        except ValueError as err:
            assert "k" in str(err)
            continue
        xi = out.xi if isinstance(out, lugrip.LimitSurface) else out
        assert math.isfinite(xi) and 0.0 <= xi <= 2.0 / 3.0 + 1e-12  # xi(inf) = 2/3


OBSERVER_FIELDS = ("dt", "gain", "bandwidth", "torque_noise", "resolution_max", "max_invalid",
                   "substeps", "max_substeps", "filter_force", "f_n_min", "torque_cutoff")


@settings(max_examples=300, deadline=None)
@given(values=st.dictionaries(st.sampled_from(OBSERVER_FIELDS), hostile, min_size=1, max_size=3))
def test_observer_hostile_keywords(values):
    """Observer keywords: an observer whose first step is finite, or a ValueError naming the
    field; never a TypeError or OverflowError from the bindings."""
    try:
        obs = lugrip.Observer("table1", **values)
    except ValueError as err:
        assert _names_a_field(str(err), values), str(err)
        return
    run = obs.run(lugrip.simulate_sliding("table1", n_maneuvers=1, seed=0))
    assert np.all(np.isfinite(run.omega_hat))


@settings(max_examples=200, deadline=None)
@given(f_t=st.floats(min_value=0.0, max_value=1e300), tau=st.floats(min_value=-1e300, max_value=1e300))
def test_static_grasp_force_finite_or_value_error(f_t, tau):
    """A finite load: a finite, non-negative force, or a ValueError naming the load."""
    try:
        f = lugrip.static_grasp_force("aluminium_can", f_t=f_t, tau=tau)
    except ValueError as err:
        assert "f_t" in str(err) and "tau" in str(err)
        return
    assert math.isfinite(float(f)) and float(f) >= 0.0
