"""First model, first plot: the cart pendulum of models/cart_pendulum.py (a pendulum hanging
from a cart on a spring), ten seconds with the midpoint variational integrator, and the
figure every Trajectory draws (coordinates, velocities, energy error).

    python examples/first_plot.py [OUT_DIR]      # writes OUT_DIR/first_plot.png (default out/)
"""
import pathlib
import sys

import lagrange_gen as lg

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

mod = lg.load("models/cart_pendulum.py")            # generates generated/cart_pendulum.py if needed
traj = lg.simulate(mod, "midpoint", q0=[0.1, 0.5], v0=[0.0, 0.0], t_end=10.0, h=1e-3,
                   save_every=10)
print(traj)
print("max |E - E0| =", traj.max_energy_error)      # bounded: midpoint is symplectic
traj.plot(out / "first_plot.png")
