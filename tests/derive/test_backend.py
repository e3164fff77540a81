"""symengine and sympy differentiation backends give the same equations (checked numerically)."""

import numpy as np
import pytest
import sympy as sp

from lg_test_support import MODELS_DIR
from lagrange_gen import load_model
from lagrange_gen.derive import backend, derive

pytest.importorskip("symengine")


@pytest.mark.parametrize("stem", ["double_pendulum", "spring_mass_chain", "cartesian_pendulum"])
def test_backends_agree(monkeypatch, stem):
    model = load_model(MODELS_DIR / f"{stem}.py")
    fast = derive(model)
    monkeypatch.setattr(backend, "BACKEND", "sympy")
    slow = derive(model)
    args = [fast.q, fast.qd, fast.t, fast.params, fast.aux["w"], fast.aux["lam"]]
    rng = np.random.default_rng(7)
    values = [rng.uniform(-1, 1, len(fast.q)), rng.uniform(-1, 1, len(fast.q)), 0.3,
              np.array(model.defaults(), dtype=float), rng.uniform(-1, 1, len(fast.q)),
              rng.uniform(-1, 1, len(fast.aux["lam"]))]
    pairs = [(fast.H, slow.H), (fast.rhs, slow.rhs), (fast.J, slow.J), (fast.gamma, slow.gamma)]
    pairs += [(fast.jac[k], slow.jac[k]) for k in fast.jac]
    for a, b in pairs:
        if a.shape[0] * a.shape[1] == 0:
            continue
        fa, fb = sp.lambdify(args, a), sp.lambdify(args, b)
        np.testing.assert_allclose(np.asarray(fa(*values), float), np.asarray(fb(*values), float),
                                   rtol=1e-12, atol=1e-12)
