"""Pipeline cost: derive + emit, first numba compile, cached re-import, against sympy.physics.mechanics.

Every phase that involves numba's cache runs in a fresh subprocess with its own NUMBA_CACHE_DIR,
so "first compile" really starts cold and "cached" really starts a new interpreter.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
import numba, numpy  # noqa: F401  (imports are timed separately from the module)
t1 = time.perf_counter()
from lagrange_gen.run.loader import import_generated, compile_all
mod = import_generated(sys.argv[1])
t2 = time.perf_counter()
compile_all(mod)
t3 = time.perf_counter()
print(json.dumps({"imports": t1 - t0, "module_import": t2 - t1, "kernels": t3 - t2}))
"""


def _child(path, cache_dir):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir))
    out = subprocess.run([sys.executable, "-c", _CHILD, str(path)], env=env,
                         capture_output=True, text=True)
    if out.returncode != 0:
        last = (out.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"bench child for {path} failed: {last}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure_ours(model_file, options=None):
    """dict of seconds: derive_emit, first_compile (cold cache), cached (module import + kernel
    load with a warm cache, beyond numba/numpy imports)."""
    from ..codegen import generate_model
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        result = generate_model(model_file, Path(tmp) / "gen", options=options or {})
        derive_emit = time.perf_counter() - start
        cache = Path(tmp) / "numba_cache"
        cold = _child(result.path, cache)
        warm = _child(result.path, cache)
        lines = result.path.read_text().count("\n")
    return {"derive_emit": derive_emit, "first_compile": cold["module_import"] + cold["kernels"],
            "cached": warm["module_import"] + warm["kernels"], "lines": lines}


def _sympy_cart_pendulum():
    import sympy as sp
    from sympy.physics import mechanics as me
    x, th = me.dynamicsymbols("x theta")
    M, m, l, k, g = sp.symbols("M m l k g")
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    cart = O.locatenew("C", x * N.x)
    cart.set_vel(N, x.diff() * N.x)
    bob = cart.locatenew("B", l * sp.sin(th) * N.x - l * sp.cos(th) * N.y)
    bob.set_vel(N, bob.pos_from(O).dt(N))
    cart_particle, bob_particle = me.Particle("Pc", cart, M), me.Particle("Pb", bob, m)
    cart_particle.potential_energy = k * x**2 / 2
    bob_particle.potential_energy = -m * g * l * sp.cos(th)
    return me.Lagrangian(N, cart_particle, bob_particle), [x, th]


def _sympy_n_link(n):
    """The same chain as models/n_link_pendulum.py: absolute angles, equal point masses."""
    import sympy as sp
    from sympy.physics import mechanics as me
    q = me.dynamicsymbols(f"q1:{n + 1}")
    m, l, g = sp.symbols("m l g")
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    prev, particles = O, []
    for i in range(n):
        Ai = N.orientnew(f"A{i}", "Axis", [q[i], N.z])
        Ai.set_ang_vel(N, q[i].diff() * N.z)
        Pi = prev.locatenew(f"P{i}", -l * Ai.y)
        Pi.v2pt_theory(prev, N, Ai)
        particle = me.Particle(f"Pa{i}", Pi, m)
        particle.potential_energy = m * g * Pi.pos_from(O).dot(N.y)
        particles.append(particle)
        prev = Pi
    return me.Lagrangian(N, *particles), q


def measure_sympy(system):
    """Seconds for sympy.physics.mechanics LagrangesMethod: form_lagranges_equations plus the
    mass matrix and forcing vector (what a user needs to simulate)."""
    from sympy.physics import mechanics as me
    start = time.perf_counter()
    L, q = _sympy_cart_pendulum() if system == "cart_pendulum" else _sympy_n_link(int(system.split("_")[-1]))
    lm = me.LagrangesMethod(L, q)
    lm.form_lagranges_equations()
    lm.mass_matrix  # noqa: B018  (forces evaluation)
    lm.forcing
    return time.perf_counter() - start


def run_pipeline_bench(models_dir="models", out=None):
    """Measure cart_pendulum and the 8-link pendulum; returns rows and writes markdown if out."""
    models_dir = Path(models_dir)
    cases = [("cart_pendulum", models_dir / "cart_pendulum.py", {}),
             ("n_link_pendulum_8", models_dir / "n_link_pendulum.py", {"n": 8})]
    rows = []
    for name, path, options in cases:
        ours = measure_ours(path, options)
        ref = measure_sympy(name)
        rows.append({"system": name, **ours, "sympy_lagranges_method": ref})
        print(f"{name}: derive+emit {ours['derive_emit']:.2f} s, first compile {ours['first_compile']:.2f} s, "
              f"cached import {ours['cached']:.3f} s; sympy LagrangesMethod {ref:.2f} s", flush=True)
    if out:
        out = Path(out)
        out.parent.mkdir(parents=True, exist_ok=True)
        lines = ["# Pipeline cost", "", "`lagrange-gen bench pipeline` (seconds, one run on this machine).", "",
                 "| system | derive + emit | first numba compile | cached re-import | generated lines | sympy LagrangesMethod derive |",
                 "|---|---|---|---|---|---|"]
        lines += [f"| {r['system']} | {r['derive_emit']:.2f} | {r['first_compile']:.2f} | {r['cached']:.3f} | "
                  f"{r['lines']} | {r['sympy_lagranges_method']:.2f} |" for r in rows]
        out.write_text("\n".join(lines) + "\n")
    return rows
