"""lg.kinetic_energy and lg.gravity_potential of mechanics bodies against sympy's own
RigidBody.kinetic_energy / potential written out, at random states: central inertias given in
the body's frame, in its parent's, in the inertial frame and as outer products of vectors of
different frames (the components of every such dyadic in the body's frame are what T needs)."""

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import lagrange_gen as lg
from lagrange_gen.model.intermediates import expand_intermediates

INERTIA_FRAMES = ("body", "parent", "inertial", "mixed")


def _bodies(where):
    q = me.dynamicsymbols("a0:3")
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    bodies, parent, joint = [], N, O
    axes = (lambda F: F.z, lambda F: F.y, lambda F: (F.x + 2 * F.y - F.z) / sp.sqrt(6))
    for i in range(3):
        A = parent.orientnew(f"A{i}", "Axis", (q[i], axes[i](parent)))
        G = joint.locatenew(f"G{i}", 0.1 * A.x - 0.03 * A.y + 0.2 * A.z)
        frame = {"body": A, "parent": parent, "inertial": N, "mixed": A}[where]
        inertia = me.inertia(frame, 0.02 + 0.003 * i, 0.031, 0.017, 0.0013, -0.002, 0.0011)
        if where == "mixed":      # a symmetric dyadic whose outer products mix three frames
            inertia += 0.004 * (me.outer(A.x, parent.y) + me.outer(parent.y, A.x))
            inertia += 0.002 * (me.outer(N.z, A.z) + me.outer(A.z, N.z))
        bodies.append(me.RigidBody(f"B{i}", G, A, 1.0 + 0.2 * i, (inertia, G)))
        joint, parent = joint.locatenew(f"J{i + 1}", 0.05 * A.x + 0.4 * A.z), A
    return N, q, bodies


def _ours_at(T, q, state):
    """lg's T (Coordinates a_i, Velocities a_i_dot; Intermediates expanded) at state (q, qd)."""
    values = {}
    for qi, x, v in zip(q, *state):
        values[str(qi.func)], values[f"{qi.func}_dot"] = x, v
    return float(T.xreplace({s: values[s.name] for s in T.free_symbols}))


def _sympy_at(T, q, state):
    """sympy's T (q(t), q'(t)) at state (q, qd)."""
    T = T.xreplace({qi.diff(me.dynamicsymbols._t): v for qi, v in zip(q, state[1])})
    return float(T.xreplace({qi: x for qi, x in zip(q, state[0])}))


# sympy's Point.vel notes that G2 could be reached from two points; both give the same velocity
@pytest.mark.filterwarnings("ignore:Velocity of G")
@pytest.mark.parametrize("where", INERTIA_FRAMES)
def test_kinetic_energy_equals_sympy_written_out(where):
    N, q, bodies = _bodies(where)
    ours = expand_intermediates(lg.kinetic_energy(N, bodies))
    theirs = sum(body.kinetic_energy(N) for body in bodies)
    rng = np.random.default_rng(11)
    for _ in range(3):
        state = rng.uniform(-2, 2, (2, 3))
        assert _ours_at(ours, q, state) == pytest.approx(_sympy_at(theirs, q, state), rel=1e-13, abs=1e-15)
