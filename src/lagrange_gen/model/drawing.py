"""What a model draws: named points as expressions of q (2D or 3D) and segments between them.

    from lagrange_gen import Drawing
    model = Model(..., draw=Drawing(points={"cart": (x, 0), "bob": (x + l*sin(th), -l*cos(th))},
                                    segments=[("cart", "bob")]))

The drawing is never differentiated and never generated: an animation (viz/animate.py) reads it from
the model file and evaluates it with numpy (:func:`positions_function`), so declaring or changing
it leaves the generated module byte-identical.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..errors import ModelError
from .symbols import check_name, t

__all__ = ["Drawing", "check_drawing", "positions_function"]


class Drawing:
    """points: {name: (x, y) or (x, y, z)} expressions of the coordinates, parameters and t (every
    point the same dimension); segments: [(name, name), ...] lines drawn between points."""

    def __init__(self, points, segments=()):
        self.points = points
        self.segments = segments

    @property
    def dim(self) -> int:
        return len(next(iter(self.points.values())))

    @property
    def names(self) -> tuple:
        return tuple(self.points)

    def __repr__(self):
        return f"Drawing(points={list(self.points)}, segments={list(self.segments)})"


def check_drawing(model, draw, scalar):
    """``draw`` checked against ``model`` (its coordinates and parameters known), its expressions
    made sympy by ``scalar(expr, what)``; None stays None. ModelError, one line, otherwise."""
    if draw is None:
        return None
    where = f"model {model.name}: draw"
    if not isinstance(draw, Drawing):
        raise ModelError(f"{where} must be a lagrange_gen.Drawing(points=..., segments=...), "
                         f"got {type(draw).__name__}")
    if not isinstance(draw.points, dict) or not draw.points:
        raise ModelError(f"{where}: points must be a non-empty dict {{name: (x, y) or (x, y, z)}}")
    points = {name: _point(model, where, name, xyz, scalar) for name, xyz in draw.points.items()}
    dims = {len(xyz) for xyz in points.values()}
    if len(dims) > 1:
        dims = ", ".join(f"{n}: {len(p)}D" for n, p in points.items())
        raise ModelError(f"{where}: points mix 2D and 3D ({dims})")
    segments = []
    for seg in draw.segments:
        if not (isinstance(seg, (tuple, list)) and len(seg) == 2):
            raise ModelError(f"{where}: segment {seg!r} must be a pair (point name, point name)")
        for end in seg:
            if end not in points:
                raise ModelError(f"{where}: segment {tuple(seg)} names point {end!r}, which is not "
                                 f"one of the points ({', '.join(points)})")
        segments.append(tuple(seg))
    return Drawing(points, segments)


def _point(model, where, name, xyz, scalar):
    check_name(f"{where}: point", str(name))
    if isinstance(xyz, (str, bytes, sp.Basic)) or not hasattr(xyz, "__len__") or len(xyz) not in (2, 3):
        raise ModelError(f"{where}: point {name} must be 2 or 3 coordinates (x, y[, z]), got {xyz!r}")
    exprs = tuple(scalar(e, f"draw point {name}") for e in xyz)
    allowed = set(model.coords) | set(model.params) | {t}
    for e in exprs:
        unknown = sorted(str(s) for s in e.free_symbols - allowed)
        if unknown:
            raise ModelError(f"{where}: point {name} uses {', '.join(unknown)}, which is neither a "
                             "coordinate, a parameter of the model nor t (velocities are not drawn; "
                             "a parameter the dynamics do not use: write its value)")
    return exprs


def positions_function(model):
    """f(q (F, n), p (k,) in PARAMS order, t (F,)) -> (F, P, dim) positions of the model's drawn
    points (in Drawing order), evaluated with numpy. ModelError when the model draws nothing."""
    draw = model.draw
    if draw is None:
        raise ModelError(f"model {model.name} declares nothing to draw: give Model(..., draw="
                         "Drawing(points={name: (x, y)}, segments=[(a, b)]))")
    q = sp.symbols(f"_q0:{model.n_coords}")
    p = sp.symbols(f"_p0:{len(model.params)}")
    rename = dict(zip(model.coords, q)) | dict(zip(model.params, p))
    flat = [e.xreplace(rename) for xyz in draw.points.values() for e in xyz]
    fn = sp.lambdify([q, p, t], flat, modules="numpy")
    shape = (len(draw.points), draw.dim)

    def positions(qs, params, ts):
        qs = np.asarray(qs, dtype=float)
        ts = np.broadcast_to(np.asarray(ts, dtype=float), qs.shape[:1])
        # constant entries come back as scalars: broadcast each to the F frames
        values = fn(qs.T, np.asarray(params, dtype=float), ts)
        cols = [np.broadcast_to(np.asarray(v, dtype=float), ts.shape) for v in values]
        return np.stack(cols, axis=1).reshape(len(ts), *shape)
    return positions
