"""What a stepper module declares about itself (its ``SPEC``), and the typed settings records.

Every ``steppers/<method>.py`` ends with ``SPEC = Spec(...)``; the registry (registry.METHODS, one
line per method) collects them, and everything outside steppers/ (simulate, the CLI, consistent
initialization, the generator, the analysis and the bench) reads the spec instead of testing
method names. A spec says:

* name, order, family (FAMILIES), a one-line summary, symplectic / symmetric / implicit, and the
  linear stability range ``stable`` in tau = h omega (quoted by the energy warning and README);
* which models it applies to: ``constraints`` (True: only models with holonomic constraints,
  False: only models without), ``elements`` (treats nonsmooth elements), ``stands_in_for`` (the
  methods it runs in place of on a model with elements: nonsmooth_euler for implicit_euler),
  ``contacts`` (True: only models with unilateral contacts, False: only models without),
  ``nonholonomic`` (True: only models with velocity constraints, False: only models without);
* ``settings``: a NamedTuple class, its fields typed and defaulted; simulate builds one from the
  user's keywords (``make_settings``, validated by the field types and ``limits``) and the jitted
  step reads it by name (``settings.newton_tol``), so numba sees ints as ints and bools as bools;
* ``kernels``: the generated kernels the method calls (a test checks this declaration against
  the code, codegen.needs);
* ``saved``: the named fields the method saves per output row besides (t, q, v, energy, Newton
  iterations and residual), in the order of its ``extra`` buffer, each with a width given as a
  count name (``"m"`` constraints, ``"m1"`` 1 with constraints and 0 without, ``"ne"``
  elements, ``"c"`` contacts, ``"r"`` nonholonomic constraints, ``"r1"`` 1 with nonholonomic
  constraints and 0 without, ``"n"`` coordinates) or an int;
* ``adaptive``: the method chooses its own steps (error control, dense output); its glue has the
  adaptive signature (codegen/glue.py).

The jitted side of the contract is in run_loop.py (fixed step; the rules: steppers/methods)
and adaptive.py (adaptive).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from typing import NamedTuple

from ...errors import SimulationError

FAMILIES = ("explicit", "implicit", "partitioned", "constrained", "nonsmooth")


class ExplicitSettings(NamedTuple):
    """Settings of the explicit fixed-step methods."""

    blowup_bound: float = 1e150     # BlowUp when max(|q|, |v|) exceeds it


class NewtonSettings(NamedTuple):
    """Settings of the implicit methods (one Newton solve or more per step, newton.py)."""

    newton_tol: float = 1e-12       # stopping rule, relative to max(1, |unknown|)
    max_iter: int = 50              # iteration cap per solve
    blowup_bound: float = 1e150


class PartitionedSettings(NamedTuple):
    """Settings of the partitioned methods, which run explicitly when the model allows it."""

    newton_tol: float = 1e-12
    max_iter: int = 50
    blowup_bound: float = 1e150
    newton_always: bool = False     # use the Newton path even for constant H, velocity-free forces


#: One line per settings field for the CLI's help (cli_simulate builds an option per field).
SETTING_HELP = {
    "newton_tol": "Newton tolerance, relative to max(1, |unknown|)",
    "max_iter": "Newton iteration cap per solve",
    "blowup_bound": "BlowUp when max(|q|, |v|) exceeds this",
    "newton_always": "use the Newton path even for constant H and velocity-free forces",
    "compliance": "constraint compliance epsilon >= 0 (0: rigid; 1/k: a spring of stiffness k)",
    "relaxation": "constraint relaxation d > 0, in steps",
    "baumgarte": "Baumgarte stabilization gains ALPHA BETA",
    "rtol": "relative tolerance of the local error",
    "atol": "absolute tolerance of the local error",
    "h_max": "largest step",
    "max_steps": "cap on the steps (accepted and rejected) of one call",
    "theta": "theta-method weight in (0, 1] (1/2: energy-neutral free flight, 1: damping)",
    "contact_tol": "contact problem tolerance: largest impulse change of a Gauss-Seidel sweep "
                   "relative to the largest impulse",
    "max_sweeps": "cap on the projected Gauss-Seidel sweeps of one step's contact problem",
    "zeno_interval": "an impact of a contact less than this after its previous one is plastic "
                     "(the contact then rests)",
    "gap_tol": "a contact touches when its gap is at most this",
    "rest_velocity": "a touching contact whose normal (slip) velocity is at most this is at "
                     "rest (sticks)",
}

#: Validation of the common fields: (lower bound, bound included, inf allowed).
LIMITS = {"newton_tol": (0.0, False, False), "max_iter": (1, True, False),
          "blowup_bound": (0.0, False, True)}


@dataclass(frozen=True)
class Spec:
    """The declaration of one stepper method (see the module docstring)."""

    name: str
    order: int
    family: str
    summary: str
    settings: type
    kernels: tuple
    symplectic: bool = False
    symmetric: bool = False
    implicit: bool = False
    stable: str = ""
    constraints: bool = False
    elements: bool = False
    stands_in_for: tuple = ()
    contacts: bool = False
    nonholonomic: bool = False
    #: A nonholonomic or contact method that also treats holonomic constraints beside the
    #: velocity constraints or the contacts.
    holonomic_too: bool = False
    #: A contact method that also treats nonholonomic (velocity) constraints beside the
    #: contacts, as rigid equality rows of its step (a bicycle that falls onto the floor).
    nonholonomic_too: bool = False
    saved: tuple = ()
    limits: dict = field(default_factory=dict)
    adaptive: bool = False
    #: Linear stability on x'' = -omega^2 x, tau = h omega (fixed-step unconstrained methods):
    #: the end of the first stable interval (0: unstable for every tau, inf: A-stable), the
    #: closed-form spectral radius rho(tau) and phase per step of the step matrix (callables or
    #: None); the analysis checks the measured step matrix against them.
    stable_tau: float = None
    rho: object = None
    phase: object = None
    #: Constrained methods: "none" (|Phi| and |J v| held to the Newton tolerance), "bounded"
    #: (regularized: a compliance-sized violation) or "grows" (no projection: drift).
    constraint_drift: str = ""

    def __post_init__(self):
        if self.family not in FAMILIES:
            raise ValueError(f"{self.name}: family {self.family!r} is not one of {FAMILIES}")

    def saved_layout(self, n: int, m: int, ne: int, nc: int = 0, nr: int = 0) -> tuple:
        """((name, start, width), ...) of the saved fields in the extra buffer (nc contacts,
        nr nonholonomic constraints)."""
        counts = {"n": n, "m": m, "m1": min(m, 1), "ne": ne, "c": nc, "r": nr, "r1": min(nr, 1)}
        layout, start = [], 0
        for name, width in self.saved:
            w = counts[width] if isinstance(width, str) else int(width)
            layout.append((name, start, w))
            start += w
        return tuple(layout)

    def n_saved(self, n: int, m: int, ne: int, nc: int = 0, nr: int = 0) -> int:
        """Width of the extra buffer (sum of the saved fields' widths)."""
        return sum(w for _, _, w in self.saved_layout(n, m, ne, nc, nr))

    def saves_constraints(self, m: int) -> bool:
        """Whether a run of a model with m holonomic constraints saves the constrained methods'
        fields (multipliers, constraint_error, velocity_constraint_error) and so starts from a
        consistent state: a constrained method, or a contact method on a constrained model."""
        return self.constraints or bool(m and self.contacts and self.holonomic_too)

    def setting_names(self) -> tuple:
        return tuple(self.settings._fields)


def make_settings(spec: Spec, given: dict):
    """The method's settings record from the user's keywords ``given`` (None values take the
    default). Raises SimulationError, one line, naming the setting and the value."""
    unknown = [k for k in given if k not in spec.settings._fields]
    if unknown:
        raise SimulationError(
            f"method {spec.name!r} has no setting {unknown[0]!r}; its settings: "
            f"{', '.join(spec.settings._fields)}")
    values = {}
    for name in spec.settings._fields:
        value = given.get(name)
        default = spec.settings._field_defaults[name]
        values[name] = default if value is None else _checked(spec, name, value, default)
    return spec.settings(**values)


def _checked(spec, name, value, default):
    """value converted to the type of ``default``, after the field's limits."""
    limit = {**LIMITS, **spec.limits}.get(name)
    if isinstance(default, bool):
        if not isinstance(value, (bool, int)) or value not in (0, 1):
            raise SimulationError(f"{name} must be True or False, got {value!r}")
        return bool(value)
    if isinstance(default, tuple):
        try:
            items = tuple(float(x) for x in value)
        except (TypeError, ValueError):
            items = ()
        if len(items) != len(default):
            raise SimulationError(f"{name} must be {len(default)} numbers, got {value!r}")
        for x in items:
            _check_number(name, x, limit, value)
        return items
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise SimulationError(f"{name} must be a positive integer, got {value!r}")
        _check_number(name, value, limit, value, integer=True)
        return int(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise SimulationError(f"{name} must be {_describe(limit)}, got {value!r}")
    _check_number(name, float(value), limit, value)
    return float(value)


def _describe(limit, integer=False):
    if limit is None:
        return "a finite number"
    low, inclusive, allow_inf = limit
    if integer:
        return "a positive integer" if (low, inclusive) == (1, True) else f"an integer >= {low:g}"
    bound = f"{'>=' if inclusive else '>'} {low:g}"
    return f"a number {bound} (math.inf: no bound)" if allow_inf else f"a finite number {bound}"


def _check_number(name, x, limit, shown, integer=False):
    allow_inf = limit is not None and limit[2]
    ok = not math.isnan(x) and (math.isfinite(x) or (allow_inf and x > 0))
    if ok and limit is not None:
        low, inclusive, _ = limit
        ok = x >= low if inclusive else x > low
    if not ok:
        raise SimulationError(f"{name} must be {_describe(limit, integer)}, got {shown!r}")
