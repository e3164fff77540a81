"""`lagrange-gen identify DATA.csv --kind prandtl|damping`: print identified parameters.

CSV input, comma-separated, one sample per row, an optional header row naming the columns:

- prandtl: x, F (already F - m x''), optionally v (velocity) or t (time), needed with --damping;
  without a header the columns are x, F[, v];
- damping: t, x (uniform t); without a header the columns are t, x.

Header names are matched case-insensitively; aliases: F_minus_mxdd / y / f for F, xdot /
velocity for v, time for t.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from ..errors import IdentificationError

_ALIASES = {"x": ("x",), "F": ("f", "f_minus_mxdd", "y"), "v": ("v", "xdot", "velocity"),
            "t": ("t", "time")}


def add_parser(subparsers):
    p = subparsers.add_parser(
        "identify", help="identify Prandtl-model or damping parameters from a CSV record",
        description="Identify k0, k_i, eta_i of the generalized Prandtl model from a loading "
                    "half-cycle (or full cycles) in the (x, F - m x'') plane, or viscous damping "
                    "from a free decay by the wavelet logarithmic decrement.")
    p.add_argument("data", metavar="DATA.csv",
                   help="prandtl: columns x,F[,v] (F = F - m x''); damping: columns t,x")
    p.add_argument("--kind", choices=["prandtl", "damping"], required=True)
    p.add_argument("--elements", type=int, metavar="N",
                   help="prandtl: number of Saint-Venant elements (default: chosen by BIC)")
    p.add_argument("--damping", type=float, default=0.0, metavar="C",
                   help="prandtl: known viscous coefficient, subtracted as C x' (needs v or t)")
    p.add_argument("--noise", type=float, metavar="S",
                   help="prandtl: noise standard deviation of F (default: estimated)")
    p.add_argument("--method", choices=["pwl", "wavelet"], default="pwl",
                   help="prandtl: breakpoint search (default: pwl)")
    p.add_argument("--branches", choices=["all", "one"], default="all",
                   help="prandtl: pool every branch that starts from a full excursion (default) "
                        "or use the loading branch only")
    p.add_argument("--period", type=float, metavar="T",
                   help="damping: damped period (default: from the spectrum)")
    p.add_argument("--scale", type=float, metavar="A",
                   help="damping: analysing scale in samples (default: matched to the period)")
    p.add_argument("--mass", type=float, default=1.0, metavar="M",
                   help="damping: mass m, for c = 2 m sigma (default: 1)")
    return p


def read_columns(path):
    """(names or None, data (rows, columns)) of a numeric CSV file with an optional header."""
    path = Path(path)
    if not path.is_file():
        raise IdentificationError(f"{path}: no such file")
    rows = [r for r in csv.reader(_text_lines(path)) if r and any(cell.strip() for cell in r)]
    if not rows:
        raise IdentificationError(f"{path}: empty file, no samples")
    names = None
    try:
        [float(cell) for cell in rows[0]]
    except ValueError:
        names, rows = [cell.strip().lower() for cell in rows[0]], rows[1:]
    width = len(names) if names else len(rows[0]) if rows else 0
    data = []
    for number, row in enumerate(rows, 2 if names else 1):
        try:
            values = [float(cell) for cell in row]
        except ValueError:
            raise IdentificationError(
                f"{path}: line {number}: non-numeric value in {row}") from None
        if len(values) != width:
            raise IdentificationError(f"{path}: line {number}: {len(values)} columns, "
                                      f"expected {width}")
        data.append(values)
    return names, np.array(data, dtype=float).reshape(len(data), width)


def _text_lines(path):
    """The lines of a UTF-8 text file (a byte-order mark is dropped); IdentificationError naming
    the file and line when it is binary or in another encoding."""
    data = path.read_bytes()
    if b"\x00" in data:
        raise IdentificationError(f"{path}: not a UTF-8 text file (binary data); expected a CSV file")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise IdentificationError(f"{path}: line {line}: not a UTF-8 text file (byte "
                                  f"0x{data[exc.start]:02x}); save the CSV as UTF-8") from None
    return text.splitlines(keepends=True)


def _columns(path, names, data, wanted, optional=()):
    """Dict name -> (N,) column; by header name when there is a header, else by position."""
    found = {}
    for position, key in enumerate(wanted + optional):
        if names is not None:
            hits = [i for i, n in enumerate(names) if n in _ALIASES[key]]
            index = hits[0] if hits else None
        else:
            index = position if position < data.shape[1] else None
        if index is not None:
            found[key] = data[:, index]
        elif key in wanted:
            have = ", ".join(names) if names else f"{data.shape[1]} unnamed column(s)"
            raise IdentificationError(f"{path}: no column {key!r} (have {have}); "
                                      f"expected columns {','.join(wanted)}")
    return found


def _check_options(args):
    """IdentificationError naming the first option whose value cannot be meant."""
    if args.noise is not None and not (math.isfinite(args.noise) and args.noise >= 0):
        raise IdentificationError(f"--noise {args.noise:g}: must be a finite number >= 0 "
                                  "(the standard deviation of the noise on F)")


def run(args) -> int:
    from . import identify_damping, identify_prandtl
    _check_options(args)
    names, data = read_columns(args.data)
    if args.kind == "prandtl":
        cols = _columns(args.data, names, data, ("x", "F"), ("v", "t") if names else ("v",))
        fit = identify_prandtl(cols["x"], cols["F"], args.elements, args.noise,
                               damping=args.damping, velocity=cols.get("v"), t=cols.get("t"),
                               method=args.method, branches=args.branches)
    else:
        cols = _columns(args.data, names, data, ("t", "x"))
        fit = identify_damping(cols["t"], cols["x"], period=args.period, scale=args.scale,
                               m=args.mass)
    print(fit.summary())
    return 0
