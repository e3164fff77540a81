"""Energy and rolling constraint over long runs: nonholonomic_midpoint against nonholonomic_rk4
on the vertical rolling disk (models/rolling_disk.py, steady circular motion) and on the
Chaplygin sleigh in a harmonic well (models/sleigh_in_well.py). Both systems conserve the
energy exactly; the table shows max |E - E0| up to two times and max |A v + b| over the run.

    python examples/rolling_energy.py        # about a minute once the glue is compiled
"""
import math
from pathlib import Path

import numpy as np

import lagrange_gen as lg

ROOT = Path(__file__).resolve().parent.parent
R, SPIN, TURN, HEADING = 0.5, 4.0, 1.5, 0.3            # rolling_disk's radius, a steady motion
A, U, W, TH = 0.5, 0.5, 1.0, 0.3                       # sleigh: knife edge, speeds, heading
CASES = {
    "rolling_disk": ([0.0, 0.0, HEADING, 0.0],
                     [R * SPIN * math.cos(HEADING), R * SPIN * math.sin(HEADING), TURN, SPIN]),
    "sleigh_in_well": ([1.0, 0.0, TH], [U * math.cos(TH) - A * W * math.sin(TH),
                                        U * math.sin(TH) + A * W * math.cos(TH), W]),
}
T_END, EARLY = 10000.0, 200.0

print(f"{'model':15} {'method':22} {'h':>5} {'|dE| t<=200':>12} {'|dE| t<=1e4':>12} "
      f"{'max|Av+b|':>10}")
for name, (q0, v0) in CASES.items():
    mod = lg.load(ROOT / "models" / f"{name}.py")
    for method in ("nonholonomic_midpoint", "nonholonomic_rk4"):
        for h in (0.1, 0.05):
            traj = lg.simulate(mod, method, q0, v0, t_end=T_END, h=h, save_every=10)
            dE = np.abs(traj.energy - traj.energy[0])
            early = dE[traj.t <= EARLY].max()
            print(f"{name:15} {method:22} {h:5.2f} {early:12.2e} {dE.max():12.2e} "
                  f"{traj.saved['velocity_constraint_error'].max():10.1e}")
