"""A 30-DoF humanoid as a branched joint tree: pelvis fixed to the world, a 2-DoF waist
(yaw, pitch) carrying the chest, a 2-DoF neck (yaw, pitch) carrying the head, two 7-DoF arms
on the chest (shoulder pitch, roll, yaw, elbow, wrist yaw, pitch, roll) and two 6-DoF legs on
the pelvis (hip yaw, roll, pitch, knee, ankle pitch, roll). Adult-sized link lengths and masses
(about 65 kg moving); inertia tensors about the mass centres are those of boxes of the links'
size turned by a few degrees, so every tensor is full.

URDF style (origins and axes in the parent joint's frame, every frame parallel to the world's
at q = 0, z up): lagrange_gen.model.joint_tree builds the 30 RigidBodies from TREE with
sympy.physics.mechanics, Pinocchio the same tree (lagrange_gen.bench.robots_peers). The
`robots` bench suite (`lagrange-gen bench robots`) generates it; build() only, no `model`:
running the file derives nothing until asked.
"""
import lagrange_gen as lg
from lagrange_gen.model.joint_tree import tree_bodies

#: joint: parent joint (-1: the fixed pelvis), axis and origin in the parent's frame (m);
#: mass (kg), com (m) in the body frame; inertia (ixx, iyy, izz, ixy, iyz, izx) about the com
TREE = [
    {"name": "waist_yaw", "parent": -1, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0, 0.1),
     "mass": 2.0, "com": (0, 0, 0.04), "inertia": (0.01667, 0.01214, 0.02536, 0.0001811, -0.0007695, 0.0003173)},
    {"name": "waist_pitch", "parent": 0, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, 0.08),
     "mass": 14.0, "com": (0.01, 0, 0.22), "inertia": (0.3562, 0.2623, 0.2084, -0.004725, 0.003032, 0.008992)},
    {"name": "neck_yaw", "parent": 1, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0, 0.46),
     "mass": 0.6, "com": (0, 0, 0.03), "inertia": (0.00064, 0.00064, 0.00064, -2.861e-21, 1.378e-21, -3.427e-22)},
    {"name": "neck_pitch", "parent": 2, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, 0.06),
     "mass": 4.5, "com": (0.02, 0, 0.11), "inertia": (0.02774, 0.03027, 0.02179, 0.0001064, -0.0004376, -0.0002922)},
    {"name": "l_shoulder_pitch", "parent": 1, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0.21, 0.38),
     "mass": 1.4, "com": (0, 0.05, 0), "inertia": (0.002333, 0.002333, 0.002333, 4.75e-21, -1.476e-21, 1.908e-20)},
    {"name": "l_shoulder_roll", "parent": 4, "type": "revolute", "axis": (1, 0, 0), "origin": (0, 0.07, 0),
     "mass": 0.6, "com": (0, 0.02, -0.03), "inertia": (0.00064, 0.00064, 0.00064, 6.117e-23, 1.87e-21, -2.955e-23)},
    {"name": "l_shoulder_yaw", "parent": 5, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0, -0.06),
     "mass": 1.9, "com": (0.005, 0, -0.12), "inertia": (0.01196, 0.01197, 0.002613, 2.308e-05, 0.0004082, -0.00053)},
    {"name": "l_elbow", "parent": 6, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.24),
     "mass": 1.2, "com": (0, 0, -0.11), "inertia": (0.006238, 0.006226, 0.001016, -1.712e-05, 0.000353, 0.0002539)},
    {"name": "l_wrist_yaw", "parent": 7, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0, -0.23),
     "mass": 0.4, "com": (0, 0, -0.02), "inertia": (0.0001667, 0.0001667, 0.0001667, 8.536e-22, 4.162e-22, -1.17e-22)},
    {"name": "l_wrist_pitch", "parent": 8, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.04),
     "mass": 0.3, "com": (0, 0, -0.01), "inertia": (0.0001025, 8.005e-05, 0.0001025, -6.943e-07, 8.541e-07, 2.642e-08)},
    {"name": "l_wrist_roll", "parent": 9, "type": "revolute", "axis": (1, 0, 0), "origin": (0, 0, -0.03),
     "mass": 0.5, "com": (0.01, 0, -0.07), "inertia": (0.001403, 0.00113, 0.0004088, 9.201e-06, -4.993e-05, 3.411e-05)},
    {"name": "r_shoulder_pitch", "parent": 1, "type": "revolute", "axis": (0, 1, 0), "origin": (0, -0.21, 0.38),
     "mass": 1.4, "com": (0, -0.05, 0), "inertia": (0.002333, 0.002333, 0.002333, 1.301e-20, -4.19e-22, -1.26e-20)},
    {"name": "r_shoulder_roll", "parent": 11, "type": "revolute", "axis": (1, 0, 0), "origin": (0, -0.07, 0),
     "mass": 0.6, "com": (0, -0.02, -0.03), "inertia": (0.00064, 0.00064, 0.00064, -1.409e-21, -3.946e-22, 5.571e-21)},
    {"name": "r_shoulder_yaw", "parent": 12, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0, -0.06),
     "mass": 1.9, "com": (0.005, 0, -0.12), "inertia": (0.01198, 0.01194, 0.002613, -1.175e-05, 0.0006497, 0.0001695)},
    {"name": "r_elbow", "parent": 13, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.24),
     "mass": 1.2, "com": (0, 0, -0.11), "inertia": (0.006239, 0.006239, 0.001001, -1.075e-05, 0.0002395, 0.0002355)},
    {"name": "r_wrist_yaw", "parent": 14, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0, -0.23),
     "mass": 0.4, "com": (0, 0, -0.02), "inertia": (0.0001667, 0.0001667, 0.0001667, 7.281e-23, -4.261e-22, -2.609e-21)},
    {"name": "r_wrist_pitch", "parent": 15, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.04),
     "mass": 0.3, "com": (0, 0, -0.01), "inertia": (0.0001025, 8.011e-05, 0.0001024, -2.95e-07, 1.51e-06, 1.988e-08)},
    {"name": "r_wrist_roll", "parent": 16, "type": "revolute", "axis": (1, 0, 0), "origin": (0, 0, -0.03),
     "mass": 0.5, "com": (0.01, 0, -0.07), "inertia": (0.001401, 0.001132, 0.0004091, 7.414e-06, -3.713e-05, 5.475e-05)},
    {"name": "l_hip_yaw", "parent": -1, "type": "revolute", "axis": (0, 0, 1), "origin": (0, 0.1, -0.06),
     "mass": 1.0, "com": (0, 0, -0.03), "inertia": (0.001367, 0.001367, 0.001666, -1.599e-07, -3.502e-06, 1.367e-05)},
    {"name": "l_hip_roll", "parent": 18, "type": "revolute", "axis": (1, 0, 0), "origin": (0, 0, -0.07),
     "mass": 1.3, "com": (0, 0.01, -0.02), "inertia": (0.002167, 0.002167, 0.002167, 1.718e-20, 2.106e-21, -1.05e-20)},
    {"name": "l_hip_pitch", "parent": 19, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.02),
     "mass": 6.5, "com": (0, 0, -0.19), "inertia": (0.1058, 0.1059, 0.02182, -0.0002928, 0.004766, 0.005182)},
    {"name": "l_knee", "parent": 20, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.42),
     "mass": 3.4, "com": (0, 0, -0.18), "inertia": (0.04872, 0.04876, 0.006903, -2.78e-06, -8.357e-05, -0.001392)},
    {"name": "l_ankle_pitch", "parent": 21, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.41),
     "mass": 0.3, "com": (0, 0, 0), "inertia": (0.000125, 0.000125, 0.000125, 9.383e-22, 9.451e-22, 3.938e-22)},
    {"name": "l_ankle_roll", "parent": 22, "type": "revolute", "axis": (1, 0, 0), "origin": (0, 0, -0.02),
     "mass": 1.2, "com": (0.04, 0, -0.05), "inertia": (0.00128, 0.006002, 0.006737, -0.000228, 3.173e-05, -0.000329)},
    {"name": "r_hip_yaw", "parent": -1, "type": "revolute", "axis": (0, 0, 1), "origin": (0, -0.1, -0.06),
     "mass": 1.0, "com": (0, 0, -0.03), "inertia": (0.001367, 0.001367, 0.001667, 4.635e-08, 2.509e-06, 5.539e-06)},
    {"name": "r_hip_roll", "parent": 24, "type": "revolute", "axis": (1, 0, 0), "origin": (0, 0, -0.07),
     "mass": 1.3, "com": (0, -0.01, -0.02), "inertia": (0.002167, 0.002167, 0.002167, -1.106e-20, 1.662e-20, -1.14e-20)},
    {"name": "r_hip_pitch", "parent": 25, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.02),
     "mass": 6.5, "com": (0, 0, -0.19), "inertia": (0.1059, 0.1058, 0.02187, -0.0003168, 0.005422, 0.004925)},
    {"name": "r_knee", "parent": 26, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.42),
     "mass": 3.4, "com": (0, 0, -0.18), "inertia": (0.04876, 0.04875, 0.006872, 1.775e-06, 0.0007908, -9.4e-05)},
    {"name": "r_ankle_pitch", "parent": 27, "type": "revolute", "axis": (0, 1, 0), "origin": (0, 0, -0.41),
     "mass": 0.3, "com": (0, 0, 0), "inertia": (0.000125, 0.000125, 0.000125, 7.896e-22, -9.247e-22, -1.311e-21)},
    {"name": "r_ankle_roll", "parent": 28, "type": "revolute", "axis": (1, 0, 0), "origin": (0, 0, -0.02),
     "mass": 1.2, "com": (0.04, 0, -0.05), "inertia": (0.001271, 0.006005, 0.006745, -0.0002065, 4.067e-05, -0.0002564)},
]


def build():
    g = lg.parameters("g", defaults=(9.81,))
    N, O, q, links = tree_bodies(TREE)          # world frame N (z up), pelvis point O
    T = lg.kinetic_energy(N, links)
    V = lg.gravity_potential(N, -g * N.z, links)  # sum of m g z of the mass centres
    return lg.Model("humanoid", coords=q, T=T, V=V, frame=N,
                    description="30-DoF humanoid tree: waist, neck, two 7-DoF arms, two 6-DoF legs.")
