"""Standard errors and identifiability of the eq. 32 refinement (log-parameter space)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np


def _weak_directions(H: np.ndarray, names: Sequence[str]):
    """Eigen-decomposition of the scale-free (unit-diagonal) Gauss-Newton matrix: pairs
    (eigenvalue / largest, {name: weight}), weakest first; and the correlation matrix."""
    d = np.sqrt(np.maximum(np.diag(H), 1e-300))
    Hn = H / np.outer(d, d)
    lam, vec = np.linalg.eigh(Hn)
    lam_max = max(lam.max(), 1e-300)
    dirs = []
    for i in np.argsort(lam):
        v = vec[:, i] / d  # back to log-parameter units
        v = v / np.max(np.abs(v))
        dirs.append(
            (
                float(max(lam[i], 0.0) / lam_max),
                {n: float(round(c, 3)) for n, c in zip(names, v) if abs(c) >= 0.05},
            )
        )
    try:
        cov = np.linalg.inv(Hn)
        s = np.sqrt(np.abs(np.diag(cov)))
        corr = cov / np.outer(s, s)
    except np.linalg.LinAlgError:
        corr = np.full_like(H, np.nan)
    return dirs, corr


def _combination_text(weights: Mapping[str, float]) -> str:
    parts = []
    for n, c in weights.items():
        ex = f"{c:+.2g}"
        parts.append(f"{n}^{ex}")
    return " * ".join(parts)
