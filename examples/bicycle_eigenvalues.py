"""The Whipple bicycle's eigenvalues against forward speed (the benchmark's Figure 3): the
nonlinear model models/bicycle.py linearized about upright straight running by
lagrange_gen.linearize_nonholonomic at each speed, the weave and capsize speeds by root finding.

    python examples/bicycle_eigenvalues.py [OUT_DIR]   # writes OUT_DIR/bicycle_eigenvalues.png
                                                       # (default docs/figures, the guide's)
"""
import sys
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.optimize import brentq  # noqa: E402

import lagrange_gen as lg  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
mod = lg.load(ROOT / "models" / "bicycle.py")
r_rear, r_front = mod.DEFAULT_PARAMS[list(mod.PARAMS).index("r_R")], \
    mod.DEFAULT_PARAMS[list(mod.PARAMS).index("r_F")]


def lean_steer_eigenvalues(v):
    """The four eigenvalues of lean and steer at the rear contact's speed v (m/s)."""
    q, qd = np.zeros(8), np.zeros(8)
    qd[0], qd[6], qd[7] = v, -v / r_rear, -v / r_front       # x' = v, wheels rolling
    lin = lg.linearize_nonholonomic(mod, q, qd, speeds=("phi", "delta", "theta_R"))
    rows, cols = [0, 1], [lin.coordinates.index("phi"), lin.coordinates.index("delta")]
    M, C, K = (lin.mass[np.ix_(rows, rows)], lin.damping[np.ix_(rows, rows)],
               lin.stiffness[np.ix_(rows, cols)])
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.linalg.eigvals(A)


def weave_real_part(v):
    return max(e.real for e in lean_steer_eigenvalues(v) if abs(e.imag) > 1e-9)


def capsize_eigenvalue(v):
    return min((e.real for e in lean_steer_eigenvalues(v) if abs(e.imag) <= 1e-9), key=abs)


v_weave = brentq(weave_real_part, 3.0, 5.0, xtol=1e-13)
v_capsize = brentq(capsize_eigenvalue, 5.5, 6.5, xtol=1e-13)
print(f"weave speed {v_weave:.12f} m/s, capsize speed {v_capsize:.12f} m/s")

speeds = np.linspace(0.0, 10.0, 401)
eig = np.array([np.sort_complex(lean_steer_eigenvalues(v)) for v in speeds])
fig, ax = plt.subplots(figsize=(7, 4.5))
ax.axvspan(v_weave, v_capsize, color="0.9", label="self-stable")
ax.plot(speeds, eig.real, ".", color="C0", ms=2)
ax.plot(speeds, np.abs(eig.imag), ".", color="C1", ms=2)
ax.plot([], [], ".", color="C0", label="real part")
ax.plot([], [], ".", color="C1", label="|imaginary part|")
ax.axhline(0.0, color="k", lw=0.5)
ax.set(xlim=(0, 10), ylim=(-10, 10), xlabel="forward speed v (m/s)", ylabel="eigenvalue (1/s)",
       title=f"Whipple bicycle (benchmark parameters): v_w = {v_weave:.4f}, "
             f"v_c = {v_capsize:.4f} m/s")
ax.legend(loc="lower left")
out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "figures"
out_dir.mkdir(parents=True, exist_ok=True)
fig.savefig(out_dir / "bicycle_eigenvalues.png", dpi=120, bbox_inches="tight")
print(f"weave speed {v_weave:.12f} m/s, capsize speed {v_capsize:.12f} m/s")
