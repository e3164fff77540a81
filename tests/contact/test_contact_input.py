"""Contact input: the one-line ModelError of each bad contact, and which methods apply."""

import pytest
import sympy as sp

from lagrange_gen import Contact, Model, ModelError, coordinates, parameters, t
from lagrange_gen.steppers.core import registry


def _ball(**contact):
    y = coordinates("y")
    m, g = parameters("m g", defaults=(1.0, 9.81))
    contact = {"gap": y, **contact}
    contact = {k: (v(y) if callable(v) else v) for k, v in contact.items()}
    return Model("ball", coords=[y], T=m * y.d**2 / 2, V=m * g * y, contacts=[Contact(**contact)])


def test_a_good_contact_is_accepted():
    model = _ball(restitution=0.5, friction=0.0)
    assert model.n_contacts == 1 and model.contacts[0].name == "contact_0"


def test_rheonomic_gaps_and_slip_pairs_are_accepted():
    """A moving surface (gap and slips depending on t) and a pair of slip velocities (3D)."""
    model = _ball(gap=lambda y: y - sp.sin(t), friction=0.3,
                  slip=lambda y: (y.d - sp.cos(t), 2 * y.d))
    contact = model.contacts[0]
    assert len(contact.slips) == 2 and contact.slip == contact.slips


@pytest.mark.parametrize("contact, message", [
    (dict(restitution=-0.1), r"contact contact_0: restitution must be in \[0, 1\], got -0.1"),
    (dict(restitution=1.5), r"restitution must be in \[0, 1\], got 1.5"),
    (dict(friction=-0.2, slip=lambda y: y.d), r"friction must be >= 0, got -0.2"),
    (dict(friction=0.3), r"friction 0.3 without a tangent: give slip="),
    (dict(gap=sp.Integer(2)), r"the gap 2 does not depend on any coordinate \(y\)"),
    (dict(gap=lambda y: y.d), r"the gap y_dot depends on velocities"),
    (dict(gap=lambda y: sp.sin(t)), r"the gap sin\(t\) does not depend on any coordinate \(y\)"),
    (dict(friction=0.3, slip=lambda y: (y.d,)), r"slip must be one slip velocity \(2D\) or a "
                                                r"pair \(u1, u2\) \(3D\), got 1 of them"),
    (dict(friction=0.3, slip=lambda y: (y.d, y.d, y.d)), r"or a pair \(u1, u2\) \(3D\), got 3"),
    (dict(friction=0.3, slip=lambda y: (y.d, y * y.d**2)), r"the slip y\*y_dot\*\*2 is not linear"),
    (dict(friction=0.3, slip=lambda y: (y.d, y)), r"the slip y does not depend on any velocity"),
    (dict(friction=0.3, slip=()), r"got 0 of them"),
    (dict(friction=0.3, slip=lambda y: y.d**2), r"the slip y_dot\*\*2 is not linear"),
    (dict(friction=0.3, slip=lambda y: y), r"the slip y does not depend on any velocity"),
])
def test_bad_contact_is_one_line_naming_it(contact, message):
    with pytest.raises(ModelError, match=message) as info:
        _ball(**contact)
    assert "\n" not in str(info.value) and "model ball" in str(info.value)


def test_restitution_from_a_parameter_default_is_checked():
    e = parameters("e", defaults=(2.0,))
    with pytest.raises(ModelError, match=r"restitution must be in \[0, 1\], got e = 2"):
        _ball(restitution=e)


def test_not_a_contact_is_refused():
    y = coordinates("y")
    with pytest.raises(ModelError, match="contact 0 is int, not Contact"):
        Model("ball", coords=[y], T=y.d**2 / 2, contacts=[3])


def test_only_the_contact_methods_apply_to_contacts_and_not_elsewhere():
    assert registry.applicable_methods(0, 0, 1) == ("moreau_jean", "spook_contacts",
                                                    "dop853_impacts")
    # with holonomic constraints too: all three (rows of the step's system; dop853_impacts' KKT
    # system between switches)
    assert registry.applicable_methods(1, 0, 1) == ("moreau_jean", "spook_contacts",
                                                    "dop853_impacts")
    # velocity constraints beside contacts: moreau_jean alone
    assert registry.applicable_methods(0, 0, 1, 1) == ("moreau_jean",)
    assert "nonholonomic constraints beside contacts" in registry.inapplicable(
        "dop853_impacts", 1, 0, 1, 1)
    assert "nonsmooth elements" in registry.inapplicable("moreau_jean", 0, 1, 1)
    assert "moreau_jean" not in registry.applicable_methods(0, 0, 0)
    assert "dop853_impacts" not in registry.applicable_methods(0, 0, 0)
    assert "unilateral contacts" in registry.inapplicable("verlet", 0, 0, 2)
    assert "has none" in registry.inapplicable("moreau_jean", 0, 0, 0)
