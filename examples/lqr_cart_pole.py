"""LQR on the inverted cart pole: A, B from lagrange_gen.linearize, the gains from scipy's
continuous algebraic Riccati equation, the controller jitted and run inside simulate's loop.
The pole starts 0.25 rad from upright with the cart 0.5 m off; the controller brings both back.
The gains reach the controller as data (control_params), so trying two weightings compiles the
loop once.

    python examples/lqr_cart_pole.py [OUT_DIR]   # prints the final state and the peak force,
                                                 # writes OUT_DIR/lqr_cart_pole.png (default out/)
"""
import pathlib
import sys

import numba
import numpy as np
import scipy.linalg
from matplotlib.figure import Figure

import lagrange_gen as lg

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

mod = lg.load("models/cart_pole.py")                       # inputs=[u], outputs cart, tip_x
q_eq = lg.equilibrium(mod, [0.0, 0.1], u=[0.0])             # Newton on the forces: theta = 0
A, B, C, D = lg.linearize(mod, q_eq, [0.0, 0.0], u=[0.0])   # exact derivatives, (4, 4), (4, 1)


def lqr_gain(weights):
    """K (4,) of u = -K (q, qd) for the state weights (4,) and a unit input weight."""
    P = scipy.linalg.solve_continuous_are(A, B, np.diag(weights), np.eye(1))
    return (B.T @ P)[0]


@numba.njit
def lqr(t, q, qd, p, K):                                    # K = control_params
    return -(K[0] * q[0] + K[1] * q[1] + K[2] * qd[0] + K[3] * qd[1])


runs = {}
for label, weights in (("cart weight 10", [10.0, 100.0, 1.0, 1.0]),
                       ("cart weight 100", [100.0, 100.0, 1.0, 1.0])):
    runs[label] = lg.simulate(mod, "midpoint", q0=[0.5, 0.25], t_end=10.0, h=1e-2,
                              control=lqr, control_params=lqr_gain(weights))
    traj = runs[label]
    print(f"{label}: final q {traj.q[-1]}, peak |u| {np.abs(traj.saved['input_u']).max():.2f} N,"
          f" tip_x(10 s) {traj.saved['output_tip_x'][-1, 0]:.2e} m")

fig = Figure(figsize=(8, 5), layout="constrained")
top, bottom = fig.subplots(2, 1, sharex=True)
for i, (label, traj) in enumerate(runs.items()):
    style = "-" if i == 0 else "--"
    top.plot(traj.t, traj.q[:, 0], style, lw=1, color="C0", label=f"cart x [m], {label}")
    top.plot(traj.t, traj.q[:, 1], style, lw=1, color="C1", label=f"pole theta [rad], {label}")
    bottom.plot(traj.t, traj.saved["input_u"][:, 0], style, lw=1, color="C2", label=label)
top.legend(fontsize=7)
bottom.legend(fontsize=7)
bottom.set_ylabel("force u [N]")
bottom.set_xlabel("t [s]")
fig.savefig(out / "lqr_cart_pole.png", dpi=90)
