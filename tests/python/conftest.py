"""Shared fixtures: the independent LS reference, parameter sets, slow oracles."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import lugrip

REFERENCE_DIR = Path(__file__).resolve().parents[1] / "reference"
LS_REFERENCE_CSV = REFERENCE_DIR / "ls_reference.csv"

# No per-example deadline: the first call of a parameter set builds the LS tables (~0.1 s).
settings.register_profile(
    "lugrip", deadline=None, suppress_health_check=[HealthCheck.too_slow], print_blob=True
)
settings.load_profile("lugrip")


def load_ls_reference(path: Path = LS_REFERENCE_CSV) -> dict[float, dict[str, np.ndarray]]:
    """k -> {'c', 'ft', 'tau', 'G'} arrays from tests/reference/ls_reference.csv."""
    rows: dict[float, list[tuple[float, ...]]] = {}
    header = None
    for line in path.read_text().splitlines():
        if not line or line.startswith("#"):
            continue
        cells = line.split(",")
        if header is None:
            header = cells
            continue
        rec = dict(zip(header, cells))
        k = math.inf if rec["k"] == "inf" else float(rec["k"])
        rows.setdefault(k, []).append(
            (float(rec["c_tilde"]), float(rec["ft_star"]), float(rec["tau_star"]), float(rec["G"]))
        )
    out = {}
    for k, r in rows.items():
        a = np.array(r)
        out[k] = {"c": a[:, 0], "ft": a[:, 1], "tau": a[:, 2], "G": a[:, 3]}
    return out


@pytest.fixture(scope="session")
def ls_reference():
    return load_ls_reference()


@pytest.fixture(scope="session")
def table1():
    return lugrip.ContactParams.table1()


_SURFACES: dict[float, lugrip.LimitSurface] = {}


def surface(k: float) -> lugrip.LimitSurface:
    """One LimitSurface per k for the whole session."""
    if k not in _SURFACES:
        _SURFACES[k] = lugrip.LimitSurface(k)
    return _SURFACES[k]


def tau_max(p: lugrip.ContactParams, f_n):
    """mu xi delta f_n^(gamma+1) (eq. 4), computed here from the parameters."""
    return p.mu * lugrip.shape_factor(p.k) * p.delta * np.asarray(f_n, float) ** (p.gamma + 1.0)


def viscous_ratio(p: lugrip.ContactParams, f_n):
    """K = pi delta^3 beta_A f_n^(3 gamma - 1) / mu (docs/model.md 5.1)."""
    return math.pi * p.delta**3 * p.beta_a * np.asarray(f_n, float) ** (3 * p.gamma - 1) / p.mu


@pytest.fixture(scope="session")
def lsk():
    """lsk(k) -> cached lugrip.LimitSurface(k)."""
    return surface


@pytest.fixture(scope="session")
def phys():
    """Independent formulas of the contact quantities (tau_max, viscous_ratio)."""
    import types

    return types.SimpleNamespace(tau_max=tau_max, viscous_ratio=viscous_ratio)


@pytest.fixture
def exit_2(capsys):
    """A command-line call that must be refused: ``exit_2(argv)`` runs ``lugrip.cli.main`` and
    asserts exit code 2 with a one-line message and no traceback on stderr; returns the line."""
    from lugrip.cli import main

    def run(argv) -> str:
        rc = main([str(a) for a in argv])
        err = capsys.readouterr().err.strip()
        assert rc == 2, err
        assert len(err.splitlines()) == 1 and "Traceback" not in err, err
        return err

    return run
