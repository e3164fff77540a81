"""The kinematic tree of sympy.physics.mechanics frames and points, walked once and kept.

Each frame's orientation N.dcm(F), its angular velocity (in its own components) and each
point's position and velocity (in N) are computed from its parent's, one product of small
matrices per joint, and every entry is an ``Intermediate`` (model/intermediates.py): the
energies built from them (model/bodies.py) stay short sums over shared subexpressions.

The frame tree is read from sympy's orientation records (``ReferenceFrame._dcm_dict``), the
point tree from ``Point._pos_dict`` and ``Point._vel_dict``: sympy offers no public way to list
a frame's or a point's neighbours. That reading lives in ``_records`` alone; when the records
are not there (another sympy) it raises RecordsMissing and the energies fall back to sympy's
own ``kinetic_energy`` and ``pos_from`` with one warning line: correct, but expanded.
"""

from __future__ import annotations

from collections import deque

import sympy as sp

from ..errors import ModelError
from .intermediates import new_intermediate
from .symbols import Coordinate, t

__all__ = ["KinematicTree", "RecordsMissing"]


class KinematicTree:
    """The kinematics of one inertial frame N, built on demand and kept: R(F) = N.dcm(F) (3, 3),
    w(F) the angular velocity of F in N in F's components (3, 1), r(P), v(P) the position (from
    the fixed origin) and velocity of P in N components (3, 1); entries are Intermediates."""

    def __init__(self, frame):
        self.N = frame
        self._R = {frame: sp.eye(3)}
        self._w = {frame: sp.zeros(3, 1)}
        self._r, self._v = {}, {}
        self._parent = {frame: None}
        self._convert = {}
        self._walk_frames()

    # -- symbols --------------------------------------------------------------------------
    def _coords(self, expr):
        """A mechanics expression with dynamicsymbols q(t) as Coordinates, q(t)' as their
        velocities and mechanics' time symbol as t (what Model does to the rest of T)."""
        expr = sp.sympify(expr)
        derivs, funcs = {}, {}
        for d in expr.atoms(sp.Derivative):
            f = d.expr
            if (isinstance(f, sp.core.function.AppliedUndef) and len(f.args) == 1
                    and d.variable_count == ((f.args[0], 1),)):
                derivs[d] = Coordinate(str(f.func)).d
        for f in expr.atoms(sp.core.function.AppliedUndef):
            if len(f.args) == 1 and isinstance(f.args[0], sp.Symbol):
                funcs[f] = Coordinate(str(f.func))
                funcs[f.args[0]] = t
        if derivs:
            expr = expr.xreplace(derivs)
        return expr.xreplace(funcs) if funcs else expr

    def _name(self, expr):
        """An Intermediate for ``expr`` (numbers and symbols stay as they are), named k<serial>
        in the order of creation in this process (what _in_order sorts by)."""
        expr = sp.sympify(expr)
        if expr.is_Number or expr.is_Symbol:
            return expr
        return new_intermediate(expr)

    def _named(self, matrix):
        return matrix.applyfunc(self._name)

    # -- frames ---------------------------------------------------------------------------
    def _walk_frames(self):
        """R and w of every frame connected to N, each from its parent in a breadth-first walk
        over the orientation records."""
        queue = deque([self.N])
        while queue:
            parent = queue.popleft()
            for child in _neighbours(parent, "_dcm_dict"):
                if child in self._R:
                    continue
                local = self._coords(child.dcm(parent))        # [v]_child = local [v]_parent
                self._parent[child] = parent
                self._R[child] = self._named(self._R[parent] * local.T)
                relative = self.components(child.ang_vel_in(parent), child, adjacent=parent)
                self._w[child] = self._named(local * self._w[parent] + relative)
                queue.append(child)

    def parent_frame(self, frame):
        """The frame ``frame`` was reached from in the walk (None for N and unreached frames)."""
        return self._parent.get(frame)

    def coords(self, expr):
        """``expr`` (a sympy expression or Matrix of mechanics) in Coordinates (see _coords)."""
        if isinstance(expr, sp.MatrixBase):
            return expr.applyfunc(self._coords)
        return self._coords(expr)

    def point_path(self, point):
        """[points] from the nearest fixed point out to ``point`` (as position() walks it)."""
        def fixed(p):
            given = _records(p, "_vel_dict").get(self.N)
            return given is not None and given == 0
        root, path = _nearest(point, fixed, self.N, what="a fixed point (O.set_vel(N, 0))")
        return [root] + [child for child, _ in path]

    def R(self, frame):
        if frame not in self._R:
            raise ModelError(f"frame {frame} is not connected to the inertial frame {self.N} by "
                             "orientations (orient_axis, orientnew, ...)")
        return self._R[frame]

    def w(self, frame):
        self.R(frame)
        return self._w[frame]

    def components(self, vector, frame, adjacent=None):
        """Components (3, 1) of a mechanics Vector in ``frame`` (converted to Coordinates),
        through the kept R when its terms are in other frames."""
        out = sp.zeros(3, 1)
        for comps, where in vector.args:
            comps = self._coords(comps)
            if where == frame:
                out += comps
            elif where == adjacent:
                out += self._coords(frame.dcm(where)) * comps
            else:
                out += self.R(frame).T * (self.R(where) * comps)
        return out

    def dyadic_components(self, dyadic, frame):
        """Components (3, 3) of a mechanics Dyadic in ``frame`` (converted to Coordinates): the
        sum over its outer products c a b of c A B^T, A and B the components of a and b
        (components() above). sympy's Dyadic.to_matrix dots every pair of unit vectors through
        the frame records, a product of 3x1 matrices per pair, which made the central inertias
        the largest part of building a 30-body tree."""
        out = sp.zeros(3, 3)
        for coefficient, a, b in dyadic.args:
            out += self._coords(coefficient) * self.components(a, frame) * self.components(b, frame).T
        return out

    def in_N(self, vector):
        """Components (3, 1) in N of a mechanics Vector, each term through R of its frame."""
        out = sp.zeros(3, 1)
        for comps, where in vector.args:
            out += self.R(where) * self._coords(comps)
        return out

    def rate_in_N(self, vector):
        """Components (3, 1) in N of d/dt_N of a mechanics Vector (the velocity of a position
        vector): for each term c in frame F, R(F) (dc/dt + w(F) x c)."""
        out = sp.zeros(3, 1)
        for comps, where in vector.args:
            c = self._coords(comps)
            out += self.R(where) * (_time_derivative(c) + self.w(where).cross(c))
        return out

    # -- points ---------------------------------------------------------------------------
    def velocity(self, point):
        """v (3, 1) in N of ``point``: from the nearest point whose velocity in N is given (a
        fixed origin, or a point set with set_vel / v2pt_theory), as sympy's Point.vel finds
        it, adding d/dt of each position vector on the way out."""
        if point not in self._v:
            root, path = _nearest(point, lambda p: self.N in _records(p, "_vel_dict"), self.N)
            if root not in self._v:
                self._v[root] = self._named(self.in_N(root.vel(self.N)))
            for child, parent in path:
                if child not in self._v:
                    self._v[child] = self._named(self._v[parent] + self.rate_in_N(child.pos_from(parent)))
        return self._v[point]

    def position(self, point):
        """r (3, 1) in N of ``point`` from the nearest fixed point (velocity given as zero)."""
        if point not in self._r:
            def fixed(p):
                given = _records(p, "_vel_dict").get(self.N)
                return given is not None and given == 0
            root, path = _nearest(point, fixed, self.N, what="a fixed point (O.set_vel(N, 0))")
            self._r.setdefault(root, sp.zeros(3, 1))
            for child, parent in path:
                if child not in self._r:
                    self._r[child] = self._named(self._r[parent] + self.in_N(child.pos_from(parent)))
        return self._r[point]


def _time_derivative(c):
    """d/dt of components (3, 1) in Coordinates: sum over coordinates of dc/dq q.d."""
    coords = sorted({s for s in c.free_symbols if isinstance(s, Coordinate)}, key=str)
    out = sp.zeros(*c.shape)
    for q in coords:
        out += c.diff(q) * q.d
    if t in c.free_symbols:
        out += c.diff(t)
    return out


def _records(obj, record):
    """sympy's table ``record`` of a frame or point ({other: DCM or Vector}); RecordsMissing when this
    sympy keeps it elsewhere (the one place that reads sympy's internals)."""
    table = getattr(obj, record, None)
    if not isinstance(table, dict):
        raise RecordsMissing(record)
    return table


def _neighbours(obj, record):
    """The frames (or points) ``obj`` is directly related to in sympy's record ``record``."""
    return sorted(_records(obj, record), key=str)


class RecordsMissing(Exception):
    """sympy's orientation or position records are not where this sympy keeps them."""


def _nearest(point, wanted, frame, what=None):
    """(root, path): the nearest point (breadth first over positions) for which ``wanted`` is
    true, and path [(child, parent)] from root out to ``point`` ([] when ``point`` is the root).
    ModelError naming ``what`` when there is none."""
    parents, queue = {point: None}, deque([point])
    while queue:
        here = queue.popleft()
        if wanted(here):
            path, node = [], here
            while parents[node] is not None:
                path.append((parents[node], node))
                node = parents[node]
            return here, path
        for other in _neighbours(here, "_pos_dict"):
            if other not in parents:
                parents[other] = here
                queue.append(other)
    what = what or f"a velocity given in {frame}"
    raise ModelError(f"point {point}: no point located from it has {what}; set one with "
                     f"O.set_vel({frame}, 0)")
