"""Energy by method: the energy error of the double pendulum (a chaotic, conservative model)
over 20 s with the same step h = 0.01 for four methods. Explicit Euler gains energy without
bound; rk4 is accurate per step but its error creeps upward; midpoint and composition6 are
symplectic, so their energy error oscillates without a trend however long the run. At this h
midpoint (order 2) errs more than rk4 (order 4) over 20 s: bounded is not the same as small.

    python examples/energy_by_method.py [OUT_DIR]   # writes OUT_DIR/energy_by_method.png
"""
import pathlib
import sys

import numpy as np
from matplotlib.figure import Figure

import lagrange_gen as lg

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

mod = lg.load("models/double_pendulum.py")
fig = Figure(figsize=(8, 4), layout="constrained")
ax = fig.add_subplot()
for method in ("explicit_euler", "rk4", "midpoint", "composition6"):
    traj = lg.simulate(mod, method, q0=[2.0, 2.5], t_end=20.0, h=1e-2, save_every=5)
    error = np.abs(traj.energy - traj.energy[0])
    print(f"{method:15s} max |E - E0| = {error.max():.3e}")
    ax.semilogy(traj.t, np.maximum(error, 1e-17), lw=1, label=method)
ax.set_xlabel("t [s]")
ax.set_ylabel("|E - E0|")
ax.set_title("double pendulum, h = 0.01")
ax.legend()
fig.savefig(out / "energy_by_method.png", dpi=90)
