"""Whipple bicycle: rear frame with rider (B), front frame (H: fork and handlebar), two knife-edge
wheels (R, F) rolling without slipping on a horizontal plane, with the benchmark parameters of
Meijaard, Papadopoulos, Ruina and Schwab, "Linearized dynamics equations for the balance and
steer of a bicycle: a benchmark and review", Proc. R. Soc. A 463 (2007) 1955-1982, Table 1.

Axes as in the benchmark: x forward, y to the right, z down; gravity +g z. Coordinates: the rear
contact point (x, y), yaw psi, lean (roll) phi, pitch theta of the rear frame (yaw-lean-pitch:
R_B = Rz(psi) Rx(phi) Ry(theta)), steer delta about the steering axis (tilted back by lambda
from the downward vertical, fixed in B), the rear wheel's rotation theta_R relative to B and the
front wheel's theta_F relative to H. Positive lean is to the right, positive steer turns right.

In the reference configuration (every angle zero) both wheels touch the ground, the contacts are
the wheelbase w apart and the steering axis meets the ground the trail c ahead of the front
contact. The mass centres and central inertias of B and H are the table's, given in these axes
(a planar xz-symmetric frame: I_xx, I_xz, I_zz, I_yy); a wheel is a disk with I_xx = I_zz about
its diameters and I_yy about its axle.

Constraints:
  - holonomic (1): the front wheel touches the ground. Its lowest point is the centre plus r_F
    times the unit vector of the wheel plane closest to the downward vertical, whose height is
    sqrt(1 - a_z^2) for the axle direction a: z(front centre) + r_F sqrt(1 - a_z^2) = 0 (it
    fixes the pitch theta given lean and steer). The rear wheel touches the ground by the choice
    of coordinates (its centre is r_R above (x, y) along the lean frame's z).
  - nonholonomic (4): the material point of each wheel at its contact has no horizontal
    velocity (the vertical components follow from the holonomic constraint), written in the
    yawed frame's axes (forward, sideways) so that the rows stay short.

lagrange_gen.linearize_nonholonomic about upright straight running at speed v (rear contact
speed, theta_R' = -v / r_R) with independent speeds (phi', delta', theta_R') gives the
benchmark's M q'' + v C1 q' + (g K0 + v^2 K2) q = 0 in q = (phi, delta) (tests/rolling/
test_bicycle_benchmark.py, docs/guides/rolling.md).
"""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x, y, psi, phi, theta, delta, theta_R, theta_F = coordinates(
    "x y psi phi theta delta theta_R theta_F")
(w, c, lam, g, r_R, m_R, IR_xx, IR_yy, x_B, z_B, m_B, IB_xx, IB_xz, IB_zz, IB_yy,
 x_H, z_H, m_H, IH_xx, IH_xz, IH_zz, IH_yy, r_F, m_F, IF_xx, IF_yy) = parameters(
    "w c lam g r_R m_R IR_xx IR_yy x_B z_B m_B IB_xx IB_xz IB_zz IB_yy "
    "x_H z_H m_H IH_xx IH_xz IH_zz IH_yy r_F m_F IF_xx IF_yy",
    defaults=(1.02, 0.08, float(sp.pi / 10), 9.81, 0.3, 2.0, 0.0603, 0.12,
              0.3, -0.9, 85.0, 9.2, 2.4, 2.8, 11.0,
              0.9, -0.7, 4.0, 0.05892, -0.00756, 0.00708, 0.06,
              0.35, 3.0, 0.1405, 0.28))


def rot_x(a):
    return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])


def rot_y(a):
    return sp.Matrix([[sp.cos(a), 0, sp.sin(a)], [0, 1, 0], [-sp.sin(a), 0, sp.cos(a)]])


def rot_z(a):
    return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])


q = [x, y, psi, phi, theta, delta, theta_R, theta_F]
qd = sp.Matrix([s.d for s in q])


def velocity(point):
    """d point/dt (3, 1) of a position (3, 1) in ground axes."""
    return point.jacobian(q) * qd


e_x, e_y, e_z = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1])

# Orientations (body axes -> ground axes): yaw, lean (L: the rear wheel's plane, x horizontal),
# pitch (B), steer about the axis u fixed in B (H).
R_yaw = rot_z(psi)
R_L = R_yaw * rot_x(phi)
R_B = R_L * rot_y(theta)
steer = rot_y(lam) * rot_z(delta) * rot_y(-lam)       # rotation by delta about u (B axes)
R_H = R_B * steer
u_axis = rot_y(lam) * e_z                             # (sin lam, 0, cos lam): downward axis

# Angular velocities in body axes.
w_L = rot_x(phi).T * (psi.d * e_z) + phi.d * e_x
w_B = rot_y(theta).T * w_L + theta.d * e_y
w_R = w_B + theta_R.d * e_y                           # the rear wheel, in B axes
w_H = steer.T * w_B + delta.d * u_axis
w_F = w_H + theta_F.d * e_y                           # the front wheel, in H axes

# Points (ground axes): rear wheel centre, the steering axis' point on the ground in the
# reference configuration, mass centres, front wheel centre (offsets from the rear wheel centre
# in B axes at the reference configuration).
P_R = sp.Matrix([x, y, 0]) - r_R * R_L * e_z
axis_point = sp.Matrix([w + c, 0, r_R])
P_B = P_R + R_B * sp.Matrix([x_B, 0, z_B + r_R])
P_axis = P_R + R_B * axis_point
P_H = P_axis + R_H * (sp.Matrix([x_H, 0, z_H + r_R]) - axis_point)
P_F = P_axis + R_H * (sp.Matrix([w, 0, r_R - r_F]) - axis_point)

I_B = sp.Matrix([[IB_xx, 0, IB_xz], [0, IB_yy, 0], [IB_xz, 0, IB_zz]])
I_H = sp.Matrix([[IH_xx, 0, IH_xz], [0, IH_yy, 0], [IH_xz, 0, IH_zz]])
I_R = sp.diag(IR_xx, IR_yy, IR_xx)
I_F = sp.diag(IF_xx, IF_yy, IF_xx)


def kinetic(mass, point, inertia, omega):
    v = velocity(point)
    return mass * (v.T * v)[0, 0] / 2 + (omega.T * inertia * omega)[0, 0] / 2


T = (kinetic(m_R, P_R, I_R, w_R) + kinetic(m_B, P_B, I_B, w_B)
     + kinetic(m_H, P_H, I_H, w_H) + kinetic(m_F, P_F, I_F, w_F))
V = -g * (m_R * P_R[2] + m_B * P_B[2] + m_H * P_H[2] + m_F * P_F[2])   # z down

# Front contact: the front wheel's lowest point (axle a, unit; the in-plane unit vector closest
# to the downward vertical is (e_z - a_z a) / sqrt(1 - a_z^2)).
axle_F = R_H * e_y
down_F = sp.sqrt(1 - axle_F[2]**2)
to_contact_F = r_F * (e_z - axle_F[2] * axle_F) / down_F
front_touches = P_F[2] + r_F * down_F


def contact_slip(centre, omega_ground, to_contact):
    """Horizontal velocity (forward, sideways in the yawed axes) of the wheel's material point
    at its contact."""
    v = R_yaw.T * (velocity(centre) + omega_ground.cross(to_contact))
    return [v[0], v[1]]


rear_slip = contact_slip(P_R, R_B * w_R, r_R * R_L * e_z)
front_slip = contact_slip(P_F, R_H * w_F, to_contact_F)

model = Model("bicycle", coords=q, T=T, V=V,
              constraints=[front_touches],
              nonholonomic=rear_slip + front_slip,
              description="Whipple bicycle, benchmark parameters (Meijaard et al. 2007).")
