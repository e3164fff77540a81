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
    assert sp.simplify(out["contact_WT"] - sp.Matrix([[sp.cos(a), -sp.sin(a)]])) == sp.zeros(1, 2)
    assert out["contact_rate"] == sp.zeros(2, 1)          # a plane: W is constant


def test_point_on_plane_with_friction_needs_a_tangent():
    with pytest.raises(ModelError, match="friction .* without a tangent"):
        _ramp_model(tangent=False)
