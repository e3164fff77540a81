"""`lagrange-gen bench robots`: the robots of issue 28 from model file to kernels, against Pinocchio.

Cases: the UR5-like arm (models/ur5.py), spatial chains of 8, 12 and 24 links
(models/spatial_chain.py --set n=...) and the 30-DoF humanoid tree (models/humanoid.py);
``--quick``: the UR5 and chains of 3 and 4 links. Each case runs in its own child process
with a fresh NUMBA_CACHE_DIR and a time limit: a case that does not finish is reported as
"timeout after X s" with the stage it was in (the child announces every stage on stdout as it
enters it, so what it finished survives the kill).

Before each case, another child compiles the stepper library's rk4 glue into that fresh cache
(one rk4 step of the cart pendulum through the portable glue) and reports its seconds apart:
that compile is paid once per installation and numba cache, by the first model a user runs,
not by every model, so the case's first step measures what the robot itself costs (its
kernels, the energy check). The first-step column with that compile added is reported too.

In the child, one after the other:

1. run the model file (load_model), derive and emit (codegen.generate.generate_parts with
   ``methods=["rk4", "implicit_euler"]``: rk4's kernels plus the Jacobian kernels rhs_jacobian and
   mass_matvec_dq, which the derivative rows need), write; generated lines;
2. kernel compile (loader.compile_all), first rk4 step (simulate, its glue compiled);
3. agreement with Pinocchio built from the same TREE (bench/robots_peers): H against crba, qdd
   against aba, d(qdd)/d(q, qd) against computeABADerivatives (max relative differences);
4. per call from Python (best of 5): ``mod.forward_dynamics`` with preallocated arrays,
   ``mod.accelerations``, ``pin.aba``; d(qdd)/d(q, qd) composed from our kernels (dynamics,
   rhs_jacobian, mass_matvec_dq and three solves: no kernel returns d(qdd)/d(q, qd) itself)
   both from Python and as one njit function, against ``pin.computeABADerivatives``;
5. ns per rk4 step in the jitted loop (simulate's timed run), beside an rk4 loop in Python over
   ``pin.aba`` (Pinocchio has no jitted loop of its own; for scale only).

Times are of one run on a shared machine: compare ratios within the run.

Over 300 lines: the parent and the child it starts (``python -m lagrange_gen.bench.robots
--child``) stay in one module so that the stage events they exchange have one definition.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

from .robots_report import METHODS

#: (label, model file stem, build options, seconds the child may take)
CASES = (("UR5", "ur5", {}, 300),
         ("spatial chain, 8 links", "spatial_chain", {"n": 8}, 300),
         ("spatial chain, 12 links", "spatial_chain", {"n": 12}, 300),
         ("spatial chain, 24 links", "spatial_chain", {"n": 24}, 300),
         ("humanoid tree, 30 DoF", "humanoid", {}, 300))
QUICK_CASES = (("UR5", "ur5", {}, 240),
               ("spatial chain, 3 links", "spatial_chain", {"n": 3}, 120),
               ("spatial chain, 4 links", "spatial_chain", {"n": 4}, 120))
H_STEP = 1e-3


def run_robots_bench(models_dir="models", reports_dir="reports", quick=False, timeout_scale=1.0):
    """Measure every case (child processes), write reports_dir/robots.md; returns
    {"rows": [...], "report": path}."""
    from .robots_report import markdown
    from .common import write_report
    cases = QUICK_CASES if quick else CASES
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, (label, stem, options, limit) in enumerate(cases):
            limit = limit * timeout_scale
            row = measure_case(Path(models_dir) / f"{stem}.py", options, Path(tmp) / f"case{k}", limit)
            row.update(label=label, stem=stem, options=options, limit=limit)
            rows.append(row)
            print(summary_line(row), flush=True)
    path = write_report(Path(reports_dir) / "robots.md", markdown(rows, quick))
    return {"rows": rows, "report": path}


def summary_line(row):
    if row.get("timeout"):
        return f"{row['label']}: timeout after {row['limit']:.0f} s ({row['where']})"
    if row.get("error"):
        return f"{row['label']}: failed in {row['where']}: {row['error']}"
    return (f"{row['label']}: model file {row['model_file']:.1f} s, derive {row['derive']:.1f} s, "
            f"emit {row['emit']:.1f} s, compile {row['kernel_compile']:.1f} s, first step "
            f"{row['first_step']:.1f} s, {row['lines']} lines; forward dynamics "
            f"{row['fd_ns'] / 1e3:.2f} us (pin.aba {row['pin_aba_ns'] / 1e3:.2f} us), "
            f"accelerations {row['accel_ns'] / 1e3:.2f} us, d(qdd) {row['dqdd_jit_ns'] / 1e3:.2f} us "
            f"(pin {row['pin_daba_ns'] / 1e3:.2f} us), rk4 {row['rk4_ns'] / 1e3:.2f} us per step")


def warm_stepper_library(models_dir, work, env, limit):
    """Seconds to compile the portable rk4 glue into ``env``'s numba cache (a child process:
    the cart pendulum generated into ``work`` and one rk4 step); None when it failed."""
    code = ("import sys, time\n"
            "from pathlib import Path\n"
            "from lagrange_gen.codegen.generated_files import generate_model\n"
            "from lagrange_gen.run.loader import import_generated\n"
            "from lagrange_gen.run.simulate import simulate\n"
            "mod = import_generated(generate_model(Path(sys.argv[1]), Path(sys.argv[2]), methods=['rk4']).path)\n"
            "start = time.perf_counter()\n"
            "simulate(mod, 'rk4', [0.1, 0.5], [0.0, 0.0], t_end=1e-3, h=1e-3, jit='portable')\n"
            "print(time.perf_counter() - start)\n")
    try:
        done = subprocess.run([sys.executable, "-c", code, str(Path(models_dir) / "cart_pendulum.py"),
                               str(work / "warm")], env=env, capture_output=True, text=True, timeout=limit)
        return float(done.stdout.strip().splitlines()[-1])
    except (subprocess.TimeoutExpired, ValueError, IndexError):
        return None


def measure_case(model_file, options, work, limit):
    """Run the child on one model file; the row of everything it reported (stage seconds,
    sizes, ns), with ``timeout``/``error`` and ``where`` (the stage it was in) when it did
    not finish. ``library_compile``: the stepper library's rk4 glue compiled into the case's
    fresh numba cache beforehand (warm_stepper_library)."""
    work.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(work / "numba_cache"))
    library_compile = warm_stepper_library(Path(model_file).parent, work, env, limit)
    cmd = [sys.executable, "-m", "lagrange_gen.bench.robots", "--child",
           json.dumps({"model_file": str(model_file), "options": options, "out_dir": str(work / "gen")})]
    start = time.perf_counter()
    try:
        done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=limit)
        stdout, stderr, timed_out, code = done.stdout, done.stderr, False, done.returncode
    except subprocess.TimeoutExpired as exc:
        stdout, stderr, timed_out, code = _text(exc.stdout), _text(exc.stderr), True, None
    row = parse_events(stdout)
    row["wall"] = time.perf_counter() - start
    row["library_compile"] = library_compile
    if timed_out:
        row["timeout"] = True
    elif code != 0 or "done" not in row:
        last = (stderr.strip().splitlines() or ["no output"])[-1]
        row["error"] = last[:300]
    return row


def _text(data):
    if data is None:
        return ""
    return data.decode(errors="replace") if isinstance(data, bytes) else data


def parse_events(stdout):
    """The child's JSON lines folded into one row: results update it; ``where`` is the last
    stage entered (with its detail, e.g. the kernel being emitted) and how long it had run."""
    row, stage, detail, entered = {}, "start", "", None
    for line in stdout.splitlines():
        try:
            event = json.loads(line)
        except ValueError:
            continue
        if not isinstance(event, dict):
            continue
        if "stage" in event:
            stage, detail, entered = event["stage"], "", event["at"]
        elif "detail" in event:
            detail = event["detail"]
        elif "result" in event:
            row.update(event["result"])
        row["last_at"] = event.get("at", row.get("last_at"))
    row["where"] = stage + (f": {detail}" if detail else "")
    row["stage_entered_at"] = entered
    return row


# ---------------------------------------------------------------- the child


_T0 = time.perf_counter()


def _event(**fields):
    fields["at"] = round(time.perf_counter() - _T0, 3)
    print(json.dumps(fields), flush=True)


def _result(**values):
    _event(result=values)


def _progress_class():
    from ..codegen.generate import Progress

    class EventProgress(Progress):
        """The generator's progress lines (stderr), and each stage and kernel announced on
        stdout for the parent."""

        @property
        def detail(self):
            return self.__dict__.get("_detail", "")

        @detail.setter
        def detail(self, value):
            self.__dict__["_detail"] = value
            if value:
                _event(detail=value)

        @contextmanager
        def stage(self, name):
            _event(stage=name)
            with super().stage(name) as progress:
                yield progress
    return EventProgress


def per_call_ns(fn, target_s=0.2, repeats=5):
    """ns per call of fn(), best of ``repeats`` timed batches of about target_s each."""
    fn()
    start, count = time.perf_counter(), 0
    while time.perf_counter() - start < 0.02:
        fn()
        count += 1
    per = (time.perf_counter() - start) / count
    reps = max(10, int(target_s / max(per, 1e-9)))
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(reps):
            fn()
        best = min(best, (time.perf_counter() - start) / reps)
    return 1e9 * best


def _rel(a, b):
    import numpy as np
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(float(np.abs(b).max()), 1e-300))


def _derivatives_jit(mod):
    """An njit d(qdd)/d(q, qd) from the module's kernels (what a user writes today: there is no
    such kernel): H qdd = rhs, H dqdd/dq = d rhs/dq - d(H w)/dq at w = qdd, H dqdd/dqd = d rhs/dqd."""
    import numpy as np
    from numba import njit
    dynamics, rhs_jacobian, mass_matvec_dq = mod.dynamics, mod.rhs_jacobian, mod.mass_matvec_dq

    @njit(cache=False)
    def dqdd(q, v, p, H, rhs, Jq, Jqd, D, out):
        n = q.shape[0]
        dynamics(q, v, 0.0, p, H, rhs)
        rhs_jacobian(q, v, 0.0, p, Jq, Jqd)
        qdd = np.linalg.solve(H, rhs)
        mass_matvec_dq(q, qdd, 0.0, p, D)
        B = np.empty((n, 2 * n))
        B[:, :n] = Jq - D
        B[:, n:] = Jqd
        out[:, :] = np.linalg.solve(H, B)
    return dqdd


def _child(args):
    import numpy as np
    from ..model.model_file import load_model
    from ..codegen.generate import generate_parts
    from ..codegen.write import write_if_changed
    Progress = _progress_class()
    model_file, options, out_dir = Path(args["model_file"]), args["options"], Path(args["out_dir"])

    _event(stage="model file")
    start = time.perf_counter()
    model = load_model(model_file, **options)
    _result(model_file=time.perf_counter() - start, n=len(model.coords))

    progress = Progress(f"{model_file}" + "".join(f" --set {k}={v}" for k, v in options.items()))
    parts = generate_parts(model, out_dir, methods=list(METHODS), progress=progress)
    _event(stage="write")
    write_if_changed(parts.target, parts.text)
    _result(derive=parts.seconds["derive"], emit=parts.seconds["emit"],
            lines=parts.text.count("\n"), kb=len(parts.text.encode()) / 1024,
            kernels=[t.name for t in parts.texts])

    # What a user waits for: the first rk4 step compiles the kernels and glue rk4 reaches.
    _event(stage="first step")
    from ..run.loader import compile_all, import_generated
    from ..run.simulate import simulate
    start = time.perf_counter()
    mod = import_generated(parts.target)
    n = mod.N_COORDS
    rng = np.random.default_rng(0)
    q, v, tau = rng.uniform(-1, 1, n), rng.normal(size=n), np.zeros(n)
    simulate(mod, "rk4", q, v, t_end=H_STEP, h=H_STEP)
    _result(first_step=time.perf_counter() - start)

    _event(stage="kernel compile")     # the other kernels (Jacobians, robotics kernels)
    start = time.perf_counter()
    compile_all(mod)
    _result(kernel_compile=time.perf_counter() - start)

    _event(stage="Pinocchio")
    import runpy
    from . import robots_peers
    namespace = runpy.run_path(str(model_file))
    tree = namespace["chain_tree"](**options) if options and "chain_tree" in namespace else namespace["TREE"]
    p = mod.DEFAULT_PARAMS.copy()
    peer = robots_peers.pinocchio_model(tree, g=float(p[list(mod.PARAMS).index("g")]))
    H, rhs, qdd = np.zeros((n, n)), np.zeros(n), np.zeros(n)
    mod.forward_dynamics(q, v, 0.0, p, np.zeros((n, n)), qdd)   # its H: a workspace it may overwrite
    mod.dynamics(q, v, 0.0, p, H, rhs)
    Jq, Jqd, D = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    mod.rhs_jacobian(q, v, 0.0, p, Jq, Jqd)
    mod.mass_matvec_dq(q, qdd, 0.0, p, D)
    pdq, pdv = robots_peers.aba_derivatives(peer, q, v, tau)
    _result(err_H=_rel(H, robots_peers.crba(peer, q)), err_qdd=_rel(qdd, robots_peers.aba(peer, q, v, tau)),
            err_dq=_rel(np.linalg.solve(H, Jq - D), pdq), err_dv=_rel(np.linalg.solve(H, Jqd), pdv))

    _event(stage="per call")
    import pinocchio as pin
    fd = mod.forward_dynamics
    Hbuf = np.zeros((n, n))
    fd_ns = per_call_ns(lambda: fd(q, v, 0.0, p, Hbuf, qdd))
    accel_ns = per_call_ns(lambda: mod.accelerations(q, v))
    model_, data_ = peer.model, peer.data
    qp, vp, tp = peer.to_pin(q), peer.to_pin(v), peer.to_pin(tau)
    pin_aba_ns = per_call_ns(lambda: pin.aba(model_, data_, qp, vp, tp))
    dyn, rj, mmv = mod.dynamics, mod.rhs_jacobian, mod.mass_matvec_dq
    rhs_b, out = np.zeros(n), np.zeros((n, 2 * n))

    def dqdd_python():
        dyn(q, v, 0.0, p, H, rhs_b)
        rj(q, v, 0.0, p, Jq, Jqd)
        a = np.linalg.solve(H, rhs_b)
        mmv(q, a, 0.0, p, D)
        return np.linalg.solve(H, np.hstack((Jq - D, Jqd)))
    dqdd_py_ns = per_call_ns(dqdd_python)
    if hasattr(mod, "forward_dynamics_jacobian"):      # the module's own kernel
        W = np.zeros((n, n))
        mod.forward_dynamics_jacobian(q, v, 0.0, p, H, rhs_b, Jq, Jqd, W)
        out[:, :n], out[:, n:] = Jq, Jqd
        fdj = mod.forward_dynamics_jacobian
        dqdd_jit_ns = per_call_ns(lambda: fdj(q, v, 0.0, p, H, rhs_b, Jq, Jqd, W))
        tau_out = np.zeros(n)
        inv = mod.inverse_dynamics
        inv(q, v, qdd, 0.0, p, tau_out)
        _result(id_ns=per_call_ns(lambda: inv(q, v, qdd, 0.0, p, tau_out)),
                pin_rnea_ns=per_call_ns(lambda: pin.rnea(model_, data_, qp, vp, peer.to_pin(qdd))),
                err_id=_rel(tau_out, robots_peers.rnea(peer, q, v, qdd)))
    else:
        jit = _derivatives_jit(mod)
        jit(q, v, p, H, rhs_b, Jq, Jqd, D, out)
        dqdd_jit_ns = per_call_ns(lambda: jit(q, v, p, H, rhs_b, Jq, Jqd, D, out))
    pin_daba_ns = per_call_ns(lambda: pin.computeABADerivatives(model_, data_, qp, vp, tp))
    _result(fd_ns=fd_ns, accel_ns=accel_ns, pin_aba_ns=pin_aba_ns, dqdd_py_ns=dqdd_py_ns,
            dqdd_jit_ns=dqdd_jit_ns, pin_daba_ns=pin_daba_ns,
            err_dqdd_jit=_rel(out, np.hstack((pdq, pdv))))

    _event(stage="rk4 loop")
    probe = simulate(mod, "rk4", q, v, t_end=20 * H_STEP, h=H_STEP, save_every=20)
    steps = int(min(200_000, max(200, 0.3 / max(probe.wall_time / 20, 1e-9))))
    walls = [simulate(mod, "rk4", q, v, t_end=steps * H_STEP, h=H_STEP, save_every=steps).wall_time
             for _ in range(3)]
    _result(rk4_ns=1e9 * min(walls) / steps, pin_rk4_py_ns=_pin_rk4_ns(pin, model_, data_, qp, vp, tp))
    _result(done=True)


def _pin_rk4_ns(pin, model, data, q, v, tau, h=H_STEP, steps=None):
    """ns per rk4 step of a Python loop over pin.aba (q is a vector space here: revolute and
    prismatic joints only)."""
    import numpy as np

    def f(x, y):
        return y, np.array(pin.aba(model, data, x, y, tau))

    def loop(count):
        x, y = q.copy(), v.copy()
        for _ in range(count):
            k1q, k1v = f(x, y)
            k2q, k2v = f(x + 0.5 * h * k1q, y + 0.5 * h * k1v)
            k3q, k3v = f(x + 0.5 * h * k2q, y + 0.5 * h * k2v)
            k4q, k4v = f(x + h * k3q, y + h * k3v)
            x = x + h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
            y = y + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    start = time.perf_counter()
    loop(50)
    count = steps or max(100, int(0.3 / max((time.perf_counter() - start) / 50, 1e-9)))
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        loop(count)
        best = min(best, (time.perf_counter() - start) / count)
    return 1e9 * best


if __name__ == "__main__" and sys.argv[1:2] == ["--child"]:
    _child(json.loads(sys.argv[2]))
