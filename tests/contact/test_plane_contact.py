"""Contact.point_on_plane: a sympy.physics.mechanics Point against a plane gives the gap, W_N and
W_T that the block on a ramp (models/block_on_ramp.py) writes by hand, derived here directly
(r . n, its gradient, d(slip)/d qdot) without derive/; bad input stays one line."""

import pytest
import sympy as sp
import sympy.physics.mechanics as me

from lagrange_gen import Contact, Model, ModelError, parameters
from lagrange_gen.derive.contacts import derive_contacts


def _ramp_model(tangent=True, friction=None):
    X, Y = me.dynamicsymbols("X Y")
    m, g, a, mu = parameters("m g a mu", defaults=(1.0, 9.81, 0.5, 0.3))
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", X * N.x + Y * N.y)
    normal = sp.sin(a) * N.x + sp.cos(a) * N.y
    along = sp.cos(a) * N.x - sp.sin(a) * N.y
    contact = Contact.point_on_plane(P, O, N, normal, along if tangent else None,
                                     restitution=0, friction=mu if friction is None else friction,
                                     name="ramp")
    model = Model("mech_ramp", coords=[X, Y],
                  T=m * (X.diff(me.dynamicsymbols._t)**2 + Y.diff(me.dynamicsymbols._t)**2) / 2,
                  V=m * g * Y, contacts=[contact])
    return model, a


def test_point_on_plane_matches_the_ramp_written_by_hand():
    model, a = _ramp_model()
    Xc, Yc = model.coords
    Xd, Yd = model.velocities
    out = derive_contacts(model)
    gap = Xc * sp.sin(a) + Yc * sp.cos(a)
    assert sp.simplify(out["contact_gap"][0] - gap) == 0
    assert sp.simplify(out["contact_WN"] - sp.Matrix([[sp.sin(a), sp.cos(a)]])) == sp.zeros(1, 2)
    # one tangent: its row, then the zero row of the second tangent
    assert sp.simplify(out["contact_WT"] - sp.Matrix([[sp.cos(a), -sp.sin(a)], [0, 0]])) \
        == sp.zeros(2, 2)
    assert out["contact_rate"] == sp.zeros(3, 1)          # a fixed plane: W is constant
    assert out["contact_bias"] == sp.zeros(3, 1)


def test_point_on_plane_with_friction_needs_a_tangent():
    with pytest.raises(ModelError, match="friction .* without a tangent"):
        _ramp_model(tangent=False)


def _incline(tangents):
    x, y, z = me.dynamicsymbols("x y z")
    m, g, a, mu = parameters("m g a mu", defaults=(1.0, 9.81, 0.3, 0.5))
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", x * N.x + y * N.y + z * N.z)
    normal = sp.sin(a) * N.x + sp.cos(a) * N.z
    pair = tangents(N, normal) if callable(tangents) else tangents
    contact = Contact.point_on_plane(P, O, N, normal, tangents=pair, friction=mu, name="incline")
    v = P.pos_from(O).dt(N)
    model = Model("incline", coords=[x, y, z], T=m * v.dot(v) / 2, V=m * g * z,
                  contacts=[contact])
    return model, a


def test_point_on_plane_with_the_frames_tangents_gives_the_3d_rows():
    """tangents="frame" on the plane with normal (sin a, 0, cos a): t1 = N.y (the axis of N
    with no normal component), t2 = n x N.y = (-cos a, 0, sin a); the rows written by hand."""
    model, a = _incline("frame")
    out = derive_contacts(model)
    assert sp.simplify(out["contact_WN"] - sp.Matrix([[sp.sin(a), 0, sp.cos(a)]])) == sp.zeros(1, 3)
    by_hand = sp.Matrix([[0, 1, 0], [-sp.cos(a), 0, sp.sin(a)]])
    assert sp.simplify(out["contact_WT"] - by_hand) == sp.zeros(2, 3)
    assert out["contact_rate"] == sp.zeros(3, 1)


def test_point_on_plane_refuses_tangents_that_are_not_orthonormal():
    with pytest.raises(ModelError, match=r"contact incline: the tangents must be orthonormal "
                                         r"and in the plane; t1 . normal = sin\(a\)"):
        _incline(lambda N, n: (N.x, N.y))
    with pytest.raises(ModelError, match=r"tangents must be a pair of Vectors or 'frame', got 1"):
        _incline(lambda N, n: (N.y,))
