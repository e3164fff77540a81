"""The unrolled LDL^T forward dynamics emitted for small n (codegen/forward.py).

The solve statements are executed as plain Python on random SPD and singular matrices and
compared with numpy and with linalg's Cholesky (the loops every other path uses): the same
solution to round-off and SINGULAR_MASS in exactly the same cases. Then the generated
forward_dynamics of real models is checked against H^-1 rhs from their own dynamics kernel
solved by numpy, including the spherical pendulum at its singular pole."""

import math

import numpy as np
import pytest

from lagrange_gen.codegen.forward import UNROLL_MAX, unrolled_solve_lines
from lagrange_gen.steppers.core import linalg
from lagrange_gen.steppers.core.status import OK, SINGULAR_MASS


def _run_unrolled(H, b):
    """Execute unrolled_solve_lines on H (n, n), b (n,): (status, x)."""
    n = len(b)
    scope = {f"H_{j}_{k}": H[j, k] for j in range(n) for k in range(j, n)}
    scope.update({f"rhs_{i}": b[i] for i in range(n)})
    out = np.full(n, np.nan)
    scope.update(qdd=out, math=math, SINGULAR_RTOL=linalg.SINGULAR_RTOL, OK=OK,
                 SINGULAR_MASS=SINGULAR_MASS)
    body = "\n".join("    " + line for line in unrolled_solve_lines(n))
    exec(f"def _solve():\n{body}\n", scope)
    return scope["_solve"](), out


def _cases(seed=3):
    rng = np.random.default_rng(seed)
    for n in range(1, UNROLL_MAX + 1):
        for _ in range(10):
            A = rng.normal(size=(n, n))
            yield A @ A.T + 1e-2 * np.eye(n) * rng.uniform(0.1, 10)
            yield A + A.T                               # symmetric, mostly indefinite
        S = rng.normal(size=(n, n))
        S[-1] = S[0]
        yield S @ S.T                                   # singular (rank n - 1 or less)
        yield np.zeros((n, n))
        bad = np.eye(n)
        bad[0, 0] = math.nan
        yield bad


@pytest.mark.parametrize("H", list(_cases()))
def test_unrolled_solve_matches_numpy_and_refuses_what_cholesky_refuses(H):
    n = H.shape[0]
    b = np.linspace(-1.0, 2.0, n)
    status, x = _run_unrolled(H, b)
    factor_ok = linalg.cholesky_inplace(H.copy())
    assert (status == OK) == factor_ok
    if status == OK:
        ref = np.linalg.solve(H, b)
        assert np.abs(x - ref).max() <= 1e-12 * np.linalg.cond(H) * max(1.0, np.abs(ref).max())


@pytest.mark.parametrize("stem, options, q", [
    ("cart_pendulum", {}, [0.3, -1.2]), ("double_pendulum", {}, [0.4, 2.0]),
    ("spherical_pendulum", {}, [0.7, 0.3]), ("n_link_pendulum", {"n": 3}, [0.1, -0.5, 1.1]),
    ("n_link_pendulum", {"n": 4}, [0.1, -0.5, 1.1, 2.5])])
def test_generated_forward_dynamics_is_h_inverse_rhs(generated, stem, options, q):
    mod = generated(stem, **options)
    n = mod.N_COORDS
    assert mod.MASS_IS_CONSTANT is False and n <= UNROLL_MAX
    q, v = np.array(q), np.linspace(0.5, -0.8, n)
    p = mod.DEFAULT_PARAMS
    H, rhs, a = np.empty((n, n)), np.empty(n), np.empty(n)
    mod.dynamics(q, v, 0.3, p, H, rhs)
    assert mod.forward_dynamics(q, v, 0.3, p, np.empty((n, n)), a) == OK
    ref = np.linalg.solve(H, rhs)
    np.testing.assert_allclose(a, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())


def test_singular_pole_is_reported(generated):
    mod = generated("spherical_pendulum")
    q = np.zeros(2)                                    # sin(theta) = 0: H singular
    a = np.empty(2)
    assert mod.forward_dynamics(q, np.ones(2), 0.0, mod.DEFAULT_PARAMS, np.empty((2, 2)), a) == SINGULAR_MASS
