"""``lugrip params``: contact-parameter presets (paper Tables 1 and 2) as YAML, and validation
of parameter files."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import CliError

__all__ = ["PRESET_SOURCES", "describe", "preset_yaml", "register", "run"]

PRESET_SOURCES = {
    "table1": "paper Table 1: parameters identified on a rigid cardboard slider",
    "big_resin_block": "paper Table 2 (big resin block): mu and beta_A; other fields Table 1",
    "small_resin_block": "paper Table 2 (small resin block): mu and beta_A; other fields Table 1",
    "plastic_bottle": "paper Table 2 (plastic bottle): mu and beta_A; other fields Table 1",
    "aluminium_can": "paper Table 2 (aluminium can): mu and beta_A; other fields Table 1",
}

_BETA_NOTE = (
    "beta_A: the paper prints the unit 'Ns/m'; eq. 7 (f_tv = pi beta_A rho^2 omega c) needs "
    "N s/m^3, so the printed numbers are used unchanged in N s/m^3 (docs/model.md section 11, item 6). "
    "Table 1 (cardboard, 4.9e9) and Table 2 (objects, 1.2e7-2.1e7) differ by 230-400x; each is "
    "used as printed for its own objects (docs/model.md section 11, item 9)."
)

_EPILOG = """\
examples:
  lugrip params --list
  lugrip params --preset table1 > p.yaml
  lugrip params --check p.yaml
"""

_UNITS = {"mu": "-", "beta_a": "N s/m^3", "sigma0": "N m/rad", "sigma_z": "N m s/rad",
          "delta": "m/N^gamma", "gamma": "-", "k": "-", "c_max": "-",
          "static_ratio": "-", "kinetic_ratio": "-", "stribeck_speed": "m/s"}
_MEANING = {"mu": "friction coefficient of the limit surface",
            "beta_a": "viscous friction per unit area and speed",
            "sigma0": "micro-asperity stiffness",
            "sigma_z": "micro-asperity damping",
            "delta": "contact radius rho = delta f_n^gamma",
            "gamma": "contact radius exponent",
            "k": "pressure exponent (0: elliptic limit surface)",
            "c_max": "saturation of |c~|",
            "static_ratio": "break-away friction / mu (S's capacity in stick)",
            "kinetic_ratio": "sliding friction level / mu (S's capacity once sliding)",
            "stribeck_speed": "Stribeck speed of the sliding update's capacity (0: none)"}


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "params",
        help="contact-parameter presets (paper Tables 1, 2) as YAML; check a parameter file",
        description=(
            "Print a parameter preset as YAML (SI units), list the presets, or validate a "
            "parameter file and print the parameters with the derived contact quantities."),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--preset", metavar="NAME",
                   help="print a preset as YAML: " + ", ".join(PRESET_SOURCES))
    g.add_argument("--list", action="store_true", help="list the presets")
    g.add_argument("--check", type=Path, metavar="FILE",
                   help="validate a parameter YAML file (contact parameters and the observer block, "
                   "as `lugrip observe --params` reads it) and print the parsed values")
    p.set_defaults(run=run)


def preset_yaml(name: str) -> str:
    """YAML text of a preset, with comments giving its source and the beta_A unit note."""
    from .. import PRESETS, ContactParams

    key = name.lower().replace("-", "_")
    if key == "aluminum_can":
        key = "aluminium_can"
    if key not in PRESETS:
        raise CliError(f"argument --preset: unknown preset {name!r}; "
                       f"known: {', '.join(PRESETS)}")
    params = ContactParams.preset(key)
    header = [
        f"# lugrip contact parameters: {key}",
        f"# Source: {PRESET_SOURCES[key]}.",
        "# SI units. " + _BETA_NOTE[: _BETA_NOTE.index(" Table 1")],
        "#" + _BETA_NOTE[_BETA_NOTE.index(" Table 1"):],
        f"# Written by: lugrip params --preset {key}",
    ]
    return _wrap_comments(header) + params.to_yaml()


def _wrap_comments(lines: list[str], width: int = 92) -> str:
    import textwrap

    out = []
    for line in lines:
        body = line[1:].strip()
        out.extend("# " + part for part in textwrap.wrap(body, width - 2))
    return "\n".join(out) + "\n"


def describe(params, source: str = "") -> str:
    """Human-readable listing: fields with units, xi(k), rho, f_t,max, tau_max at 1 and 5 N."""
    import numpy as np

    from .. import _core

    lines = [f"contact parameters{' from ' + source if source else ''} (valid):"]
    for name, value in params.to_dict().items():
        lines.append(f"  {name:<8} = {value:<14.6g} [{_UNITS[name]}]  {_MEANING[name]}")
    if params.k == 0.0:
        lines.append("  limit surface: the ellipse (f_t/(mu f_n))^2 + (tau/tau_max)^2 = 1, "
                     "xi fixed at the k = 4 value")
    model = _core.ContactModel(params.to_core())
    f_n = np.array([1.0, 5.0])
    rho = model.rho(f_n)
    ft_max = model.ft_max(f_n)
    tau_max = model.tau_max(f_n)
    lines.append(f"  xi(k)    = {params.xi:.8f} [-]  torsional shape factor, "
                 "tau_max = mu xi rho f_n")
    lines.append(f"  {'f_n [N]':>10}{'rho [mm]':>12}{'f_t,max [N]':>14}{'tau_max [N mm]':>16}")
    for i, fn in enumerate(f_n):
        lines.append(f"  {fn:>10.3g}{rho[i] * 1e3:>12.4f}{ft_max[i]:>14.4f}"
                     f"{tau_max[i] * 1e3:>16.4f}")
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    from .. import PRESETS, ContactParams

    if args.list:
        width = max(len(n) for n in PRESETS)
        for name in PRESETS:
            p = ContactParams.preset(name)
            print(f"{name:<{width}}  mu = {p.mu:<5g} beta_a = {p.beta_a:<9.4g} N s/m^3   "
                  f"{PRESET_SOURCES[name]}")
        return 0
    if args.preset is not None:
        sys.stdout.write(preset_yaml(args.preset))
        return 0
    path: Path = args.check
    if not path.exists():
        raise CliError(f"argument --check: {path}: no such file")
    if path.is_dir():
        raise CliError(f"argument --check: {path} is a directory")
    from .._observer import read_observer_settings

    params = ContactParams.from_yaml(path)  # ValueError names the file and the field
    # the observer block is checked as `lugrip observe --params` builds it
    block = read_observer_settings(path)
    sys.stdout.write(describe(params, str(path)))
    if block:
        sys.stdout.write("observer settings (valid):\n")
        for key, value in block.items():
            sys.stdout.write(f"  {key:<16} = {value}\n")
    return 0
