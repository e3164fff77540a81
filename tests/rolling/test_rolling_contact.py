"""lg.rolling_contact: the rolling constraints of a wheel on a plane from
sympy.physics.mechanics frames and points, against the constraints written by hand in
models/rolling_disk.py (a vertical disk) and models/tilted_disk.py (a disk free to tilt), at
random states; a Model built with them derives the same constraint rows as the hand-written
model."""

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import lagrange_gen as lg
from lagrange_gen.errors import ModelError


def _numeric(exprs, symbols):
    return sp.lambdify(symbols, sp.Matrix(exprs), "numpy")


def test_vertical_disk_gives_the_hand_written_constraints():
    """Heading phi about N.z, rolling angle theta about the axle A.y, centre R above (x, y):
    x' - R cos(phi) theta' and y' - R sin(phi) theta', as models/rolling_disk.py writes them."""
    x, y, phi, theta = me.dynamicsymbols("x y phi theta")
    R = sp.Symbol("R", positive=True)
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [phi, N.z])
    W = A.orientnew("W", "Axis", [theta, A.y])
    O = me.Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x + y * N.y + R * N.z)
    rolling = lg.rolling_contact(C, W, A.y, R, N, N.z, origin=O)
    t = me.dynamicsymbols._t
    by_hand = [x.diff(t) - R * sp.cos(phi) * theta.diff(t),
               y.diff(t) - R * sp.sin(phi) * theta.diff(t)]
    assert [sp.simplify(a - b) for a, b in zip(rolling.slip, by_hand)] == [0, 0]
    assert sp.simplify(rolling.height) == 0                   # the centre is R above the plane
    assert sp.simplify((rolling.to_contact + R * N.z).magnitude()) == 0


def _tilted_disk():
    """The disk of models/tilted_disk.py in mechanics terms: yaw psi about N.z, tilt theta about
    the yawed x axis, spin phi about the axle L.y; the contact point at (x, y, 0), the centre R
    along L.z from it."""
    x, y, psi, theta, phi = q = me.dynamicsymbols("x y psi theta phi")
    R = sp.Symbol("R", positive=True)
    N = me.ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [psi, N.z])
    L = Y.orientnew("L", "Axis", [theta, Y.x])
    D = L.orientnew("D", "Axis", [phi, L.y])
    O = me.Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x + y * N.y + R * L.z)
    return q, R, N, Y, L, D, O, C


def test_tilted_disk_gives_the_hand_written_constraints_in_the_heading_axes():
    q, R, N, Y, L, D, O, C = _tilted_disk()
    x, y, psi, theta, phi = q
    rolling = lg.rolling_contact(C, D, L.y, R, N, N.z, origin=O)
    t = me.dynamicsymbols._t
    qd = [s.diff(t) for s in q]
    # the hand-written rows of models/tilted_disk.py: the contact point's velocity in the
    # heading's axes, (v_C + omega x (-R L.z)) . Y.x and . Y.y
    v = C.vel(N) + D.ang_vel_in(N).cross(-R * L.z)
    by_hand = [v.dot(Y.x), v.dot(Y.y)]
    values, rates = sp.symbols("v0:5"), sp.symbols("w0:5")
    plain = dict(zip(qd, rates)) | dict(zip(q, values))
    ours = _numeric([e.subs(plain) for e in rolling.slip] + [rolling.height.subs(plain)],
                    [R, *values, *rates])
    theirs = _numeric([e.subs(plain) for e in by_hand], [R, *values, *rates])
    rng = np.random.default_rng(3)
    for _ in range(20):
        state = rng.uniform(-1.2, 1.2, 10)                  # |tilt| < pi/2: it stands on its rim
        got = ours(0.5, *state)[:, 0]
        c, s = np.cos(state[2]), np.sin(state[2])           # the heading rotates the rows
        np.testing.assert_allclose([c * got[0] + s * got[1], -s * got[0] + c * got[1]],
                                   theirs(0.5, *state)[:, 0], atol=1e-13)
        assert abs(got[2]) < 1e-13                          # the rim touches the plane


def test_a_model_from_it_derives_the_rolling_disk_rows():
    """Model(nonholonomic=rolling.slip) with the mechanics coordinates: its constraint rows
    A qdot + b are those of models/rolling_disk.py (same coordinates and order)."""
    from lagrange_gen.derive.nonholonomic import derive_nonholonomic
    x, y, phi, theta = me.dynamicsymbols("x y phi theta")
    m, R, I_spin, I_turn = lg.parameters("m R I_spin I_turn", defaults=(1.0, 0.5, 0.125, 0.0625))
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [phi, N.z])
    W = A.orientnew("W", "Axis", [theta, A.y])
    O = me.Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x + y * N.y + R * N.z)
    rolling = lg.rolling_contact(C, W, A.y, R, N, N.z)
    t = me.dynamicsymbols._t
    T = (m * (x.diff(t)**2 + y.diff(t)**2) + I_spin * theta.diff(t)**2
         + I_turn * phi.diff(t)**2) / 2
    model = lg.Model("rolling_from_mechanics", coords=[x, y, phi, theta], T=T,
                     nonholonomic=rolling.slip)
    rows = derive_nonholonomic(model)
    A_ours, b_ours = rows["nh_A"], rows["nh_b"]
    cx, cy, cphi, cth = model.coords
    A_hand = sp.Matrix([[1, 0, 0, -R * sp.cos(cphi)], [0, 1, 0, -R * sp.sin(cphi)]])
    assert sp.simplify(A_ours - A_hand) == sp.zeros(2, 4)
    assert sp.simplify(b_ours) == sp.zeros(2, 1)


def test_bad_input_is_one_line():
    N = me.ReferenceFrame("N")
    W = N.orientnew("W", "Axis", [me.dynamicsymbols("a"), N.x])
    O = me.Point("O")
    with pytest.raises(ModelError, match="lies flat"):
        lg.rolling_contact(O, W, N.z, 1.0, N, N.z)
    with pytest.raises(ModelError, match="not constant"):
        lg.rolling_contact(O, W, N.y, 1.0, N, W.z)
