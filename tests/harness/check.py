"""Generate a drawn model, call every kernel its module emits, compare with the reference.

Three ways to run a module: ``"njit"`` calls the compiled dispatchers; ``"py_func"`` runs the
printed source as plain Python (pure_kernels), with every kernel a kernel calls (composed
kernels, forward_dynamics) replaced by its py_func too, so nothing is compiled; ``"native"``
calls the kernels lowered to LLVM by jit/native.py, as the portable glue does (native_kernels).

Every comparison is recorded in CHECKED {(kind, mode): count}, kind being a kernel name,
``<kernel>[composed]``, a forward-dynamics path or ``fd:<kernel>`` (finite differences), so a
test can assert that the run covered every kernel kind.
"""

from __future__ import annotations

import inspect
import types
from collections import Counter
from dataclasses import dataclass

import numpy as np

from lagrange_gen.codegen import generate_text
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core.status import OK

from .strategies import sample_state

RTOL = 1e-9          # kernel vs reference, elementwise relative ...
FLOOR = 1e-9         # ... plus FLOOR * max(1, max |reference output|) for entries near zero
CHECKED: Counter = Counter()
STATS: Counter = Counter()

_QQTP = ("q", "qd", "t", "p")
#: kernel -> (inputs, outputs as (argument, shape), reference quantities), as documented in
#: README / codegen.spec; shapes: n coordinates, m constraints, e elements, c contacts.
CONTRACT = {
    "mass_matrix": (("q", "t", "p"), (("H", "nn"),), ("H",)),
    "dynamics": (_QQTP, (("H", "nn"), ("rhs", "n")), ("H", "rhs")),
    "rhs": (_QQTP, (("out", "n"),), ("rhs",)),
    "energy": (_QQTP, (), ("E",)),
    "momentum_rate": (_QQTP, (("out", "n"),), ("momentum_rate",)),
    "rhs_jacobian": (_QQTP, (("Jq", "nn"), ("Jqd", "nn")), ("drhs_dq", "drhs_dqd")),
    "momentum_rate_jacobian": (_QQTP, (("Jq", "nn"), ("Jqd", "nn")), ("dmom_dq", "dmom_dqd")),
    "mass_matvec_dq": (("q", "w", "t", "p"), (("out_mat", "nn"),), ("dHw_dq",)),
    "constraints": (("q", "qd", "t", "p"), (("phi", "m"), ("J", "mn"), ("gamma", "m")), ("Phi", "J", "gamma")),
    "constraint_rate": (("q", "t", "p"), (("out", "m"),), ("Phi_t",)),
    "power": (_QQTP, (("out", "P"),), ("power",)),
    "transport": (("q", "t", "p"), (("out", "n"),), ("b",)),
    "transport_dq": (("q", "t", "p"), (("out_mat", "nn"),), ("db",)),
    "constraint_dq": (("q", "w", "lam", "t", "p"), (("dJw", "mn"), ("dJTlam", "nn")), ("dJw_dq", "dJTlam_dq")),
    "elements": (("q", "p"), (("s", "e"), ("G", "en"), ("coef", "e3")), ("s", "G", "coef")),
    "elements_hessian": (("q", "we", "p"), (("out_mat", "nn"),), ("hess_w",)),
    "events": (_QQTP, (("out", "g"),), ("events",)),
    # only a model with unilateral contacts has it
    "contacts": (("q", "t", "p"), (("gap", "c"), ("WN", "cn"), ("WT", "2cn"), ("coef", "c2")),
                 ("contact_gap", "contact_WN", "contact_WT", "contact_coef")),
    # only a model with velocity constraints has them (constraint_gamma_dq: with holonomic ones too)
    "nonholonomic": (_QQTP, (("A", "rn"), ("b", "r"), ("gamma", "r")), ("nh_A", "nh_b", "nh_gamma")),
    "nonholonomic_dq": (("q", "qd", "w", "mu", "t", "p"),
                        (("dAw", "rn"), ("dATmu", "nn"), ("dc", "rn"), ("dgamma_dq", "rn"),
                         ("dgamma_dqd", "rn")),
                        ("nh_dAw", "nh_dATmu", "nh_dc", "nh_dgamma_dq", "nh_dgamma_dqd")),
    "constraint_gamma_dq": (_QQTP, (("dgamma_dq", "mn"), ("dgamma_dqd", "mn")),
                            ("gamma_dq", "gamma_dqd")),
    "contact_rates": (_QQTP, (("out", "3c"),), ("contact_rate",)),
    "contact_bias": (("q", "t", "p"), (("out", "3c"),), ("contact_bias",)),
    # the kernels of a module generated from bodies (README, Robots); qdd is the State's w
    "inverse_dynamics": (("q", "qd", "qdd", "t", "p"), (("tau", "n"),), ("tau_id",)),
    "gravity_forces": (("q", "t", "p"), (("out", "n"),), ("gravity",)),
    "bias_forces": (_QQTP, (("out", "n"),), ("bias",)),
}
#: the kernels only a module generated from bodies has (tests/harness/test_spatial_trees.py)
BODY_KERNELS = ("inverse_dynamics", "gravity_forces", "bias_forces")
#: the kernels only a module of a model with unilateral contacts has
CONTACT_KERNELS = ("contacts", "contact_bias", "contact_rates")
#: the kernels only a module of a model with velocity constraints has
NONHOLONOMIC_KERNELS = ("nonholonomic", "nonholonomic_dq", "constraint_gamma_dq")
#: the parameter derivatives only a module generated with sensitivities has: not drawn here;
#: tests/gradients compares them with central differences of the kernels they differentiate
#: (which this harness checks against the reference) and the sensitivities they give with
#: central differences of whole runs
SENSITIVITY_KERNELS = ("rhs_dp", "momentum_rate_dp", "mass_matvec_dp", "transport_dp")


@dataclass
class State:
    """One evaluation point: q, qd, w (n,), t, params {name: value}, p (PARAMS order), lam (m,),
    we (ne,), mu (r,) (None: zeros)."""

    q: np.ndarray
    qd: np.ndarray
    t: float
    params: dict
    p: np.ndarray
    w: np.ndarray
    lam: np.ndarray
    we: np.ndarray
    mu: np.ndarray = None

    @property
    def qdd(self):
        """The accelerations given to inverse_dynamics: the numbers of w (n,)."""
        return self.w


def generate(drawn, out_dir, methods):
    """Generate and import the module of a DrawnModel (methods: [] for every kernel, symbolic)."""
    model = drawn.build()
    model.source_path = str(out_dir / f"{drawn.name}_model.py")    # never written: no staleness check
    text, _, target = generate_text(model, out_dir, methods=methods)
    target.write_text(text)
    return import_generated(target)


def pure_kernels(mod):
    """The module's functions with every numba dispatcher replaced by its py_func, calling each
    other's py_funcs (a namespace; accelerations included)."""
    env = dict(vars(mod))
    for name, obj in vars(mod).items():
        if hasattr(obj, "py_func"):
            f = obj.py_func
            scope = env if f.__module__ == mod.__name__ else f.__globals__
            env[name] = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
    acc = mod.accelerations
    env["accelerations"] = types.FunctionType(acc.__code__, env, "accelerations", acc.__defaults__)
    return types.SimpleNamespace(**env)


_CALLERS: dict = {}


def _caller(n_args):
    """A jitted function calling a first-class function with ``n_args`` arguments: how a
    native kernel is called from Python (numba compiles it once per kernel signature)."""
    if n_args not in _CALLERS:
        from numba import njit
        names = ", ".join(f"a{i}" for i in range(n_args))
        scope = {}
        exec(f"def call(kernel, {names}):\n    return kernel({names})", scope)
        _CALLERS[n_args] = njit(scope["call"])
    return _CALLERS[n_args]


def native_kernels(mod):
    """pure_kernels with every kernel that the portable glue can reach (the module's KERNELS and
    forward_dynamics) replaced by its native kernel (jit/native.py); a kernel outside the subset
    native_ir lowers raises Unsupported here, so the harness says which."""
    from lagrange_gen.jit.native import native_kernel
    from lagrange_gen.jit.portable import native_dir
    env = vars(pure_kernels(mod))
    for name in (*mod.KERNELS, "forward_dynamics", *BODY_KERNELS, "forward_dynamics_torques"):
        if not hasattr(mod, name):
            continue
        kernel = native_kernel(mod, name, native_dir())

        def call(*args, _kernel=kernel):
            return _caller(len(args))(_kernel, *args)

        env[name] = call
    return types.SimpleNamespace(**env)


def states(drawn, mod, rng, count):
    """``count`` States; the first at the default parameters, the others with every parameter
    scaled by a factor in [0.7, 1.4] (passed through p, not frozen into the module)."""
    n, m, ne = len(drawn.coords), len(drawn.constraints), len(drawn.elements)
    out = []
    for i in range(count):
        q, qd, t = sample_state(drawn, rng)
        scale = 1.0 if i == 0 else rng.uniform(0.7, 1.4, len(drawn.defaults))
        params = dict(zip(drawn.defaults, np.asarray(list(drawn.defaults.values())) * scale))
        p = np.array([params[name] for name in mod.PARAMS], dtype=float)
        out.append(State(q, qd, t, params, p, rng.uniform(-1, 1, n), rng.uniform(-1, 1, m),
                         rng.uniform(-1, 1, ne), rng.uniform(-1, 1, len(drawn.nonholonomic))))
    return out


def compare(label, got, expected, rtol=RTOL, floor=FLOOR):
    """None when |got - expected| <= rtol |expected| + floor max(1, max |expected|) everywhere,
    else a message with the worst entry."""
    got, expected = np.asarray(got, dtype=float), np.asarray(expected, dtype=float)
    if got.shape != expected.shape:
        return f"{label}: shape {got.shape}, expected {expected.shape}"
    if got.size == 0:
        return None
    allowed = rtol * np.abs(expected) + floor * max(1.0, float(np.max(np.abs(expected))))
    excess = np.abs(got - expected) - allowed
    if np.all(excess <= 0):     # NaN (an entry never written) fails here
        return None
    worst = np.unravel_index(int(np.argmax(np.where(np.isnan(excess), np.inf, excess))), got.shape)
    return f"{label}{[int(i) for i in worst]}: got {float(got[worst])!r}, expected {float(expected[worst])!r}"


ACCUMULATING = {"transport", "transport_dq"}


def _shape(key, n, m, ne, ng=0, nc=0, nr=0):
    return {"n": (n,), "nn": (n, n), "m": (m,), "mn": (m, n), "e": (ne,), "en": (ne, n),
            "e3": (ne, 3), "g": (ng,), "P": (2 * n + 2,), "c": (nc,), "cn": (nc, n),
            "c2": (nc, 2), "2c": (2 * nc,), "2cn": (2 * nc, n), "3c": (3 * nc,), "r": (nr,),
            "rn": (nr, n)}[key]


def call_kernel(kern, name, state, sizes):
    """Run kernel ``name`` of ``kern`` at a state on NaN-filled outputs: {reference name: value}.
    sizes: (n, m, ne[, ng[, nc[, nr]]]) coordinates, constraints, elements, events, contacts,
    velocity constraints."""
    inputs, outputs, quantities = CONTRACT[name]
    # The accumulating kernels (out += ...) start from zeros, the others from NaN (unwritten
    # entries show).
    fill = 0.0 if name in ACCUMULATING else np.nan
    arrays = [np.full(_shape(key, *sizes), fill) for _, key in outputs]
    result = getattr(kern, name)(*[getattr(state, a) for a in inputs], *arrays)
    return dict(zip(quantities, arrays if outputs else [result]))


def kind(mod, name):
    """The kernel kind recorded for coverage: composed kernels say so in their docstring."""
    doc = getattr(mod, name).py_func.__doc__ or ""
    return f"{name}[composed]" if "composed" in doc else name


def check_kernels(mod, kern, ref, state, mode, skip=()):
    """Every kernel of mod.KERNELS but those in ``skip`` (checked otherwise by the caller),
    forward_dynamics and accelerations at one state against the reference: a list of
    mismatches (a kernel that raises is one)."""
    failures = []
    for name in (*(k for k in mod.KERNELS if k not in skip), "forward_dynamics"):
        try:
            failures += _check_forward(mod, kern, ref, state, mode) if name == "forward_dynamics" \
                else _check_kernel(mod, kern, name, ref, state, mode)
        except Exception as exc:      # noqa: BLE001  e.g. SingularMass, ZeroDivisionError
            failures.append(f"{name}: raised {type(exc).__name__}: {exc}")
    return [f for f in failures if f]


def _check_kernel(mod, kern, name, ref, state, mode):
    inputs, outputs, _ = CONTRACT[name]
    documented = list(inputs) + [o for o, _ in outputs]
    actual = list(inspect.signature(getattr(mod, name).py_func).parameters)
    if actual != documented:
        return [f"{name}: arguments {actual}, documented {documented}"]
    values = call_kernel(kern, name, state,
                         (ref.n, ref.m, ref.ne, len(ref.drawn.events), getattr(ref, "nc", 0),
                          getattr(ref, "nr", 0)))
    # counted for coverage only where it computes something: constraint and element kernels
    # of a model without constraints or elements fill empty or zero arrays
    if all(np.size(v) for v in values.values()) and (ref.m or "lam" not in inputs) and (ref.ne or "we" not in inputs):
        CHECKED[(kind(mod, name), mode)] += 1
    return [compare(f"{name}.{quantity}", got, ref.value(quantity, state)) for quantity, got in values.items()]


def forward_path(mod, state):
    if not hasattr(mod, "MASS_FACTOR"):
        return "forward_dynamics[general]"
    default = all(state.params[n] == d for n, d in zip(mod.PARAMS, mod.DEFAULTS))
    return "forward_dynamics[factored]" if default else "forward_dynamics[factored, other parameters]"


def _check_forward(mod, kern, ref, state, mode):
    """forward_dynamics and accelerations: H_ref qdd = rhs_ref to rounding (a backward-error
    check, independent of the conditioning of H), and the status OK."""
    n = ref.n
    H, rhs = ref.value("H", state), ref.value("rhs", state)
    work, qdd = np.full((n, n), np.nan), np.full(n, np.nan)
    status = kern.forward_dynamics(state.q, state.qd, state.t, state.p, work, qdd)
    acc = kern.accelerations(state.q, state.qd, state.t, params=dict(zip(mod.PARAMS, state.p)))
    CHECKED[(forward_path(mod, state), mode)] += 1
    CHECKED[("accelerations", mode)] += 1
    out = [None if status == OK else f"forward_dynamics: status {status}"]
    out += [_residual("forward_dynamics.qdd", qdd, H, rhs), _residual("accelerations", acc, H, rhs)]
    if hasattr(mod, "forward_dynamics_torques"):
        # joint torques tau = w: H qdd = rhs + tau
        qdd_tau = np.full(n, np.nan)
        status = kern.forward_dynamics_torques(state.q, state.qd, state.w, state.t, state.p, np.full((n, n), np.nan), qdd_tau)
        CHECKED[("forward_dynamics_torques", mode)] += 1
        out += [None if status == OK else f"forward_dynamics_torques: status {status}",
                _residual("forward_dynamics_torques.qdd", qdd_tau, H, rhs + state.w)]
    return out


def _residual(label, qdd, H, rhs):
    """None when |H qdd - rhs| <= RTOL (|H| |qdd| + |rhs|) + FLOOR max(1, ...) everywhere."""
    residual = H @ qdd - rhs
    scale = np.abs(H) @ np.abs(qdd) + np.abs(rhs)
    if np.all(np.abs(residual) <= RTOL * scale + FLOOR * max(1.0, float(np.max(scale)))):
        return None
    worst = int(np.argmax(np.where(np.isnan(residual), np.inf, np.abs(residual))))
    return f"{label}[{worst}]: H qdd - rhs = {residual[worst]!r} (qdd = {qdd.tolist()}, rhs = {rhs.tolist()})"


def check_model(drawn, methods, out_dir, modes, seed, n_states):
    """Generate a DrawnModel for ``methods``, then at ``n_states`` random states check every
    kernel against the reference and every Jacobian kernel against finite differences, in each
    of ``modes`` ("py_func", "njit", "native"). Returns the list of mismatches (empty when all agree)."""
    from .fd import check_derivatives
    from .reference import Reference
    mod = generate(drawn, out_dir, methods)
    ref = Reference(drawn)
    failures = []
    for mode in modes:
        kern = mod if mode == "njit" else native_kernels(mod) if mode == "native" \
            else pure_kernels(mod)
        for state in states(drawn, mod, np.random.default_rng(seed), n_states):
            failures += [f"{mode}: {f}" for f in check_kernels(mod, kern, ref, state, mode)]
            try:
                fd = check_derivatives(mod, kern, state, (ref.n, ref.m, ref.ne, 0, ref.nc), mode)
            except Exception as exc:      # noqa: BLE001  a kernel raising near the state
                fd = [f"finite differences: raised {type(exc).__name__}: {exc}"]
            failures += [f"{mode}: {f}" for f in fd]
    return failures
