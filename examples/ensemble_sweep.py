"""Ensemble sweep: 400 cart pendulums over a grid of spring stiffness k and bob mass m, run in one
parallel numba loop (member i equals simulate with its inputs, bit for bit); the figure shows
the largest cart excursion over 5 s for each member.

    python examples/ensemble_sweep.py [OUT_DIR]     # writes OUT_DIR/ensemble_sweep.png
"""
import pathlib
import sys

import numpy as np
from matplotlib.figure import Figure

import lagrange_gen as lg

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

ks, ms = np.linspace(2.0, 40.0, 20), np.linspace(0.1, 2.0, 20)
ens = lg.ensemble("models/cart_pendulum.py", "rk4", q0=[0.0, 1.0],
                  params=lg.grid(k=ks, m=ms), t_end=5.0, h=1e-3, save_every=10)
print("q:", ens.q.shape, " failed members:", int((ens.status != 0).sum()))
reach = np.abs(ens.q[:, :, 0]).max(axis=1).reshape(len(ks), len(ms))   # grid: k slowest

fig = Figure(figsize=(6, 4.5), layout="constrained")
ax = fig.add_subplot()
image = ax.pcolormesh(ms, ks, reach, shading="auto")
fig.colorbar(image, ax=ax, label="max |x| over 5 s")
ax.set_xlabel("bob mass m")
ax.set_ylabel("spring stiffness k")
fig.savefig(out / "ensemble_sweep.png", dpi=90)
