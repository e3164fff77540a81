"""Bouncing ball, contact and impacts: the ball of models/bouncing_ball.py (gap y >= 0, Newton
restitution e = 0.8) stepped by moreau_jean, dropped from 1 m. The apex heights fall as
e^(2k) h0 and the ball comes to rest at the Zeno time sqrt(2 h0 / g) (1 + e) / (1 - e).

    python examples/bouncing_ball.py [OUT_DIR]      # writes OUT_DIR/bouncing_ball.png
"""
import pathlib
import sys

import numpy as np
from matplotlib.figure import Figure

import lagrange_gen as lg

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

h0, g, e = 1.0, 9.81, 0.8
traj = lg.simulate("models/bouncing_ball.py", "moreau_jean", q0=[h0], v0=[0.0], t_end=5.0,
                   h=1e-3)
t_rest = np.sqrt(2 * h0 / g) * (1 + e) / (1 - e)
moving = np.nonzero(np.abs(traj.v[:, 0]) > 1e-6)[0]
print(f"at rest from t = {traj.t[moving[-1]]:.3f} s (Zeno time {t_rest:.3f} s)")

fig = Figure(figsize=(8, 3.5), layout="constrained")
ax = fig.add_subplot()
ax.plot(traj.t, traj.q[:, 0], lw=1, label="y (moreau_jean, h = 1e-3)")
ax.plot([0.0, 5.0], [h0 * e**2] * 2, "k:", lw=1, label="first apex e^2 h0")
ax.axvline(t_rest, color="grey", lw=1, ls="--", label="Zeno time")
ax.set_xlabel("t [s]")
ax.set_ylabel("height [m]")
ax.legend()
fig.savefig(out / "bouncing_ball.png", dpi=90)
