"""Random kinematic trees for the differential tests and the harness: tables in the format of
lagrange_gen.model.joint_tree, drawn from a numpy Generator."""

from __future__ import annotations

__all__ = ["random_tree"]


def random_tree(rng, n, prismatic=0.3, aligned=0.0):
    """A random tree of ``n`` joints for the differential tests: random parents, unit axes
    (a coordinate axis with probability ``aligned``), offsets, masses and positive definite
    full inertia tensors (R diag(d) R^T with principal moments obeying the triangle
    inequality). ``rng`` a numpy Generator."""
    import numpy as np
    tree = []
    for i in range(n):
        if rng.random() < aligned:
            axis = np.eye(3)[rng.integers(3)]
        else:
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
        d = rng.uniform(0.02, 0.2, size=3)
        d[2] = rng.uniform(abs(d[0] - d[1]) + 0.005, d[0] + d[1] - 0.005)
        R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        I = R @ np.diag(d) @ R.T
        tree.append({"name": f"j{i}", "parent": int(rng.integers(-1, i)) if i else -1,
                     "type": "prismatic" if rng.random() < prismatic else "revolute",
                     "axis": [round(float(a), 12) for a in axis],
                     "origin": [round(float(c), 12) for c in rng.uniform(-0.5, 0.5, size=3)],
                     "mass": round(float(rng.uniform(0.5, 3.0)), 12),
                     "com": [round(float(c), 12) for c in rng.uniform(-0.3, 0.3, size=3)],
                     "inertia": [round(float(c), 12) for c in
                                 (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[2, 0])]})
    return tree
