"""Coulomb friction (Moreau-Jean, no regularization) and the refusals of issue 7."""

import textwrap

import numpy as np
import pytest

from lagrange_gen import ModelError, SimulationError, load_model
from lagrange_gen.errors import SingularNewtonMatrix
from lagrange_gen.run.simulate import simulate
from nonsmooth_util import ns_model  # noqa: F401  (fixture)


def test_coulomb_free_decay_turning_points_and_rest(ns_model):
    """m = k = 1, F_d = 0.1, x0 = 1.05: |x(j pi)| = 0.85, 0.65, 0.45, 0.25, 0.05, rest at -0.05."""
    mod = ns_model("coulomb_oscillator")
    h = 1e-4
    traj = simulate(mod, method="implicit_euler", q0=[1.05], t_end=7 * np.pi, h=h)
    for j, amp in enumerate([0.85, 0.65, 0.45, 0.25, 0.05], start=1):
        i = int(round(j * np.pi / h))
        window = traj.q[i - 200:i + 200, 0]
        turn = window[np.argmax(np.abs(window))]
        assert turn == pytest.approx((-1) ** j * amp, abs=1e-3)
    assert traj.q[-1, 0] == pytest.approx(-0.05, abs=1e-3)
    # Sticking is exact (no creep as with a regularized law): the last second does not move.
    last = traj.t > traj.t[-1] - 1.0
    assert np.ptp(traj.q[last, 0]) == 0.0 and np.all(traj.v[last, 0] == 0.0)
    # The friction force stays within its bound and balances the spring at rest.
    assert np.all(np.abs(traj.element_state[:, 0]) <= 0.1 + 1e-14)
    assert traj.element_state[-1, 0] == pytest.approx(-0.05, abs=1e-3)


def test_singular_newton_matrix_with_friction_is_reported(ns_model):
    """m = k = 0: the Newton matrix A = m + h^2 k vanishes. The friction path factors A itself
    (the Delassus problem), and the step must still fail as a singular Newton matrix."""
    mod = ns_model("coulomb_oscillator")
    with pytest.raises(SingularNewtonMatrix, match=r"step 1 of 10 .*singular Newton matrix"):
        simulate(mod, method="implicit_euler", q0=[1.0], v0=[1.0], t_end=0.01, h=1e-3,
                 params={"m": 0.0, "k": 0.0})


@pytest.mark.parametrize("method", ["verlet", "midpoint", "rk4"])
def test_methods_without_nonsmooth_treatment_refuse(ns_model, method):
    mod = ns_model("coulomb_oscillator")
    with pytest.raises(SimulationError, match=r"cannot treat the nonsmooth element\(s\) friction.*implicit_euler"):
        simulate(mod, method=method, q0=[1.0], t_end=1.0, h=1e-3)


HEADER = "import sympy as sp\nfrom lagrange_gen import Model, SaintVenant, coordinates, parameters, t\n"


@pytest.mark.parametrize("element, message", [
    ("SaintVenant(x, 1.0, threshold=0.0)", r"threshold must be > 0, got 0"),
    ("SaintVenant(x, k, threshold=-eta)", r"threshold must be > 0"),
    ("SaintVenant(x * sp.cos(t), 1.0, threshold=1.0)", r"strain .* depends on t"),
    ("SaintVenant(x.d, 1.0, threshold=1.0)", r"strain x_dot depends on x_dot"),
])
def test_bad_elements_are_refused(tmp_path, element, message):
    path = tmp_path / "bad.py"
    path.write_text(HEADER + textwrap.dedent(f"""
        x = coordinates("x")
        k, eta = parameters("k eta", defaults=(1.0, 0.5))
        model = Model("bad", coords=[x], T=x.d**2 / 2, elements=[{element}])
    """))
    with pytest.raises(ModelError, match=message):
        load_model(path)
