"""Hypothesis strategies drawing Lagrangian models over the grammar users write.

A drawn model (DrawnModel) is a set of plain sympy ingredients, T, V, generalized or point forces
Q(q, qd, t), a Rayleigh function, holonomic constraints, nonsmooth element strains and
unilateral contacts, plus the box its states are sampled from (sample_state). Everything is well defined on that box by
construction:

* angle coordinates u_i (sampled in [-2, 2]) enter only through functions defined on the whole
  real line: sin, cos, tanh, atan, exp, 2**x, Abs, x/(k + x**2), log(k + x**2), sqrt(k + x**2),
  (k + x**2)**(-3/2), atan2(x, k + y**2), and with kinks and jumps Max, Min, Piecewise,
  Heaviside, floor (their derivatives: Heaviside, DiracDelta, d floor/dx; states land on a
  kink with probability zero), ...
* radial coordinates r_i (sampled in [0.5, 2.5]) may also be divided by, raised to negative and
  fractional powers (r**-4, r**(-1/2), r**2.5) and fed to log and sqrt;
* parameters k_i have defaults in [0.5, 2] and enter as k, 1/k, k**2, 1/k**2, sqrt(k), k**-1.5.

T = 1/2 qd^T (B(q) B(q)^T + a I + diag(c(q))) qd with B entries from the grammar and c(q) >= 0
(e.g. m*r**2 for a Kepler-like phi.d**2 term, m/r**2, k/(k + u**2)) is positive definite for
every q. derive() checks H at q in [-pi, pi], beyond the sampled box, so T uses only functions
that are real for every nonzero q (no sqrt(r) or log(r) in T).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from hypothesis import strategies as st

from lagrange_gen import Contact, DryFriction, Model, PointForce, SaintVenant, coordinates, parameters, t

RADIAL_BOX, ANGLE_BOX, SPEED_BOX, TIME_BOX = (0.5, 2.5), (-2.0, 2.0), (-1.5, 1.5), (0.0, 3.0)
N_PARAMS = 5
_names = itertools.count()

# f(x, k) of one coordinate, real for every real x (k > 0 a parameter).
TOTAL = [
    lambda x, k: x, lambda x, k: x**2, lambda x, k: x**3, lambda x, k: sp.sin(x),
    lambda x, k: sp.cos(x)**2, lambda x, k: sp.atan(x), lambda x, k: sp.tanh(x),
    lambda x, k: x / (k + x**2), lambda x, k: 1 / (k + x**2)**2, lambda x, k: sp.sqrt(k + x**2),
    lambda x, k: (k + x**2)**sp.Rational(-3, 2), lambda x, k: sp.log(k + x**2),
    lambda x, k: sp.exp(x / 2), lambda x, k: sp.exp(-x**2 / k), lambda x, k: 2**x,
    lambda x, k: sp.Abs(x), lambda x, k: x * sp.Abs(x), lambda x, k: sp.sin(x) / k**2,
    # kinks and jumps: their derivatives are Heaviside, DiracDelta, Piecewise, d floor/dx
    lambda x, k: sp.Max(x, 0)**2, lambda x, k: sp.Min(x, k) * x,
    lambda x, k: sp.Piecewise((x**2, x > 0), (-k * x, True)), lambda x, k: sp.Heaviside(x - k / 2) * x,
    lambda x, k: sp.floor(x) + x / k,
]
# f(r, k) real for every real r != 0 (allowed in T).
NONZERO = [lambda r, k: 1 / r, lambda r, k: r**-2, lambda r, k: k / r**3, lambda r, k: 1 / r**4,
           lambda r, k: sp.cos(r) / r**2]
# f(r, k) real for r > 0 only (never in T).
POSITIVE_ONLY = [lambda r, k: sp.sqrt(r), lambda r, k: r**sp.Rational(3, 2),
                 lambda r, k: r**sp.Rational(-1, 2), lambda r, k: sp.log(r), lambda r, k: r**2.5,
                 lambda r, k: sp.Abs(r) / r**3]
# f(x, y, k) of two coordinates, real everywhere.
PAIR = [lambda x, y, k: sp.atan2(x, k + y**2), lambda x, y, k: x / (k + y**2),
        lambda x, y, k: sp.sin(x - y), lambda x, y, k: sp.cos(x) * y, lambda x, y, k: x * y]
# c(x, k) >= 0 for every real x: diagonal inertia and damping coefficients.
NONNEGATIVE = [lambda x, k: x**2, lambda x, k: 1 / (k + x**2), lambda x, k: sp.exp(x),
               lambda x, k: sp.cosh(x), lambda x, k: sp.sin(x)**2, lambda x, k: (k + x**2)**sp.Rational(-1, 2)]
NONNEGATIVE_NONZERO = [lambda r, k: r**-2, lambda r, k: r**2 / (k + r**4)]
PARAM = [lambda k: k, lambda k: 1 / k, lambda k: k**2, lambda k: 1 / k**2, lambda k: sp.sqrt(k),
         lambda k: k**sp.Rational(-3, 2)]
COEFFS = [sp.Integer(1), sp.Integer(-1), sp.Integer(2), sp.Rational(1, 2), sp.Rational(-3, 2),
          sp.Rational(1, 3)]
SPEED = [lambda v, k: v, lambda v, k: -v * sp.Abs(v), lambda v, k: v / (k + v**2), lambda v, k: v**2,
         lambda v, k: sp.Integer(1)]
TIME = [lambda k: sp.Integer(1), lambda k: sp.sin(k * t), lambda k: sp.cos(t), lambda k: sp.exp(-t / k),
        lambda k: t, lambda k: 1 / (k + t**2), lambda k: 1 + sp.Heaviside(t - k) / 2]


@dataclass
class DrawnModel:
    """The ingredients of one drawn model; ``build`` makes the lagrange_gen Model of them.

    radial[i]: coordinate i is sampled in RADIAL_BOX (else ANGLE_BOX); params: the declared
    Parameters (each carries its default); forces: n expressions or None; point_forces: [(point, force)] tuples;
    elements: [(kind, strain, coefficient, threshold or None, yield force or None)];
    contacts: [(gap, restitution, friction, slip or None)]; nonholonomic: velocity constraints
    A(q) . qd + b(q, t) (expressions).
    """

    name: str
    coords: list
    radial: list
    params: list
    T: sp.Expr
    V: sp.Expr = sp.S.Zero
    forces: list | None = None
    point_forces: list = field(default_factory=list)
    dissipation: sp.Expr = sp.S.Zero
    constraints: list = field(default_factory=list)
    elements: list = field(default_factory=list)
    events: list = field(default_factory=list)
    contacts: list = field(default_factory=list)
    nonholonomic: list = field(default_factory=list)

    @property
    def defaults(self):
        """{parameter name: default}"""
        return {p.name: p.default for p in self.params}

    def build(self) -> Model:
        """A fresh Model of these ingredients."""
        forces = [PointForce(p, f) for p, f in self.point_forces] if self.point_forces else self.forces
        elements = []
        for kind, strain, coef, threshold, yield_force in self.elements:
            if kind == "saint_venant":
                elements.append(SaintVenant(strain, coef, threshold=threshold, yield_force=yield_force))
            else:
                elements.append(DryFriction(rate_of=strain, bound=coef))
        return Model(self.name, coords=self.coords, T=self.T, V=self.V, forces=forces,
                     dissipation=self.dissipation, constraints=self.constraints, elements=elements,
                     events={f"g{i}": g for i, g in enumerate(self.events)},
                     contacts=[Contact(gap, restitution, friction, slip)
                               for gap, restitution, friction, slip in self.contacts],
                     nonholonomic=self.nonholonomic)


def sample_state(drawn, rng):
    """(q (n,), qd (n,), t) uniformly in the model's box."""
    q = np.array([rng.uniform(*(RADIAL_BOX if r else ANGLE_BOX)) for r in drawn.radial])
    return q, rng.uniform(*SPEED_BOX, len(q)), float(rng.uniform(*TIME_BOX))


class _Grammar:
    """Draws expressions over one model's coordinates and parameters (``draw`` from st.composite)."""

    def __init__(self, draw, coords, radial, params):
        self.draw, self.coords, self.radial, self.params = draw, coords, radial, params

    def pick(self, options):
        return self.draw(st.sampled_from(options))

    def param(self):
        return self.pick(PARAM)(self.pick(self.params))

    def factor(self, in_T=False):
        """f(q) of one or two coordinates: the building block of every expression."""
        i = self.draw(st.integers(0, len(self.coords) - 1))
        x, k = self.coords[i], self.pick(self.params)
        options = TOTAL + (NONZERO if self.radial[i] else [])
        if self.radial[i] and not in_T:
            options = options + POSITIVE_ONLY
        if len(self.coords) > 1 and self.draw(st.integers(0, 4)) == 0:
            y = self.coords[(i + 1 + self.draw(st.integers(0, len(self.coords) - 2))) % len(self.coords)]
            return self.pick(PAIR)(x, y, k)
        return self.pick(options)(x, k)

    def term(self, in_T=False):
        """coefficient * parameter factor * one or two coordinate factors."""
        expr = self.pick(COEFFS) * self.param() * self.factor(in_T)
        if self.draw(st.booleans()):
            expr *= self.factor(in_T)
        return expr

    def sum(self, low, high, in_T=False):
        return sp.Add(*[self.term(in_T) for _ in range(self.draw(st.integers(low, high)))])

    def nonnegative(self):
        """c(q) >= 0 for every real q: a diagonal inertia or damping coefficient."""
        i = self.draw(st.integers(0, len(self.coords) - 1))
        options = NONNEGATIVE + (NONNEGATIVE_NONZERO if self.radial[i] else [])
        return self.param() * self.pick(options)(self.coords[i], self.pick(self.params))

    def speed_time(self, v):
        return self.pick(SPEED)(v, self.pick(self.params)) * self.pick(TIME)(self.pick(self.params))


def _setup(draw, n_min, n_max):
    n = draw(st.integers(n_min, n_max))
    radial = [draw(st.booleans()) for _ in range(n)]
    tag = next(_names)
    coords = coordinates([f"{'r' if r else 'u'}{i}" for i, r in enumerate(radial)])
    coords = coords if isinstance(coords, list) else [coords]
    params = parameters(" ".join(f"k{j}" for j in range(N_PARAMS)),
                        defaults=[draw(st.integers(5, 20)) / 10 for _ in range(N_PARAMS)])
    return tag, coords, radial, params, _Grammar(draw, coords, radial, params)


def _kinetic(g, constant_mass):
    """T = 1/2 qd^T (B B^T + a I + diag(c)) qd; B and c of parameters only when constant_mass."""
    n = len(g.coords)
    qd = sp.Matrix([c.d for c in g.coords])

    def entry():
        if g.draw(st.integers(0, 2)) == 0:
            return sp.S.Zero
        return g.pick(COEFFS) * g.param() if constant_mass else g.term(in_T=True)
    B = sp.Matrix(n, n, lambda i, j: entry())
    if constant_mass:
        diag = [g.param() for _ in range(n)]
    else:      # one q-dependent diagonal term at least, so that H(q) is never constant by chance
        diag = [g.nonnegative() if i == 0 or g.draw(st.booleans()) else 0 for i in range(n)]
    A = B * B.T + g.param() * sp.eye(n) + sp.diag(*diag)
    return (qd.T * A * qd)[0, 0] / 2


def _forces(g):
    """n generalized forces Q(q, qd, t), or point forces converted by virtual work."""
    n = len(g.coords)
    speeds = [c.d for c in g.coords]
    if g.draw(st.integers(0, 3)) == 0:
        dim = g.draw(st.integers(2, 3))
        point = tuple(g.factor() for _ in range(dim))
        force = tuple(g.param() * g.factor() * g.speed_time(g.pick(speeds)) for _ in range(dim))
        return None, [(point, force)]
    forces = []
    for _ in range(n):
        terms = [g.pick(COEFFS) * g.param() * g.factor() * g.speed_time(g.pick(speeds))
                 for _ in range(g.draw(st.integers(0, 2)))]
        forces.append(sp.Add(*terms))
    return forces, []


def _rayleigh(g):
    """D = 1/2 sum c_i(q) qd_i**2 (+ a cross term): quadratic in qd, q-dependent coefficients."""
    speeds = [c.d for c in g.coords]
    D = sp.Add(*[g.nonnegative() * v**2 / 2 for v in speeds if g.draw(st.booleans())])
    if len(speeds) > 1 and g.draw(st.booleans()):
        D += g.term() * speeds[0] * speeds[-1] / 4
    return D


def _events(g):
    """1-2 event functions g(q, qd, t) from the grammar: a term minus a constant, possibly times
    a speed or a time factor (every drawn model has some: kepler() and the event tests cover
    models without)."""
    out = []
    speeds = [c.d for c in g.coords]
    for _ in range(g.draw(st.integers(1, 2))):
        e = g.term() - g.pick(COEFFS)
        if g.draw(st.booleans()):
            e *= g.speed_time(g.pick(speeds))
        out.append(e)
    return out


def _elements(g):
    """One or two SaintVenant / DryFriction elements on strains s(q) from the grammar."""
    out = []
    for _ in range(g.draw(st.integers(1, 2))):
        a, b = g.pick(g.coords), g.pick(g.coords)
        strain = a - g.pick(COEFFS) * b if a != b else a
        if g.draw(st.booleans()):
            strain += g.term()
        kind = g.pick(["saint_venant", "saint_venant", "dry_friction"])
        by_yield = kind == "saint_venant" and g.draw(st.booleans())
        threshold = None if kind == "dry_friction" or by_yield else g.param()
        out.append((kind, strain, g.param(), threshold, g.param() if by_yield else None))
    return out


def _contacts(g):
    """One or two unilateral contacts: a gap g(q) from the grammar minus a constant, plus, for a
    moving surface, a constant times a function of t; restitution k / (k + k') in (0, 1) or a
    number in [0, 1]; and either no friction or friction k with one slip velocity (2D) or a pair
    (3D), each sum_i f_i(q) qd_i (f_i from the grammar, some zero) plus, for a moving surface,
    a term times a function of t."""
    out = []
    for _ in range(g.draw(st.integers(1, 2))):
        gap = g.term() - g.pick(COEFFS)
        if g.draw(st.booleans()):
            gap += g.pick(COEFFS) * g.pick(TIME)(g.pick(g.params))
        if g.draw(st.booleans()):
            a, b = g.pick(g.params), g.pick(g.params)
            restitution = a / (a + b)          # in (0, 1) for positive a, b (the same a twice)
        else:
            restitution = g.pick([sp.Integer(0), sp.Rational(1, 2), sp.Integer(1)])
        friction, slip = sp.S.Zero, None
        tangents = g.draw(st.integers(0, 2))
        if tangents:
            friction = g.param()
            slips = tuple(_slip_velocity(g) for _ in range(tangents))
            slip = slips[0] if tangents == 1 else slips
        out.append((gap, restitution, friction, slip))
    return out


def _slip_velocity(g):
    """sum_i f_i(q) qd_i (some f_i zero, one at least), plus a term times a function of t or
    not."""
    speeds = [c.d for c in g.coords]
    slip = sp.Add(*[g.factor() * v for v in speeds if g.draw(st.booleans())])
    slip = slip if slip != 0 else g.pick(COEFFS) * speeds[0]
    if g.draw(st.booleans()):
        slip += g.term() * g.pick(TIME)(g.pick(g.params))
    return slip


def _nonholonomic(g):
    """One or two velocity constraints sum_i f_i(q) qd_i + b(q, t): f_i and b from the grammar
    (some f_i zero, one velocity at least), b zero, a term, or a term times a function of t."""
    out = []
    speeds = [c.d for c in g.coords]
    for _ in range(g.draw(st.integers(1, 2))):
        row = sp.Add(*[g.factor() * v for v in speeds if g.draw(st.booleans())])
        row = row if row != 0 else g.pick(COEFFS) * g.pick(speeds)
        kind = g.draw(st.integers(0, 2))
        b = sp.S.Zero if kind == 0 else g.term() * (g.pick(TIME)(g.pick(g.params)) if kind == 2 else 1)
        out.append(row + b)
    return out


@st.composite
def models(draw, constant_mass=False, constrained=False, elements=False, contacts=False,
           nonholonomic=False):
    """A DrawnModel of 1-3 coordinates (2-3 when constrained or nonholonomic): T, V (possibly
    time-dependent), forces, Rayleigh dissipation, and constraints / elements / contacts /
    velocity constraints when asked."""
    tag, coords, radial, params, g = _setup(draw, 2 if constrained or nonholonomic else 1, 3)
    V = g.sum(1, 3)
    if draw(st.integers(0, 3)) == 0:
        V += g.term() * g.pick(TIME)(g.pick(g.params))
    forces, point_forces = _forces(g)
    events = _events(g)
    constraints = []
    if constrained:
        constraints = [g.sum(1, 2) - g.pick(COEFFS) for _ in range(draw(st.integers(1, len(coords) - 1)))]
    return DrawnModel(
        name=f"harness_{tag}", coords=coords, radial=radial, params=params,
        T=_kinetic(g, constant_mass), V=V, forces=forces, point_forces=point_forces,
        dissipation=_rayleigh(g), constraints=constraints, elements=_elements(g) if elements else [],
        events=events, contacts=_contacts(g) if contacts else [],
        nonholonomic=_nonholonomic(g) if nonholonomic else [])


def kepler():
    """The model of issue 10: T = (r.d**2 + r**2 phi.d**2)/2, V = -1/r (radial r, angle phi)."""
    tag = next(_names)
    r, phi = coordinates("r0 u1")
    return DrawnModel(name=f"kepler_{tag}", coords=[r, phi], radial=[True, False], params=[],
                      T=(r.d**2 + r**2 * phi.d**2) / 2, V=-1 / r)
