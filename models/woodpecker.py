"""The woodpecker toy (Glocker; the Siconos example examples/mechanics/Woodpecker of
siconos/siconos-tutorials, constants from its WoodPeckerConsts.h): a sleeve (mass m_M, inertia
J_M) with a hole slightly larger than the pole, and the bird (m_S, J_S) on a spiral spring
(c_phi) to the sleeve, going down the pole in a limit cycle of jamming and slipping.

Coordinates: the sleeve's height y, its angle phi_M and the bird's angle phi_S (small angles:
the mass matrix and the contacts are linear, as in the example). Contacts, Coulomb friction
mu = 0.3 on the pole: 1 the beak on the pole (gap l_M + l_G - l_S - r_O - h_S phi_S,
restitution 0.5, slip y' + l_M phi_M' + (l_G - l_S) phi_S'), 2 and 3 the sleeve's upper and
lower edges jamming on the pole (gaps r_M - r_O +- h_M phi_M, restitution 0, slip
y' + r_M phi_M'). Gravity along -y."""
import sympy as sp

from lagrange_gen import Contact, Model, coordinates, parameters

y, phi_M, phi_S = coordinates("y phi_M phi_S")
(r_O, r_M, h_M, l_M, l_G, h_S, l_S, m_M, m_S, J_M, J_S, c_phi, g, e_beak, e_sleeve,
 mu) = parameters("r_O r_M h_M l_M l_G h_S l_S m_M m_S J_M J_S c_phi g e_beak e_sleeve mu",
                  defaults=(0.0025, 0.0031, 0.0058, 0.010, 0.015, 0.02, 0.0201, 0.0003, 0.0045,
                            5.0e-9, 7.0e-7, 0.0056, 9.81, 0.5, 0.0, 0.3))

v = sp.Matrix([y.d, phi_M.d, phi_S.d])
H = sp.Matrix([[m_S + m_M, m_S * l_M, m_S * l_G],
               [m_S * l_M, J_M + m_S * l_M**2, m_S * l_M * l_G],
               [m_S * l_G, m_S * l_M * l_G, J_S + m_S * l_G**2]])
T = (v.T * H * v)[0] / 2
V = c_phi * (phi_M - phi_S)**2 / 2 + (m_S + m_M) * g * y + m_S * g * (l_M * phi_M + l_G * phi_S)

sleeve_slip = y.d + r_M * phi_M.d
model = Model("woodpecker", coords=[y, phi_M, phi_S], T=T, V=V,
              contacts=[Contact(gap=l_M + l_G - l_S - r_O - h_S * phi_S, restitution=e_beak,
                                friction=mu, slip=y.d + l_M * phi_M.d + (l_G - l_S) * phi_S.d,
                                name="beak"),
                        Contact(gap=r_M - r_O + h_M * phi_M, restitution=e_sleeve, friction=mu,
                                slip=sleeve_slip, name="sleeve_upper"),
                        Contact(gap=r_M - r_O - h_M * phi_M, restitution=e_sleeve, friction=mu,
                                slip=sleeve_slip, name="sleeve_lower")],
              description="Woodpecker toy (Glocker; Siconos' example): sleeve and bird on a "
                          "pole, three frictional contacts, a limit cycle of jams and slips.")
