"""A thin disk rolling without slipping on a horizontal plane, free to tilt (Routh's rolling
coin): contact point (x, y), heading psi, tilt theta from the vertical, spin angle phi about the
axle; radius R, mass m, moments I_diam about a diameter and I_axle about the axle (a uniform disk
by default: m R^2 / 4 and m R^2 / 2), gravity g along -z.

Orientation (z up): the lean frame L = Rz(psi) Rx(theta) holds the disk's plane (its x axis
horizontal, its y axis the axle), the disk turns by phi about the axle. The centre is R above the
contact along L's z axis, so the disk touches the plane by the choice of coordinates; rolling:
the disk's material point at the contact has no horizontal velocity (two nonholonomic
constraints, written in the heading's axes).

Rolling straight upright at the spin rate omega (speed R omega) is stable when
omega^2 > m g R I_diam / (I_axle (I_axle + m R^2)), g / (3 R) for a uniform disk
(tests/rolling/test_tilted_disk.py, from lagrange_gen.linearize_nonholonomic).
"""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x, y, psi, theta, phi = coordinates("x y psi theta phi")
m, R, I_diam, I_axle, g = parameters("m R I_diam I_axle g",
                                     defaults=(1.0, 0.5, 0.0625, 0.125, 9.81))
q = [x, y, psi, theta, phi]
qd = sp.Matrix([s.d for s in q])


def rot_x(a):
    return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])


def rot_z(a):
    return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])


e_x, e_y, e_z = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1])
R_yaw = rot_z(psi)
R_L = R_yaw * rot_x(theta)
centre = sp.Matrix([x, y, 0]) + R * R_L * e_z
v_centre = centre.jacobian(q) * qd
# the disk's angular velocity in L's axes (the inertia diag(I_diam, I_axle, I_diam) is the same
# in every frame turned about the axle, so the spin angle phi itself never enters)
w_L = rot_x(theta).T * (psi.d * e_z) + theta.d * e_x + phi.d * e_y
inertia = sp.diag(I_diam, I_axle, I_diam)
T = m * (v_centre.T * v_centre)[0, 0] / 2 + (w_L.T * inertia * w_L)[0, 0] / 2
V = m * g * centre[2]

slip = R_yaw.T * (v_centre + (R_L * w_L).cross(-R * R_L * e_z))
model = Model("tilted_disk", coords=q, T=T, V=V, nonholonomic=[slip[0], slip[1]],
              description="Disk rolling on a plane, free to tilt (Routh's rolling coin).")
