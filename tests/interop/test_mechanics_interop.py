"""sympy.physics.mechanics as model input (issue 16, item 1).

The heavy top of models/heavy_top.py (energies written by hand) and of
tests/interop/models/heavy_top_mechanics.py (a RigidBody's kinetic energy, gravity as a Force at
the centre of mass) must give the same H and h, the hand model's g equal to minus the mechanics
model's Q (gravity moves from V to a load), and the same trajectory. The loads' generalized
forces are also compared with ones derived by hand from virtual work."""

from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import lagrange_gen as lg
from lagrange_gen import Model, ModelError, PointForce, parameters
from lagrange_gen.model.intermediates import expand_intermediates
from lagrange_gen.codegen import generate_model
from lagrange_gen.derive import derive
from lagrange_gen.run.loader import import_generated

ROOT = Path(__file__).resolve().parents[2]
HAND = ROOT / "models" / "heavy_top.py"
MECH = Path(__file__).resolve().parent / "models" / "heavy_top_mechanics.py"


def _zero(expr):
    return sp.simplify(sp.expand_trig(expr)) == 0


def _by_name(dyn, field):
    """A Dynamics field with every symbol replaced by a plain Symbol of the same name (the two
    models declare their own Parameters, equal by name only)."""
    matrix = getattr(dyn, field)
    return matrix.xreplace({s: sp.Symbol(s.name) for s in matrix.free_symbols})


def test_heavy_top_both_ways_same_H_h_and_forces():
    hand, mech = derive(lg.load_model(HAND)), derive(lg.load_model(MECH))
    assert [c.name for c in hand.q] == [c.name for c in mech.q]
    assert [p.name for p in hand.params] == [p.name for p in mech.params]
    # gravity given as me.Force(G, -m g N.z), a constant force, is folded into the potential:
    # the mechanics model's g is the hand model's and no generalized force remains
    for a, b in ((_by_name(hand, "H"), _by_name(mech, "H")), (_by_name(hand, "h"), _by_name(mech, "h")),
                 (_by_name(hand, "g"), _by_name(mech, "g"))):
        assert all(_zero(x) for x in a - b), (a, b)
    assert _by_name(mech, "Q") == sp.zeros(3, 1)
    assert not mech.has_work
    # and the hand model's g is m g l d cos(theta)/dq (not both wrong alike)
    th, m, g, l = (sp.Symbol(n) for n in ("theta", "m", "g", "l"))
    assert _by_name(hand, "g") == sp.Matrix([-m * g * l * sp.sin(th), 0, 0])


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    out = tmp_path_factory.mktemp("interop_gen")
    return [import_generated(generate_model(path, out, methods=["rk4"]).path) for path in (HAND, MECH)]


def test_heavy_top_both_ways_same_trajectory(modules):
    q0, v0 = [0.5, 0.0, 0.0], [0.3, 1.0, 20.0]
    hand, mech = (lg.simulate(mod, "rk4", q0, v0, t_end=1.0, h=1e-3) for mod in modules)
    assert np.abs(hand.q - mech.q).max() < 1e-10
    assert np.abs(hand.v - mech.v).max() < 1e-9
    assert np.ptp(hand.q[:, 0]) > 0.01          # it nutates: the comparison is not of a rest state


def _pendulum_frames():
    """Planar pendulum q (angle from the downward vertical N.y = up): bob P at l (sin q, -cos q)."""
    q = me.dynamicsymbols("q")
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [q, N.z])
    O = me.Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", -1 * A.y)
    return q, N, A, P


def test_point_force_with_mechanics_point_and_vector_is_virtual_work():
    """PointForce(P, F*N.x) on a pendulum of length 1: Q = F d(x_P)/dq = F cos q."""
    q, N, A, P = _pendulum_frames()
    m, F = parameters("m F", defaults=(1.0, 2.0))
    T = m * q.diff() ** 2 / 2
    model = Model("pushed", coords=[q], T=T, forces=[PointForce(P, F * N.x)], frame=N)
    qs = model.coords[0]
    assert sp.simplify(model.forces[0] - F * sp.cos(qs)) == 0


def test_torque_force_and_tuples_sum():
    """Torque tau N.z on A (omega = q' N.z): Q = tau; plus the KanesMethod tuple form of a force
    (P, F N.x): F cos q; sympy's Force and Torque objects alike."""
    q, N, A, P = _pendulum_frames()
    m, F, tau = parameters("m F tau", defaults=(1.0, 2.0, 0.5))
    T = lg.kinetic_energy(N, me.Particle("bob", P, m))
    model = Model("driven", coords=[q], T=T, forces=[me.Torque(A, tau * N.z), (P, F * N.x)],
                  frame=N)
    qs = model.coords[0]
    assert sp.simplify(model.forces[0] - tau - F * sp.cos(qs)) == 0
    # T comes over Intermediates (the kinematic tree kept); written out it is m q'^2 / 2
    assert sp.simplify(expand_intermediates(model.T) - m * qs.d**2 / 2) == 0


def test_torque_on_the_top_in_euler_angles():
    """Torque tau N.z on the top: omega . N.z = phi' + psi' cos(theta), so Q = (0, tau, tau cos)."""
    theta, phi, psi = me.dynamicsymbols("theta phi psi")
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Body", [phi, theta, psi], "ZXZ")
    I1, I3, tau = parameters("I1 I3 tau", defaults=(1.0, 0.5, 1.0))
    O = me.Point("O")
    O.set_vel(N, 0)
    body = me.RigidBody("top", O, A, 1, (me.inertia(A, I1, I1, I3), O))
    model = Model("spun", coords=[theta, phi, psi], T=lg.kinetic_energy(N, body),
                  forces=[me.Torque(A, tau * N.z)], frame=N)
    th = model.coords[0]
    expected = [0, tau, tau * sp.cos(th)]
    assert all(sp.simplify(a - b) == 0 for a, b in zip(model.forces, expected))


def test_mechanics_load_errors_are_one_line():
    q, N, A, P = _pendulum_frames()
    (m,) = [parameters("m", defaults=1.0)]
    with pytest.raises(ModelError, match=r"give the inertial frame, Model\(\.\.\., frame=N\)"):
        Model("noframe", coords=[q], T=m * q.diff()**2 / 2, forces=[me.Force(P, N.x)])
    x = lg.coordinates("x")
    with pytest.raises(ModelError, match="coordinates as dynamicsymbols"):
        Model("plain", coords=[x], T=m * x.d**2 / 2, forces=[me.Force(P, N.x)], frame=N)
    with pytest.raises(ModelError, match="not a Particle or RigidBody"):
        lg.kinetic_energy(N, P)


def test_eq_constraint_is_lhs_minus_rhs():
    x, y = lg.coordinates("x y")
    m, l = parameters("m l", defaults=(1.0, 1.0))
    model = Model("eq", coords=[x, y], T=m * (x.d**2 + y.d**2) / 2,
                  constraints=[sp.Eq(x**2 + y**2, l**2)])
    assert sp.expand(model.constraints[0] - (x**2 + y**2 - l**2)) == 0


def test_plain_symbols_get_the_parameters_hint():
    x = lg.coordinates("x")
    k = sp.symbols("k")
    with pytest.raises(ModelError, match=r"plain sp\.symbols are not parameters: declare them with "
                                         r"lagrange_gen\.parameters\('k', defaults=\.\.\.\)"):
        Model("plain_k", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
    with pytest.raises(ModelError, match=r"lagrange_gen\.coordinates\('z'\)"):
        Model("plain_z", coords=[sp.Symbol("z")], T=sp.Symbol("z") ** 2)
