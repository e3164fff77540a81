"""Spatial serial chain of n rigid links hanging from a fixed base, joint axes alternating z and
y (yaw, pitch, yaw, ...), link lengths, lateral offsets, masses, centres of mass and full inertia
tensors varying from link to link: the 3D counterpart of models/n_link_pendulum.py, whose
kinetic energy does not stay a short sum of cosines of angle differences.

    lagrange-gen models/spatial_chain.py --set n=8     # generated/spatial_chain_8.py

Written as a robotics engineer writes a robot: the joint table TREE (URDF style: the joint's
origin and axis in the parent link's frame; mass, com and inertia (ixx, iyy, izz, ixy, iyz, izx)
about the com in the link's frame), built into sympy.physics.mechanics frames, points and
RigidBodies (lagrange_gen.model.joint_tree.tree_bodies), T = lg.kinetic_energy(N, links) and
gravity -g N.z as the potential. The same TREE builds the chain in Pinocchio
(lagrange_gen.bench.robots_peers). build() only: running the file derives nothing.
"""
import math

import lagrange_gen as lg
from lagrange_gen.model.joint_tree import tree_bodies


def chain_tree(n=12):
    """The joint table of the n-link chain (plain data: a list of dicts)."""
    n = int(n)
    if n < 1:
        raise ValueError(f"spatial_chain: n must be >= 1, got {n}")
    lengths = [round(0.25 + 0.05 * math.sin(1.3 * i + 0.4), 4) for i in range(n)]
    tree = []
    for i in range(n):
        s, c = math.sin(1.3 * i + 0.4), math.cos(0.7 * i + 0.2)
        mass = round(1.6 - 0.04 * i + 0.2 * c, 4)
        ixx, iyy, izz = (round(mass * v, 5) for v in (0.0062 + 0.0004 * c, 0.006 - 0.0003 * s, 0.0012))
        tree.append({
            "name": f"link{i + 1}", "parent": i - 1, "type": "revolute",
            "axis": (0, 0, 1) if i % 2 == 0 else (0, 1, 0),
            # the joint sits at the end of the previous link (which hangs down -z), a little off-axis
            "origin": (0, 0, 0) if i == 0 else (round(0.02 * c, 4), round(0.015 * s, 4), -lengths[i - 1]),
            "mass": mass,
            "com": (round(0.01 * s, 4), round(-0.008 * c, 4), round(-0.5 * lengths[i], 4)),
            "inertia": (ixx, iyy, izz, round(0.04 * ixx * s, 6), round(0.05 * iyy * c, 6),
                        round(-0.03 * izz * (s + c), 6)),
        })
    return tree


TREE = chain_tree(12)


def build(n=12):
    n = int(n)
    tree = TREE if n == 12 else chain_tree(n)
    g = lg.parameters("g", defaults=(9.81,))
    N, O, q, links = tree_bodies(tree)          # base frame N (z up), base point O, n angles
    T = lg.kinetic_energy(N, links)
    V = lg.gravity_potential(N, -g * N.z, links)  # sum of m g z of the mass centres
    return lg.Model(f"spatial_chain_{n}", coords=q, T=T, V=V, frame=N,
                    description=f"Spatial {n}-link chain, joint axes alternating z/y, full inertias.")
