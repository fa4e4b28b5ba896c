"""``lugrip ls``: the normalized limit surface (paper Figures 3 and 7) and a table of values.

All values come from :class:`lugrip.LimitSurface` (the C++ tables); nothing is integrated here.
Sign convention (docs/model.md 3.2): f~*_tLS(c~) is odd with the sign opposite to c~, tau~*_LS(c~)
is even and positive.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from dataclasses import dataclass
from pathlib import Path

from . import CliError, k_label, parse_k, positive_float
from ._output import check_dir, check_file, is_same_file, staged_path

__all__ = [
    "DEFAULT_K",
    "FIG3_NAME",
    "FIG7_NAME",
    "TABLE_C",
    "LsTable",
    "demo_section",
    "figure3",
    "figure7",
    "ls_table",
    "register",
    "run",
    "write_figures",
]

DEFAULT_K = (2.0, 4.0, math.inf)
TABLE_C = (0.0, 0.1, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0)
"""Default c~ values of the printed table (those <= --c-max are printed)."""
MARKED_C = (0.0, 0.25, 0.5, 1.0, 1.5, 3.0)
"""c~ values marked (with their negatives) on Figure 7."""
FIG3_NAME = "fig03_limit_surface_curves"
FIG7_NAME = "fig07_limit_surface"

_EPILOG = """\
examples:
  lugrip ls                                  # k = 2, 4, inf; figures in out/
  lugrip ls --k 4 --c 0 0.5 1 1.5 --csv ls.csv
  lugrip ls --k 2 3 4 8 inf --c-max 3 --format pdf --out figures/
"""


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "ls",
        help="limit-surface curves (paper Figures 3 and 7) and a table of values",
        description=(
            "Draw the normalized limit surface of a soft circular contact for pressure "
            "exponents k (paper Figure 3: f~*_tLS(c~) and tau~*_LS(c~) vs the normalized CoR "
            "c~; Figure 7: the LS cross-section (f~*, tau~*) parametrized by c~) and print "
            "f~* and tau~* per k with the shape factor xi(k). Sign convention (docs/model.md 3.2): "
            "f~* is odd with the sign opposite to c~, tau~* is even and positive."),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--k", nargs="+", type=parse_k, default=list(DEFAULT_K), metavar="K",
                   help="pressure exponents: 2 Hertz, 4 the paper's xi = 0.6354, inf uniform, "
                        "ellipse the elliptic limit surface "
                        "(default: 2 4 inf)")
    p.add_argument("--out", type=Path, default=Path("out"), metavar="DIR",
                   help="directory for the figures (default: out)")
    p.add_argument("--c-max", type=positive_float, default=5.0, metavar="C",
                   help="Figure 3 shows c~ in [-C, C]; the table stops at C (default: 5)")
    p.add_argument("--format", choices=("png", "pdf", "svg"), default="png",
                   help="figure file format (default: png)")
    p.add_argument("--c", nargs="+", type=float, default=None, metavar="C_TILDE",
                   help="c~ values of the table (default: 0 0.1 0.25 0.5 0.75 1 1.5 2 3 5 10, "
                        "up to --c-max)")
    p.add_argument("--csv", type=Path, default=None, metavar="FILE",
                   help="also write the table as CSV (columns k, xi, c_tilde, ft_star, tau_star)")
    p.add_argument("--no-plot", action="store_true", help="only print the table")
    p.add_argument("--force", action="store_true",
                   help="overwrite existing figures in --out and an existing --csv file")
    p.set_defaults(run=run)


# --- computation --------------------------------------------------------------------------

@dataclass(frozen=True)
class LsTable:
    """f~* and tau~* at the c~ values, per k (lists in the order of `k`)."""

    k: tuple[float, ...]
    xi: tuple[float, ...]
    c_tilde: tuple[float, ...]
    ft_star: tuple[tuple[float, ...], ...]   # [k][c]
    tau_star: tuple[tuple[float, ...], ...]  # [k][c]

    def format(self) -> str:
        """Fixed-width text table: c~, then f~* and tau~* per k, with xi(k) in the header."""
        cw, vw = 8, 13
        lines = [
            ("Normalized limit surface (docs/model.md 3.2): f~*(c~) = f~*_tLS is odd, with the sign "
            "opposite to c~;"),
            ("tau~*(c~) = tau~*_LS is even and positive. f_t,max = mu f_n, "
            "tau_max = mu xi(k) rho f_n."),
            "",
            " " * cw + "".join(f"{'k = ' + k_label(k):>{2 * vw}}" for k in self.k),
            f"{'xi(k)':>{cw}}" + "".join(f"{x:>{2 * vw}.8f}" for x in self.xi),
            f"{'c~':>{cw}}" + "".join(f"{'f~*':>{vw}}{'tau~*':>{vw}}" for _ in self.k),
        ]
        for j, c in enumerate(self.c_tilde):
            row = f"{c:>{cw}.4g}"
            for i in range(len(self.k)):
                row += f"{self.ft_star[i][j]:>{vw}.8f}{self.tau_star[i][j]:>{vw}.8f}"
            lines.append(row)
        return "\n".join(lines) + "\n"

    def write_csv(self, path: str | Path) -> Path:
        """Long format: one row per (k, c~): k, xi, c_tilde, ft_star, tau_star."""
        path = Path(path)
        if path.parent and not path.parent.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["k", "xi", "c_tilde", "ft_star", "tau_star"])
            for i, k in enumerate(self.k):
                for j, c in enumerate(self.c_tilde):
                    w.writerow([k_label(k), repr(self.xi[i]), repr(c),
                                repr(self.ft_star[i][j]), repr(self.tau_star[i][j])])
        return path


def _surfaces(ks):
    import lugrip

    out = []
    for k in ks:
        try:
            out.append(lugrip.LimitSurface(k))
        except ValueError as err:
            raise CliError(f"argument --k: {err}") from None
    return out


def ls_table(ks, c_values) -> LsTable:
    """Tabulate f~* and tau~* (lugrip.LimitSurface) at c_values for each k."""
    import numpy as np

    c = np.asarray(list(c_values), dtype=float)
    surfaces = _surfaces(ks)
    return LsTable(
        k=tuple(float(k) for k in ks),
        xi=tuple(float(s.xi) for s in surfaces),
        c_tilde=tuple(float(x) for x in c),
        ft_star=tuple(tuple(float(v) for v in np.atleast_1d(s.ft_star(c))) for s in surfaces),
        tau_star=tuple(tuple(float(v) for v in np.atleast_1d(s.tau_star(c))) for s in surfaces),
    )


# --- figures ------------------------------------------------------------------------------

_F_SYM = r"\tilde f^{*}_{tLS}"
_T_SYM = r"\tilde\tau^{*}_{LS}"
_C_SYM = r"\tilde c"


def _k_legend(k: float) -> str:
    if k == 0.0:
        return "elliptic LS"
    name = {2.0: " (Hertz)", math.inf: " (uniform)"}.get(k, "")
    return (r"$k = \infty$" if math.isinf(k) else f"$k = {k:g}$") + name


def _colors(ks):
    from .. import plot

    return [plot.color(i) for i in range(len(ks))]


def _reference_index(ks) -> int:
    """Index of the k used as reference (differences, labels): 4 if given, else the first."""
    return list(ks).index(4.0) if 4.0 in ks else 0


_DASHES = ("--", "-.", ":", (0, (6, 2, 1, 2, 1, 2)), (0, (1, 1)))


def _line_styles(ks) -> list[dict]:
    """Same colour and dash per k in every figure: the reference k solid and thicker (drawn on
    top), the others dashed, so curves that nearly coincide stay distinguishable."""
    colors = _colors(ks)
    ref = _reference_index(ks)
    styles, n = [], 0
    for i in range(len(ks)):
        if i == ref:
            styles.append({"color": colors[i], "linestyle": "-", "linewidth": 2.4, "zorder": 4})
        else:
            styles.append({"color": colors[i], "linestyle": _DASHES[n % len(_DASHES)],
                           "linewidth": 1.7, "zorder": 3})
            n += 1
    return styles


def figure3(ks, c_max: float = 5.0):
    """Paper Figure 3: f~*_tLS(c~) and tau~*_LS(c~) on [-c_max, c_max] for each k; with more
    than one k a second row shows the difference to k = 4 (or the first k)."""
    import numpy as np

    from .. import plot

    surfaces = _surfaces(ks)
    colors = _colors(ks)
    styles = _line_styles(ks)
    # dense grid that contains 0 and +-1 (the CoR on the rim of the contact, a curvature kink)
    c = np.unique(np.concatenate([np.linspace(-c_max, c_max, 2001), [-1.0, 0.0, 1.0]]))
    c = c[np.abs(c) <= c_max]
    f = [s.ft_star(c) for s in surfaces]
    t = [s.tau_star(c) for s in surfaces]
    diff = len(ks) > 1
    ref = _reference_index(ks)
    with plot.style():
        fig, axes = plot.new_figure(
            2 if diff else 1, 2, sharex=True, row_height=3.4, col_width=5.0, squeeze=False,
            height_ratios=(3.0, 1.3) if diff else None,
            title="Normalized limit surface vs the normalized CoR position (paper Figure 3)")
        ax_f, ax_t = axes[0]
        for i, k in enumerate(ks):
            ax_f.plot(c, f[i], label=_k_legend(k), **styles[i])
            ax_t.plot(c, t[i], label=_k_legend(k), **styles[i])
        ax_f.set_ylabel(plot.axis_label("normalized friction force", _F_SYM, "-"))
        ax_t.set_ylabel(plot.axis_label("normalized friction torque", _T_SYM, "-"))
        ax_f.set_ylim(-1.08, 1.08)
        ax_t.set_ylim(-0.03, 1.06)
        for ax in (ax_f, ax_t):
            ax.axhline(0.0, color="black", linewidth=0.7)
            ax.axvline(0.0, color="black", linewidth=0.7)
            for side in (-1.0, 1.0):
                if c_max > 1.0:
                    ax.axvline(side, color="#777777", linewidth=0.9, linestyle=":")
        if c_max > 1.0:
            ax_t.annotate(r"$|\tilde c| = 1$: CoR on the rim", xy=(1.0, 0.95),
                          xytext=(6, 0), textcoords="offset points", fontsize=8.5,
                          color="#555555", va="center")
        ax_f.annotate("translation\n" + r"$\tilde c \to -\infty$: $+1$", xy=(-c_max, 1.0),
                      xytext=(4, -6), textcoords="offset points", va="top", fontsize=8.5,
                      color="#555555")
        ax_f.annotate("translation\n" + r"$\tilde c \to +\infty$: $-1$", xy=(c_max, -1.0),
                      xytext=(-4, 6), textcoords="offset points", ha="right", va="bottom",
                      fontsize=8.5, color="#555555")
        ax_t.annotate("pure rotation\n" + r"$\tilde c = 0$: $1$", xy=(0.0, 1.0),
                      xytext=(-50, -4), textcoords="offset points", ha="right", va="center",
                      fontsize=8.5, color="#555555",
                      arrowprops={"arrowstyle": "->", "color": "#777777", "lw": 0.8})
        ax_f.legend(loc="upper right")
        ax_f.set_title(r"$\tilde f^{*}_{tLS}$: odd, sign opposite to $\tilde c$")
        ax_t.set_title(r"$\tilde\tau^{*}_{LS}$: even, positive")
        if diff:
            ax_df, ax_dt = axes[1]
            for i, k in enumerate(ks):
                if i == ref:
                    continue
                ax_df.plot(c, f[i] - f[ref], label=_k_legend(k), **styles[i])
                ax_dt.plot(c, t[i] - t[ref], label=_k_legend(k), **styles[i])
            ref_text = ("k = ∞" if math.isinf(ks[ref]) else
                        "the ellipse" if ks[ref] == 0.0 else f"k = {ks[ref]:g}")
            ax_df.set_ylabel(f"difference to\n{ref_text} [-]")
            ax_dt.set_ylabel(f"difference to\n{ref_text} [-]")
            for ax in (ax_df, ax_dt):
                ax.axhline(0.0, color=colors[ref], linewidth=1.2)
                ax.set_xlabel(plot.axis_label("normalized CoR position", _C_SYM + r" = c/\rho",
                                              "-"))
        else:
            for ax in (ax_f, ax_t):
                ax.set_xlabel(plot.axis_label("normalized CoR position", _C_SYM + r" = c/\rho",
                                              "-"))
        ax_f.set_xlim(-c_max, c_max)
    return fig


def _place_label(ax, x, y, nx, ny, text, color):
    ax.annotate(text, xy=(x, y), xytext=(16 * nx, 16 * ny), textcoords="offset points",
                ha="left" if nx > 0.35 else ("right" if nx < -0.35 else "center"),
                va="bottom" if ny > 0.35 else ("top" if ny < -0.35 else "center"),
                fontsize=8.5, color=color,
                arrowprops={"arrowstyle": "-", "color": color, "lw": 0.6, "shrinkA": 0,
                            "shrinkB": 2})


def figure7(ks, marked=MARKED_C):
    """Paper Figure 7: the normalized LS cross-section, the closed curve
    +-(f~*(c~), tau~*(c~)), with the values of c~ marked on the upper half (omega < 0 in the
    sign convention of docs/model.md 1.3) for k = 4 (or the first k)."""
    import numpy as np
    from matplotlib.patches import Rectangle

    from .. import plot

    surfaces = _surfaces(ks)
    colors = _colors(ks)
    styles = _line_styles(ks)
    ref = _reference_index(ks)
    theta = np.linspace(-0.5 * np.pi, 0.5 * np.pi, 4001)[1:-1]
    c = np.tan(theta)  # c~ over (-inf, inf), dense near 0
    with plot.style():
        fig, ax = plot.new_figure(width=6.6, height=7.4,
                                  title="Normalized limit surface parametrized by "
                                        r"$\tilde c$ (paper Figure 7)")
        ax.add_patch(Rectangle(
            (-1.0, -1.0), 2.0, 2.0, fill=False, linestyle="--", linewidth=0.9,
            edgecolor="#999999",
            label=r"uncoupled limits $|\tilde f_t| \leq 1$, $|\tilde\tau| \leq 1$"))
        for i, (k, s) in enumerate(zip(ks, surfaces)):
            fu, tu = s.ft_star(c), s.tau_star(c)
            # closed curve: upper half from (1, 0) (c~ -> -inf) through (0, 1) to (-1, 0),
            # then the mirrored half -(f~*, tau~*) back to (1, 0)
            x = np.concatenate([[1.0], fu, [-1.0], -fu, [1.0]])
            y = np.concatenate([[0.0], tu, [0.0], -tu, [0.0]])
            ax.plot(x, y, label=_k_legend(k), **styles[i])
        # marked values of c~ on the reference curve
        s = surfaces[ref]
        col = colors[ref]
        values = sorted({v for m in marked for v in (m, -m)})
        cm = np.asarray(values, dtype=float)
        fm, tm = s.ft_star(cm), s.tau_star(cm)
        ax.plot(fm, tm, "o", color=col, markersize=5.5, markeredgecolor="white", zorder=4)
        xi = s.xi
        for cv, fx, ty in zip(cm, fm, tm):
            # outward normal of the LS at this point is parallel to (-c~, xi) (docs/model.md 3.2)
            nx, ny = -cv, xi
            norm = math.hypot(nx, ny)
            label = r"$\tilde c = 0$" if cv == 0 else f"{cv:+g}"
            _place_label(ax, fx, ty, nx / norm, ny / norm, label, "#333333")
        # corners: pure rotation and pure translation
        ax.plot([0.0, 0.0], [1.0, -1.0], "s", color="black", markersize=6, zorder=5,
                label=r"pure rotation, $\tilde c = 0$")
        ax.plot([1.0, -1.0], [0.0, 0.0], "D", color="black", markersize=5.5, zorder=5,
                markerfacecolor="white",
                label=r"pure translation, $|\tilde c| \to \infty$")
        ax.text(0.0, -0.55, r"lower half: $-(\tilde f^{*}, \tilde\tau^{*})$" + "\n"
                r"(opposite sense of rotation)", ha="center", va="center", fontsize=8.5,
                color="#555555")
        ax.text(0.0, 0.45, r"upper half: $(\tilde f^{*}(\tilde c), \tilde\tau^{*}(\tilde c))$"
                + "\n" + rf"labels: $\tilde c$ for {_k_legend(ks[ref])}", ha="center",
                va="center", fontsize=8.5, color="#555555")

        if len(ks) > 1:
            fr, tr = surfaces[ref].ft_star(c), surfaces[ref].tau_star(c)
            dev = max(max(np.max(np.abs(s_.ft_star(c) - fr)), np.max(np.abs(s_.tau_star(c) - tr)))
                      for s_ in surfaces)
            ax.text(0.99, 0.99, f"the curves nearly coincide: at equal $\\tilde c$ they\n"
                    f"differ by at most {dev:.3f} (Figure 3, bottom row)",
                    transform=ax.transAxes, ha="right", va="top", fontsize=8, color="#555555")
        ax.axhline(0.0, color="black", linewidth=0.7)
        ax.axvline(0.0, color="black", linewidth=0.7)
        ax.set_aspect("equal")
        ax.set_xlim(-1.32, 1.32)
        ax.set_ylim(-1.32, 1.32)
        ax.set_xlabel(plot.axis_label("normalized friction force", _F_SYM + r" = f_t/(\mu f_n)",
                                      "-"))
        ax.set_ylabel(plot.axis_label("normalized friction torque",
                                      _T_SYM + r" = \tau/\tau_{max}", "-"))
        fig.legend(loc="outside lower center", ncols=2, fontsize=8.5)
    return fig


def write_figures(out_dir: str | Path, ks=DEFAULT_K, c_max: float = 5.0,
                  fmt: str = "png") -> list[Path]:
    """Draw Figures 3 and 7 into out_dir; returns the two paths."""
    from .. import plot

    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise CliError(f"argument --out: {out_dir} exists and is not a directory")
    p3 = plot.save(figure3(ks, c_max), out_dir / f"{FIG3_NAME}.{fmt}")
    p7 = plot.save(figure7(ks), out_dir / f"{FIG7_NAME}.{fmt}")
    return [p3, p7]


# --- command ------------------------------------------------------------------------------

def run(args: argparse.Namespace) -> int:
    ks = list(dict.fromkeys(args.k))  # drop repeated k, keep the order
    if args.c is not None:
        bad = [c for c in args.c if not math.isfinite(c)]
        if bad:
            raise CliError(f"argument --c: {bad[0]!r} is not a finite number")
        c_values = list(args.c)
    else:
        c_values = [c for c in TABLE_C if c <= args.c_max + 1e-12]
    # the output policy (commands/_output.py), before any work
    if not args.no_plot:
        check_dir(args.out, "--out", force=args.force,
                  results=(f"{FIG3_NAME}.{args.format}", f"{FIG7_NAME}.{args.format}"))
    if args.csv is not None:
        check_file(args.csv, "--csv", force=args.force, create_parent=True)
        if not args.no_plot and any(is_same_file(args.csv, args.out / f"{n}.{args.format}")
                                    for n in (FIG3_NAME, FIG7_NAME)):
            raise CliError(f"argument --csv: {args.csv} is also a figure of --out")
    table = ls_table(ks, c_values)
    if not args.no_plot:
        paths = write_figures(args.out, ks, args.c_max, args.format)
        for p in paths:
            print(f"wrote {p}", file=sys.stderr)
    sys.stdout.write(table.format())
    if args.csv is not None:
        with staged_path(args.csv, "--csv", force=args.force, create_parent=True) as tmp:
            table.write_csv(tmp)
        print(f"wrote {args.csv}", file=sys.stderr)
    return 0


def demo_section(out_dir: Path) -> str:
    """Demo step: Figures 3 and 7 for k = 2, 4, inf and the xi table (Markdown)."""
    ks = list(DEFAULT_K)
    paths = write_figures(out_dir, ks, 5.0, "png")
    table = ls_table(ks, [0.5, 1.0, 1.5])
    rows = ["| k | pressure | xi(k) | f~*(1) | tau~*(1) | f~*(1.5) | tau~*(1.5) |",
            "|---|---|---|---|---|---|---|"]
    names = {2.0: "Hertz", 4.0: "paper (xi = 0.6354)", math.inf: "uniform"}
    for i, k in enumerate(ks):
        rows.append(f"| {k_label(k)} | {names.get(k, '')} | {table.xi[i]:.8f} | "
                    f"{table.ft_star[i][1]:.6f} | {table.tau_star[i][1]:.6f} | "
                    f"{table.ft_star[i][2]:.6f} | {table.tau_star[i][2]:.6f} |")
    rel = [p.relative_to(out_dir) if p.is_relative_to(out_dir) else p for p in paths]
    return "\n".join([
        ("The limit surface (LS) bounds the friction force f_t and torsional moment tau that a "
        "soft fingertip can transmit at normal force f_n. Normalized by f_t,max = mu f_n and "
        "tau_max = mu xi rho f_n, it depends only on the pressure exponent k. Each point "
        "belongs to a sliding motion, a rotation about the centre of rotation (CoR) at "
        "c = c~ rho on the contact x axis: c~ = 0 is a pure rotation (all torque, no force), "
        "|c~| -> inf a pure translation (all force, no torque). The CoR estimator inverts this "
        "map from a measured wrench. Curves from `lugrip.LimitSurface` (C++ tables, max abs "
        "error 1e-6)."),
        "",
        f"![Figure 3: f~*_tLS(c~) and tau~*_LS(c~)]({rel[0].as_posix()})",
        "",
        ("Figure 3: the two normalized curves vs c~ for k = 2 (Hertz), 4 (the paper) and inf "
        "(uniform). f~* is odd with the sign opposite to c~ (docs/model.md 3.2); the bottom row "
        "shows how weakly the shape depends on k."),
        "",
        f"![Figure 7: normalized limit surface]({rel[1].as_posix()})",
        "",
        ("Figure 7: the LS cross-section (f~*, tau~*) with the values of c~ marked. Small |c~| "
        "means rotation-dominated sliding (high torque), large |c~| translation-dominated; "
        "the pivoting mode stops when c~ > 1."),
        "",
        *rows,
    ]) + "\n"
