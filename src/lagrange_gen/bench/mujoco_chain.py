"""MuJoCo's stepping cost on the chain of models/n_link_pendulum.py, for `bench speed`.

The MJCF chain: n bodies, each hinged (axis y, relative angle) at the end of the previous link,
its point mass m at distance l below the hinge (a tiny diagonal inertia, since MuJoCo needs a
positive one), gravity g along -z, no contacts, no damping, no actuators. Relative angles phi
and the model's absolute angles th are related by th_k = phi_1 + ... + phi_k (the hinge axis
is chosen so that the signs agree); ``equivalence`` checks this against our own run.

MuJoCo steps with mj_step at the integrator asked (Euler or RK4). Two timings: a C loop
(mujoco.rollout, the cost of the step itself) and a Python loop of mj_step calls (what a
Python user writes; includes the binding overhead).
"""

from __future__ import annotations

import importlib.util
import time

import numpy as np

POINT_INERTIA = 1e-12         # kg m^2: MuJoCo needs a positive inertia; 1e-9 already moves
#                               the state by 1e-8 in 1000 steps (equivalence), 1e-12 by 1e-11


def available():
    return importlib.util.find_spec("mujoco") is not None


def chain_xml(n, m=1.0, l=1.0, g=9.81, h=1e-3, integrator="Euler"):
    """MJCF text of the n-link chain (see the module docstring)."""
    body = ""
    for k in reversed(range(n)):
        pos = "0 0 0" if k == 0 else f"0 0 {-l}"
        body = (f'<body name="link{k}" pos="{pos}">'
                f'<joint name="hinge{k}" type="hinge" axis="0 -1 0"/>'
                f'<inertial pos="0 0 {-l}" mass="{m}" diaginertia="{POINT_INERTIA} '
                f'{POINT_INERTIA} {POINT_INERTIA}"/>{body}</body>')
    return (f'<mujoco model="chain{n}"><compiler angle="radian"/>'
            f'<option timestep="{h}" gravity="0 0 {-g}" integrator="{integrator}">'
            f'<flag contact="disable"/></option><worldbody>{body}</worldbody></mujoco>')


def _model(n, h, integrator, params):
    import mujoco
    m, l, g = params
    model = mujoco.MjModel.from_xml_string(chain_xml(n, m, l, g, h, integrator))
    return model, mujoco.MjData(model)


def _set_absolute(data, th, thd):
    """Set MuJoCo's relative angles from absolute ones th (n,), thd (n,)."""
    data.qpos[:] = np.diff(np.concatenate(([0.0], th)))
    data.qvel[:] = np.diff(np.concatenate(([0.0], thd)))


def run_steps(n, h, integrator, params, th0, thd0, steps):
    """(th, thd) absolute angles and rates after ``steps`` mj_step calls from (th0, thd0)."""
    import mujoco
    model, data = _model(n, h, integrator, params)
    _set_absolute(data, th0, thd0)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return np.cumsum(data.qpos), np.cumsum(data.qvel)


def ns_per_step(n, h, integrator, params, th0, thd0, steps=20_000, repeats=3):
    """{"c_loop": ns per step in mujoco.rollout, "python_loop": ns per mj_step call from a
    Python loop}, best of ``repeats``."""
    import mujoco
    from mujoco import rollout
    model, data = _model(n, h, integrator, params)
    _set_absolute(data, th0, thd0)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    out = np.empty((1, steps, state0.size))
    rollout.rollout(model, data, state0[None], nstep=steps, state=out)     # warm-up
    best_c = best_py = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        rollout.rollout(model, data, state0[None], nstep=steps, state=out)
        best_c = min(best_c, time.perf_counter() - start)
        mujoco.mj_setState(model, data, state0, spec)
        step = mujoco.mj_step
        start = time.perf_counter()
        for _ in range(steps):
            step(model, data)
        best_py = min(best_py, time.perf_counter() - start)
    return {"c_loop": 1e9 * best_c / steps, "python_loop": 1e9 * best_py / steps}


def equivalence(mod, params, th0, h=1e-3, steps=1000):
    """Max abs difference of the final absolute angles and rates between MuJoCo's RK4 and our
    rk4 (same h, same start at rest): small when the MJCF chain is the model's chain."""
    from ..run.simulate import simulate
    n = mod.N_COORDS
    ours = simulate(mod, "rk4", th0, np.zeros(n), t_end=steps * h, h=h, save_every=steps)
    th, thd = run_steps(n, h, "RK4", params, np.asarray(th0), np.zeros(n), steps)
    return float(max(np.abs(th - ours.q[-1]).max(), np.abs(thd - ours.v[-1]).max()))
