"""Slider-crank with a clearance in the slider's guide (Flores, Leine, Glocker, Multibody Syst.
Dyn. 23 (2010) 165-190, Table 1; the Siconos example examples/Mechanics/SliderCrank).

Crank (length l1, angle q1) about the origin, connecting rod (length l2, angle q2) to the
centre of the slider, the slider (a rectangle 2a x 2b, angle q3) free to tilt and move across a
guide of height d = 2 (b + c): no holonomic constraint, the slider's centre is
(l1 cos q1 + l2 cos q2, l1 sin q1 + l2 sin q2). Its four corners meet the guide's walls:
corners 1, 2 (at -a, +a along the slider, +b across) the upper wall y = d / 2, corners 3, 4
(at -a, +a, -b) the lower wall y = -d / 2. Gravity along -y. Started from q = 0 with the crank
at 150 rad/s and the rod at -75 rad/s; the Siconos example runs it to t = 0.2 with
restitution 0.4 or 0.1, frictionless or mu = 0.01 (the defaults here: e = 0.4, mu = 0.01).

Near the crank's dead centres the slider crosses the clearance and two corners on one wall
touch together: the hard case of the contact solver (two nearly dependent rows)."""
import sympy as sp

from lagrange_gen import Contact, Model, coordinates, parameters

q1, q2, q3 = coordinates("q1 q2 q3")
l1, l2, a, b, c, m1, m2, m3, J1, J2, J3, g, e, mu = parameters(
    "l1 l2 a b c m1 m2 m3 J1 J2 J3 g e mu",
    defaults=(0.153, 0.306, 0.05, 0.025, 0.001, 0.038, 0.038, 0.076, 7.4e-5, 5.9e-4, 2.7e-6,
              9.81, 0.4, 0.01))

v = sp.Matrix([q1.d, q2.d, q3.d])
coupling = (m2 / 2 + m3) * l1 * l2 * sp.cos(q2 - q1)
H = sp.Matrix([[J1 + (m1 / 4 + m2 + m3) * l1**2, coupling, 0],
               [coupling, J2 + (m2 / 4 + m3) * l2**2, 0],
               [0, 0, J3]])
T = (v.T * H * v)[0] / 2
V = (m1 / 2 + m2 + m3) * g * l1 * sp.sin(q1) + (m2 / 2 + m3) * g * l2 * sp.sin(q2)

half = b + c                      # d / 2
xs, ys = l1 * sp.cos(q1) + l2 * sp.cos(q2), l1 * sp.sin(q1) + l2 * sp.sin(q2)


def corner(along, across):
    """(x, y) of the slider's corner at (along, across) in its own frame."""
    return (xs + along * sp.cos(q3) - across * sp.sin(q3),
            ys + along * sp.sin(q3) + across * sp.cos(q3))


def _contact(along, upper, name):
    x, y = corner(along, b if upper else -b)
    gap = half - y if upper else half + y
    slip = sum(sp.diff(x, s) * s.d for s in (q1, q2, q3))
    return Contact(gap=gap, restitution=e, friction=mu, slip=slip, name=name)


model = Model("slider_crank_clearance", coords=[q1, q2, q3], T=T, V=V,
              contacts=[_contact(-a, True, "corner1_upper"), _contact(a, True, "corner2_upper"),
                        _contact(-a, False, "corner3_lower"), _contact(a, False, "corner4_lower")],
              description="Slider-crank whose slider (2a x 2b) moves in a guide with clearance c "
                          "(Flores, Leine, Glocker 2010): four corner contacts.")
