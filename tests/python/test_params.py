"""lugrip.ContactParams: validation messages, presets (paper Tables 1 and 2), YAML I/O."""

from __future__ import annotations

import dataclasses
import math

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

import lugrip

TABLE1 = dict(mu=0.47, beta_a=4.9e9, sigma0=16.66, sigma_z=2.0, delta=0.0018, gamma=0.254)
TABLE2 = {
    "big_resin_block": (0.85, 1.24e7),
    "small_resin_block": (0.7, 1.825e7),
    "plastic_bottle": (0.85, 1.963e7),
    "aluminium_can": (0.75, 2.121e7),
}

# One bad value per field, with the rule of docs/model.md / params.hpp.
BAD = {
    "mu": [0.0, -0.47, 10.5, math.nan, math.inf],
    "beta_a": [-1.0, math.nan, math.inf],
    "sigma0": [0.0, -16.66, math.nan, math.inf],
    "sigma_z": [-2.0, math.nan, -math.inf],
    "delta": [0.0, -0.0018, 1.0, math.nan, math.inf],
    "gamma": [0.0, -0.1, 1 / 3, 0.5, math.nan],
    "k": [0.3, 0.4, 1e-9, -4.0, math.nan, -math.inf],
    "c_max": [0.0, -1.5, math.nan, math.inf, 1e4],
}


def valid_rule(name: str, v: float) -> bool:
    """The documented range of each field (params.hpp)."""
    if name == "mu":
        return math.isfinite(v) and 0 < v <= 10
    if name in ("beta_a", "sigma_z"):
        return math.isfinite(v) and v >= 0
    if name == "sigma0":
        return math.isfinite(v) and v >= 1e-12
    if name == "delta":
        return math.isfinite(v) and 0 < v < 1
    if name == "gamma":
        return 0 < v < 1 / 3
    if name == "k":
        return v >= 0.5 or v == 0.0  # 0: the elliptic limit surface
    if name == "c_max":
        return math.isfinite(v) and 0 < v <= 1000
    raise KeyError(name)


def test_table1_preset():
    p = lugrip.ContactParams.table1()
    assert p.to_dict() == {**TABLE1, "k": 4.0, "c_max": 1.5, "static_ratio": 1.0, "kinetic_ratio": 1.0,
                           "stribeck_speed": 0.0}
    assert lugrip.ContactParams.preset("table1") == p
    assert p.xi == pytest.approx(0.6354098136, abs=1e-10)


@pytest.mark.parametrize("name", list(TABLE2))
def test_table2_presets(name):
    """Table 1 with the object's mu and beta_A (paper Table 2)."""
    p = lugrip.ContactParams.preset(name)
    mu, beta_a = TABLE2[name]
    assert (p.mu, p.beta_a) == (mu, beta_a)
    for field in ("sigma0", "sigma_z", "delta", "gamma"):
        assert getattr(p, field) == TABLE1[field]
    assert (p.k, p.c_max) == (4.0, 1.5)
    assert name in lugrip.PRESETS


def test_preset_aliases_and_unknown():
    assert lugrip.ContactParams.preset("Big Resin Block") == lugrip.ContactParams.preset("big_resin_block")
    assert lugrip.ContactParams.preset("aluminum-can") == lugrip.ContactParams.preset("aluminium_can")
    with pytest.raises(ValueError, match="unknown preset 'glass'.*table1"):
        lugrip.ContactParams.preset("glass")
    assert set(lugrip.PRESETS) == {"table1", *TABLE2}


@pytest.mark.parametrize("field,value", [(f, v) for f, vs in BAD.items() for v in vs])
def test_one_bad_field_is_named(field, value):
    """A single bad field raises ValueError naming that field (and only that field)."""
    with pytest.raises(ValueError) as info:
        lugrip.ContactParams(**{**TABLE1, field: value})
    msg = str(info.value)
    assert f"{field} = " in msg
    others = [f for f in BAD if f != field and f"\n{f} = " in msg]
    assert not others, msg
    with pytest.raises(ValueError, match=field):
        lugrip.ContactParams.table1().replace(**{field: value})


def test_every_bad_field_reported_at_once():
    with pytest.raises(ValueError) as info:
        lugrip.ContactParams(mu=-1, beta_a=-1, sigma0=0, sigma_z=-1, delta=0, gamma=0.5, k=0.2, c_max=0)
    msg = str(info.value)
    for field in BAD:
        assert f"{field} = " in msg


def test_non_numeric_and_missing():
    with pytest.raises(ValueError, match="ContactParams.mu"):
        lugrip.ContactParams(**{**TABLE1, "mu": "slippery"})
    with pytest.raises(TypeError):
        lugrip.ContactParams(mu=0.5)  # the physical fields have no defaults
    p = lugrip.ContactParams(**{**TABLE1, "mu": "0.5", "k": 2})  # numeric strings and ints are coerced
    assert p.mu == 0.5 and isinstance(p.k, float)


@given(field=st.sampled_from(sorted(BAD)), value=st.floats(allow_nan=True, allow_infinity=True))
def test_validation_matches_documented_ranges(field, value):
    """Any float in any field: accepted exactly when the documented rule holds."""
    kwargs = {**TABLE1, field: value}
    if valid_rule(field, value):
        p = lugrip.ContactParams(**kwargs)
        assert getattr(p, field) == value
    else:
        with pytest.raises(ValueError, match=field):
            lugrip.ContactParams(**kwargs)


def test_frozen_and_core_round_trip():
    p = lugrip.ContactParams.preset("plastic_bottle")
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.mu = 0.1
    core = p.to_core()
    assert lugrip.ContactParams.from_core(core) == p
    assert hash(p) == hash(lugrip.ContactParams.from_core(core))


@pytest.mark.parametrize("name", lugrip.PRESETS)
def test_yaml_round_trip(name, tmp_path):
    p = lugrip.ContactParams.preset(name)
    path = tmp_path / f"{name}.yaml"
    text = p.to_yaml(path, comment=f"preset {name}")
    assert path.read_text() == text
    assert text.startswith(f"# preset {name}\n")
    data = yaml.safe_load(text)
    assert data["contact"]["beta_a"]["unit"] == "N s/m^3"
    assert data["contact"]["mu"]["value"] == p.mu
    assert lugrip.ContactParams.from_yaml(path) == p


def test_yaml_k_inf(tmp_path):
    """Uniform pressure (k = inf) survives YAML, written by us or by hand."""
    p = lugrip.ContactParams.table1().replace(k=math.inf, c_max=10.0)
    path = tmp_path / "uniform.yaml"
    p.to_yaml(path)
    back = lugrip.ContactParams.from_yaml(path)
    assert back == p and math.isinf(back.k)
    for spelling in (".inf", "inf", "Infinity", ".Inf"):
        hand = tmp_path / "hand.yaml"
        hand.write_text("\n".join(f"{k}: {v}" for k, v in TABLE1.items()) + f"\nk: {spelling}\n")
        q = lugrip.ContactParams.from_yaml(hand)
        assert math.isinf(q.k) and q.k > 0, spelling
        assert lugrip.LimitSurface(q.k).xi == 2 / 3


def test_yaml_errors(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("mu: [unclosed\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        lugrip.ContactParams.from_yaml(bad)
    bad.write_text("- 1\n- 2\n")
    with pytest.raises(ValueError, match="mapping"):
        lugrip.ContactParams.from_yaml(bad)
    bad.write_text("mu: 0.5\n")
    with pytest.raises(ValueError, match="missing.*beta_a"):
        lugrip.ContactParams.from_yaml(bad)
    bad.write_text("\n".join(f"{k}: {v}" for k, v in TABLE1.items()) + "\nfriction: 3\n")
    with pytest.raises(ValueError, match="unknown parameter 'friction'"):
        lugrip.ContactParams.from_yaml(bad)
    bad.write_text("\n".join(f"{k}: {v}" for k, v in {**TABLE1, "gamma": 0.4}.items()) + "\n")
    with pytest.raises(ValueError, match=r"(?s)bad.yaml: .*gamma = 0.4"):
        lugrip.ContactParams.from_yaml(bad)


def test_from_dict_layouts():
    flat = lugrip.ContactParams.from_dict(TABLE1)
    nested = lugrip.ContactParams.from_dict({"contact": {k: {"value": v, "unit": "x"} for k, v in TABLE1.items()}})
    assert flat == nested == lugrip.ContactParams.table1()


def test_yaml_files_wherever_params_are_taken(tmp_path):
    """Functions taking parameters accept a YAML file (a path, or a str ending in .yaml/.yml)
    as well as ContactParams, preset names and dicts; other strings are preset names."""
    import numpy as np

    can = lugrip.ContactParams.preset("aluminium_can")
    path = tmp_path / "can.yml"
    can.to_yaml(path)
    want = lugrip.g(can, 3.0, 0.4)
    for source in (path, str(path)):
        assert lugrip.g(source, 3.0, 0.4) == want
        np.testing.assert_array_equal(
            lugrip.sigma_1(source, [1.0, 5.0], 0.2), lugrip.sigma_1(can, [1.0, 5.0], 0.2)
        )
    assert lugrip.g(path, 3.0, 0.4) != lugrip.g("table1", 3.0, 0.4)
    with pytest.raises(ValueError, match="unknown preset 'can'"):
        lugrip.g("can", 3.0, 0.4)
    with pytest.raises(FileNotFoundError):
        lugrip.g(str(tmp_path / "missing.yaml"), 3.0, 0.4)
    with pytest.raises(TypeError, match=".yaml file"):
        lugrip.g(3.5, 3.0, 0.4)


def test_read_observer_settings_is_exported(tmp_path):
    assert "read_observer_settings" in lugrip.__all__
    assert "read_observer_settings" in lugrip.__doc__
    path = tmp_path / "p.yaml"
    lugrip.ContactParams.table1().to_yaml(path, observer={"bandwidth": 700.0, "integrator": "rk4"})
    assert lugrip.read_observer_settings(path) == {"bandwidth": 700.0, "integrator": "rk4"}
    assert yaml.safe_load(path.read_text())["observer"]["bandwidth"] == 700.0
    lugrip.ContactParams.table1().to_yaml(path)
    assert lugrip.read_observer_settings(path) is None


def test_elliptic_limit_surface_round_trips_and_lists(tmp_path, capsys):
    """k = 0 (the elliptic limit surface) is a valid value: YAML round trip, the k = 4 xi,
    `lugrip params --check` names the shape, `lugrip identify --k ellipse` parses to 0 and
    a k between 0 and 0.5 stays an error."""
    from lugrip.cli import main
    from lugrip.commands.identify import _exponent

    p = lugrip.ContactParams.table1().replace(k=0.0)
    assert p.xi == lugrip.shape_factor(4.0)
    path = tmp_path / "ellipse.yaml"
    p.to_yaml(path)
    assert lugrip.ContactParams.from_yaml(path) == p
    assert main(["params", "--check", str(path)]) == 0
    assert "limit surface: the ellipse" in capsys.readouterr().out
    assert _exponent("ellipse") == 0.0 and _exponent("0") == 0.0 and _exponent("inf") == math.inf
    import argparse

    for bad in ("0.2", "-1", "nan"):
        with pytest.raises(argparse.ArgumentTypeError):
            _exponent(bad)
