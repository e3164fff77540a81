"""Coordinates and parameters may be named like the generator's internals (w_0, lam_0, we_0,
q_1, x0, H, ...): a model named that way gives exactly the numbers of the same model with plain
names, compiled, through the Newton kernels that take the w / lam / we inputs (issue 10)."""

import numpy as np
import pytest

from lagrange_gen import simulate
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

# {placeholder in TEMPLATE: (internal-looking name, plain name)}. Coordinates first, then
# parameters; every name the generated code uses for its own purposes appears.
NAMES = {"A": ("w_0", "a"), "B": ("lam_0", "b"), "C": ("q_1", "c"),
         "P1": ("x0", "k1"), "P2": ("H", "k2"), "P3": ("we_0", "k3"), "P4": ("rhs", "k4"),
         "P5": ("qd_0", "k5"), "P6": ("p_0", "k6"), "P7": ("math", "k7"), "P8": ("np", "k8")}

TEMPLATE = """\
import sympy as sp
from lagrange_gen import Model, coordinates, parameters, SaintVenant
A, B, C = coordinates("A B C")
P1, P2, P3, P4, P5, P6, P7, P8 = parameters("P1 P2 P3 P4 P5 P6 P7 P8",
                                            defaults=(1.5, 2.0, 0.7, 0.3, 1.2, 0.4, 0.9, 0.25))
T = (P2 * A.d**2 + P1 * (1 + B**2 / 4) * B.d**2 + C.d**2 + P4 * A.d * C.d * sp.cos(B)) / 2
V = P3 * (A**2 + B**2 + C**2) / 2 + P6 * sp.cos(A) * C / P1 + P7 * B**4
model = Model("NAME", coords=[A, B, C], T=T, V=V, dissipation=P5 * A.d**2 / 2EXTRA)
"""

# Constraints and an element bring the lam and we inputs (kernels constraint_dq, elements_hessian).
EXTRA = """,
              constraints=[A**2 + P8 * B**2 + C - 1],
              elements=[SaintVenant(strain=A * C, stiffness=P2, threshold=P3)]"""
METHODS = {"free": ["midpoint"], "full": []}


def _source(which, model_name, kind):
    text = TEMPLATE.replace("NAME", model_name).replace("EXTRA", EXTRA if kind == "full" else "")
    for key in sorted(NAMES, key=len, reverse=True):       # P1 before A, etc.: keys are distinct
        text = text.replace(key, NAMES[key][which])
    return text


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    """{(kind, "internal" | "plain"): generated module}; kind "free" (no constraint, no element)
    has midpoint's glue, "full" (constraints and elements: no method applies to both) every
    kernel, including those with lam and we inputs, and no glue."""
    out = tmp_path_factory.mktemp("names")
    found = {}
    for kind, methods in METHODS.items():
        for which, naming in enumerate(("internal", "plain")):
            path = out / f"{naming}_{kind}.py"
            path.write_text(_source(which, f"{naming}_{kind}", kind))
            found[kind, naming] = import_generated(generate_model(path, out / "gen", methods=methods).path)
    return found


def test_generated_constants_use_the_users_names(modules):
    internal = modules["full", "internal"]
    assert internal.COORDS == ("w_0", "lam_0", "q_1")
    assert internal.PARAMS == ("x0", "H", "we_0", "rhs", "qd_0", "p_0", "math", "np")


def _kernel_calls(n, m, ne, rng):
    """{kernel: call(module) -> output arrays} at one random state, for every input vector."""
    q, v, w = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    lam, we = rng.uniform(-1, 1, m), rng.uniform(-1, 1, ne)

    def run(kernel, *args, shapes):
        outs = [np.empty(s) for s in shapes]
        kernel(*args, *outs)
        return outs
    return {
        "dynamics": lambda k: run(k.dynamics, q, v, 0.3, k.DEFAULT_PARAMS, shapes=[(n, n), n]),
        "rhs_jacobian": lambda k: run(k.rhs_jacobian, q, v, 0.3, k.DEFAULT_PARAMS, shapes=[(n, n)] * 2),
        "mass_matvec_dq": lambda k: run(k.mass_matvec_dq, q, w, 0.3, k.DEFAULT_PARAMS, shapes=[(n, n)]),
        "constraints": lambda k: run(k.constraints, q, v, 0.3, k.DEFAULT_PARAMS, shapes=[m, (m, n), m]),
        "constraint_dq": lambda k: run(k.constraint_dq, q, w, lam, 0.3, k.DEFAULT_PARAMS, shapes=[(m, n), (n, n)]),
        "elements": lambda k: run(k.elements, q, k.DEFAULT_PARAMS, shapes=[ne, (ne, n), (ne, 3)]),
        "elements_hessian": lambda k: run(k.elements_hessian, q, we, k.DEFAULT_PARAMS, shapes=[(n, n)]),
    }, (q, w, lam, we)


def test_compiled_kernels_with_w_lam_we_inputs_agree_with_plain_names(modules):
    internal, plain = modules["full", "internal"], modules["full", "plain"]
    rng = np.random.default_rng(7)
    for _ in range(3):
        calls, (q, w, lam, we) = _kernel_calls(3, 1, 1, rng)
        for name, call in calls.items():
            for got, want in zip(call(internal), call(plain)):
                np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-14, err_msg=name)
        # By hand, for the inputs w, lam, we: H = [[H, 0, rhs cos(lam_0) / 2], [0, x0 (1 + lam_0^2
        # / 4), 0], [rhs cos(lam_0) / 2, 0, 1]], Phi = w_0^2 + np lam_0^2 + q_1 - 1, s = w_0 q_1.
        x0, rhs, np_ = internal.DEFAULT_PARAMS[[0, 3, 7]]
        dHw = np.zeros((3, 3))
        dHw[:, 1] = [-rhs * np.sin(q[1]) / 2 * w[2], x0 * q[1] / 2 * w[1], -rhs * np.sin(q[1]) / 2 * w[0]]
        np.testing.assert_allclose(calls["mass_matvec_dq"](internal)[0], dHw, rtol=1e-13, atol=1e-15)
        dJw, dJTlam = calls["constraint_dq"](internal)
        np.testing.assert_allclose(dJw, [[2 * w[0], 2 * np_ * w[1], 0.0]], rtol=1e-13)
        np.testing.assert_allclose(dJTlam, np.diag([2, 2 * np_, 0]) * lam[0], rtol=1e-13)
        hess = calls["elements_hessian"](internal)[0]
        np.testing.assert_allclose(hess, [[0, 0, we[0]], [0, 0, 0], [we[0], 0, 0]], rtol=1e-13)


def test_midpoint_simulation_agrees_with_plain_names(modules):
    """A few compiled midpoint steps (Newton with the w kernel mass_matvec_dq)."""
    runs = [simulate(modules["free", naming], method="midpoint", q0=[0.3, -0.2, 0.5],
                     v0=[0.1, 0.4, -0.3], t_end=0.2, h=0.02) for naming in ("internal", "plain")]
    np.testing.assert_allclose(runs[0].q, runs[1].q, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(runs[0].v, runs[1].v, rtol=1e-12, atol=1e-14)
    assert abs(runs[0].q[-1] - runs[0].q[0]).max() > 1e-3       # it moved
