"""UR5-like 6-DoF arm as a joint tree (URDF style: joint origins and axes, not DH matrices).

Kinematics and masses are those of the UR5 in ros-industrial's ur_description (Universal
Robots' published parameters: d1 = 0.089159, shoulder offset 0.13585, elbow offset -0.1197,
a2 = 0.425, a3 = 0.39225, d4 - offsets = 0.093, d5 = 0.09465; link masses 3.7, 8.393, 2.275,
1.219, 1.219, 0.1879 kg). The URDF's fixed rotations rpy = (0, pi/2, 0) before shoulder_lift and
wrist_1 turn about the joint's own axis y, so they are folded into the zero of those angles:
q_shoulder_lift = q_urdf + pi/2, q_wrist_1 = q_urdf + pi/2, and every frame is parallel to the
base at q = 0. Centres of mass as in ur_description's link frames; inertia tensors about them are
the URDF's cylinders turned by a few degrees, so that every tensor is full (products of inertia
nonzero) as on the real links.

Each joint angle is a ``me.dynamicsymbols`` coordinate; T is the kinetic energy of the six
RigidBodies (lagrange_gen.model.joint_tree builds them from TREE with orientnew/locatenew),
gravity -g N.z a potential. Pinocchio builds the same arm from TREE
(lagrange_gen.bench.robots_peers.pinocchio_model).
"""
import lagrange_gen as lg
from lagrange_gen.model.joint_tree import tree_bodies

#: joint: parent joint (-1: the base), axis and origin in the parent's frame (m); mass (kg),
#: com (m) in the body frame; inertia (ixx, iyy, izz, ixy, iyz, izx) about the com (kg m^2)
TREE = [
    {"name": "shoulder_pan", "parent": -1, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0, 0.089159),
     "mass": 3.7, "com": (0, 0.00193, -0.02561), "inertia": (0.01025, 0.01026, 0.006692, -1.478e-05, 0.000188, 0.0002811)},
    {"name": "shoulder_lift", "parent": 0, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0.13585, 0),
     "mass": 8.393, "com": (0, -0.024201, 0.2125), "inertia": (0.1324, 0.1325, 0.01798, -0.001432, 0.01253, 0.01325)},
    {"name": "elbow", "parent": 1, "type": "revolute", "axis": (0, 1, 0), "origin": (0, -0.1197, 0.425),
     "mass": 2.275, "com": (0, 0.0265, 0.11993), "inertia": (0.03066, 0.0305, 0.005374, -0.0006342, 0.004315, 0.003798)},
    {"name": "wrist_1", "parent": 2, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, 0.39225),
     "mass": 1.219, "com": (0, 0.110949, 0.01634), "inertia": (0.002549, 0.002542, 0.002222, -1.367e-05, 7.747e-05, 5.955e-05)},
    {"name": "wrist_2", "parent": 3, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0.093, 0),
     "mass": 1.219, "com": (0, 0.0018, 0.11099), "inertia": (0.002547, 0.002531, 0.002236, -1.947e-05, 9.604e-05, 6.565e-05)},
    {"name": "wrist_3", "parent": 4, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, 0.09465),
     "mass": 0.1879, "com": (0, 0.001159, 0), "inertia": (8.672e-05, 9.011e-05, 0.0001247, 3.315e-06, -1.472e-05, -9.006e-06)},
]


def build():
    g = lg.parameters("g", defaults=(9.81,))
    N, O, q, links = tree_bodies(TREE)          # base frame N (z up), base point O, 6 angles
    T = lg.kinetic_energy(N, links)
    V = lg.gravity_potential(N, -g * N.z, links)  # sum of m g z of the mass centres
    return lg.Model("ur5", coords=q, T=T, V=V, frame=N,
                    description="UR5-like 6-DoF arm, full inertia tensors, gravity -g z.")
