"""`lagrange-gen bench firstrun`: what a user waits for between a model file and its first step
(issue 40), with native kernels (jit/native.py) and without ($LAGRANGE_GEN_NATIVE=0).

Every measurement is one fresh child process (``python -m lagrange_gen.bench.firstrun --child``)
with its own NUMBA_CACHE_DIR and LAGRANGE_GEN_PORTABLE_DIR and a fresh folder for the generated
module, and LAGRANGE_GEN_INTERPRETED=0 (the first step is a compiled one, not the interpreted
tier). Background compiles are on, as for a user: a big kernel runs at LLVM's level 0 in the
child while a detached process compiles it at level 1 (jit/native_background.py); the parent
waits for that process before it starts the next child, so that no two measurements overlap
and the ``again`` variant finds what a user's next process finds. With the interpreted tier off
nothing else runs in the background. The variants of a case:

- ``empty``: empty caches, the first model after an install: the portable glue of the method is
  compiled too;
- ``library``: caches already holding the glue of the method, compiled by a run of the same
  method on ANOTHER model (WARMUP): what every new model but the first pays (its own kernels);
  for a controlled run, the portable controlled glue compiled by ANOTHER model's run with
  ANOTHER controller (WARMUP_CONTROL, jit="portable": what the background compile leaves a user
  after a first controlled run), so the case's own controller is new;
- ``again``: a new process on the ``library`` run's caches and module (nothing new);
- ``empty, numba`` and ``library, numba``: the same with $LAGRANGE_GEN_NATIVE=0 (the model's
  kernels compiled by numba, the path before native kernels).

The parent reads each child's CPU seconds (user + system) and peak resident memory from
os.wait4, so interpreter start and imports are counted; the child reports the CPU seconds of its
phases (imports, model file to module, kernel table, first call) as JSON lines, so that a child
killed at its time limit still says where it was. CPU seconds, not wall seconds: the machine the
report is written on is shared.

The cost per call once compiled (``percall``): the UR5's forward dynamics called from Python
(the numba dispatcher, as before native kernels) and inside a jitted loop through a function
pointer (the native kernel, the numba-compiled kernel) or called directly (what the specialized
glue inlines); and ns per step of the 16-link pendulum's rk4 and verlet on the specialized glue
and on the portable glue with native and with numba-compiled kernels.

Over 300 lines: the parent and the child it starts stay in one module so that the phases they
exchange have one definition.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

H = 1e-3
#: steps of the first simulate call (t_end = FIRST_STEPS * h)
FIRST_STEPS = 3


@dataclass(frozen=True)
class Case:
    """One row: ``stem`` (models/<stem>.py) with build ``options``; ``kind`` "simulate" (first
    simulate of ``method``), "control" (first simulate with a jitted controller), "linearize"
    (first linearize_nonholonomic) or "cli" (``lagrange-gen MODEL --methods method`` on the
    module the case named by ``after`` generated: the unchanged model file)."""
    label: str
    stem: str
    method: str
    options: dict = field(default_factory=dict)
    kind: str = "simulate"
    q0: tuple = None
    v0: tuple = None
    variants: tuple = ("empty", "library", "again")
    after: str = None
    timeout: float = 300.0
    jit: str = "auto"
    #: gains (kp, kd) of the controller of a "control" case, u = kp q[1] + kd qd[1]
    gains: tuple = (20.0, 3.0)


#: upright straight running of the bicycle at 4 m/s (tests/rolling/test_bicycle_benchmark.py)
_BICYCLE_Q0, _BICYCLE_V0 = (0.0,) * 8, (4.0, 0, 0, 0, 0, 0, -4.0 / 0.3, -4.0 / 0.35)
_ALL = ("empty", "library", "again", "library, numba")

CASES = (
    Case("cart pendulum, rk4", "cart_pendulum", "rk4", q0=(0.1, 1.0), variants=_ALL),
    Case("cart pendulum, midpoint", "cart_pendulum", "midpoint", q0=(0.1, 1.0), variants=_ALL),
    Case("cart pendulum, implicit_euler", "cart_pendulum", "implicit_euler", q0=(0.1, 1.0),
         variants=_ALL),
    Case("cart pendulum, dop853", "cart_pendulum", "dop853", q0=(0.1, 1.0), variants=_ALL),
    Case("bouncing ball, dop853_impacts", "bouncing_ball", "dop853_impacts", q0=(1.0,),
         variants=_ALL),
    Case("controlled cart pendulum (cart pole), midpoint", "cart_pole", "midpoint",
         kind="control", q0=(0.0, 0.2), variants=("library", "again", "library, numba")),
    Case("spatial chain, 8 links, rk4", "spatial_chain", "rk4", {"n": 8},
         variants=("empty", "library", "again", "library, numba"), timeout=240),
    Case("spatial chain, 12 links, midpoint", "spatial_chain", "midpoint", {"n": 12},
         variants=("empty", "library", "again", "library, numba"), timeout=240),
    Case("spatial chain, 24 links, rk4", "spatial_chain", "rk4", {"n": 24},
         variants=("library", "again"), timeout=400),
    Case("humanoid, 30 DoF, implicit_euler", "humanoid", "implicit_euler",
         variants=("library", "again"), timeout=400),
    Case("lagrange-gen on the unchanged humanoid", "humanoid", "implicit_euler", kind="cli",
         variants=("again",), after="humanoid, 30 DoF, implicit_euler"),
    Case("bicycle, nonholonomic_midpoint", "bicycle", "nonholonomic_midpoint", q0=_BICYCLE_Q0,
         v0=_BICYCLE_V0, variants=("empty", "library", "again")),
    Case("bicycle, linearize_nonholonomic", "bicycle", "nonholonomic_midpoint", kind="linearize",
         q0=_BICYCLE_Q0, v0=_BICYCLE_V0, variants=("library", "again")),
)
QUICK_CASES = (
    Case("cart pendulum, rk4", "cart_pendulum", "rk4", q0=(0.1, 1.0),
         variants=("empty", "library", "again", "library, numba")),
    Case("bouncing ball, dop853_impacts", "bouncing_ball", "dop853_impacts", q0=(1.0,),
         variants=("library", "again")),
)

#: The model whose run fills the ``library`` caches of a method (another model of the same kind,
#: so that only the glue and the stepper library are reused), with its start.
WARMUP = {"dop853_impacts": ("rocking_block", None, None),
          "nonholonomic_midpoint": ("rolling_disk", (0.0, 0.0, 0.3, 0.0),
                               (2 * math.cos(0.3), 2 * math.sin(0.3), 1.5, 4.0))}
WARMUP_DEFAULT = ("double_pendulum", (0.1, 0.2), None)
#: The warm-up of a controlled case: another model with an input, another controller (gains),
#: the portable controlled glue compiled (jit="portable").
WARMUP_CONTROL = Case("warm-up cart_pendulum_forced", "cart_pendulum_forced", "midpoint",
                      kind="control", q0=(0.0, 0.2), jit="portable", gains=(10.0, 1.0))

#: The issue's goals: (case, before, goal, seconds or None, label of the case and variant
#: judged, why that variant).
GOALS = (
    ("8-link spatial chain, model file to first rk4 step", "24-34 s", "<= 3 s", 3.0,
     "spatial chain, 8 links, rk4"),
    ("12-link chain, first midpoint step (implicit: Jacobians)", "> 120 s", "<= 5 s", 5.0,
     "spatial chain, 12 links, midpoint"),
    ("30-DoF humanoid, first implicit_euler step", "> 300 s", "<= 15 s", 15.0,
     "humanoid, 30 DoF, implicit_euler"),
    ("bouncing ball, first dop853_impacts step", "60-119 s", "<= 2 s", 2.0,
     "bouncing ball, dop853_impacts"),
    ("controlled cart pendulum, a new process", "10-15 s", "<= 1 s", 1.0,
     "controlled cart pendulum (cart pole), midpoint"),
    ("bicycle, first linearize_nonholonomic", "> 18 min, 4.7 GB", "<= 10 s", 10.0,
     "bicycle, linearize_nonholonomic"),
    ("lagrange-gen on an unchanged humanoid", "12-17 s", "<= 0.2 s", 0.2,
     "lagrange-gen on the unchanged humanoid"),
)


# ---------------------------------------------------------------- the parent


def child_env(dirs, native=True):
    """The environment of a child: its caches (``dirs`` {"numba", "portable"}), background
    compiles on (module docstring), compiled first steps, native kernels on or off."""
    from ..jit.background import BACKGROUND_ENV
    from ..jit.first_run import INTERPRETED_ENV
    from ..jit.native import NATIVE_ENV, OPT_ENV
    from ..jit.portable import DIR_ENV, JIT_ENV
    env = dict(os.environ, NUMBA_CACHE_DIR=str(dirs["numba"]),
               **{DIR_ENV: str(dirs["portable"]), BACKGROUND_ENV: "1", INTERPRETED_ENV: "0",
                  NATIVE_ENV: "1" if native else "0"})
    env.pop(JIT_ENV, None)          # the default choice (bench/cli.py sets "specialized")
    env.pop(OPT_ENV, None)          # LLVM's default level, and with it the level-0 first tier
    return env


def wait_for_background(portable_dir, timeout=900.0):
    """Wall seconds spent waiting until no background compile holds a lock under
    ``portable_dir`` (jit.background: ``*.compiling`` files), at most ``timeout``."""
    from ..jit.background import lock_held
    start = time.perf_counter()
    while time.perf_counter() - start < timeout:
        if not any(lock_held(lock) for lock in Path(portable_dir).rglob(".*.compiling")):
            break
        time.sleep(0.2)
    return time.perf_counter() - start


def run_child(spec, env, timeout, work):
    """Run the child on ``spec`` (a dict, see _child) under ``env``; the row: cpu (user + system
    seconds of the whole process), rss_mb (its peak resident memory), wall, the phases and
    results it reported, and ``timeout`` or ``error`` with ``where`` (the phase it was in) when
    it did not finish."""
    work.mkdir(parents=True, exist_ok=True)
    out_path, err_path = work / "child.out", work / "child.err"
    if spec.get("kind") == "cli":        # the command itself (bench/ does not import cli/)
        cmd = [sys.executable, "-m", "lagrange_gen.cli.main", spec["model"], "-o",
               spec["out_dir"], "--methods", spec["method"],
               *(f"--set={k}={v}" for k, v in spec["options"].items())]
    else:
        cmd = [sys.executable, "-m", "lagrange_gen.bench.firstrun", "--child", json.dumps(spec)]
    start = time.perf_counter()
    with open(out_path, "w") as out, open(err_path, "w") as err:
        proc = subprocess.Popen(cmd, env=env, stdout=out, stderr=err)
        timed_out, status, usage = False, None, None
        while status is None:
            pid, code, ru = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                status, usage = code, ru
            elif time.perf_counter() - start > timeout:
                proc.kill()
                _, status, usage = os.wait4(proc.pid, 0)
                timed_out = True
            else:
                time.sleep(0.05)
        proc.returncode = os.waitstatus_to_exitcode(status)   # reaped here, not by Popen
    row = parse_events(out_path.read_text())
    if spec.get("kind") == "cli" and proc.returncode == 0:
        row["done"] = True
    row.update(cpu=usage.ru_utime + usage.ru_stime, rss_mb=usage.ru_maxrss / 1024,
               wall=time.perf_counter() - start)
    from ..jit.folders import DIR_ENV
    row["background_wait"] = wait_for_background(env[DIR_ENV]) if DIR_ENV in env else 0.0
    if timed_out:
        row["timeout"] = timeout
    elif proc.returncode != 0 or "done" not in row:
        last = (err_path.read_text().strip().splitlines() or ["no output"])[-1]
        row["error"] = last[:300]
    return row


def parse_events(stdout):
    """The child's JSON lines folded into one row: {"phases": {name: CPU seconds}, results...,
    "where": the phase it was in when its output ends}."""
    row, where = {"phases": {}}, "start"
    for line in stdout.splitlines():
        try:
            event = json.loads(line)
        except ValueError:
            continue
        if not isinstance(event, dict):
            continue
        if "enter" in event:
            where = event["enter"]
        elif "phase" in event:
            row["phases"][event["phase"]] = event["cpu"]
            where = f"after {event['phase']}"
        elif "result" in event:
            row.update(event["result"])
    row["where"] = where
    return row


class Workspace:
    """The folders of one bench run under ``root``: per (method, native) the library caches
    (filled once by WARMUP), per case and variant the generated folder and caches."""

    def __init__(self, root, models_dir, progress=True):
        self.root, self.models_dir, self.progress = Path(root), Path(models_dir), progress
        self.libraries = {}          # (method, kind, native) -> (dirs, warm-up row)
        self.case_dirs = {}          # (case label, variant) -> (dirs, gen dir)

    def dirs(self, name):
        base = self.root / name
        return {"numba": base / "numba", "portable": base / "portable"}

    def library(self, case, native):
        """The caches holding ``case.method``'s glue, compiled by a WARMUP model's run."""
        kind = case.kind if case.kind in ("linearize", "control") else "simulate"
        key = (case.method, kind, native)
        if key not in self.libraries:
            dirs = self.dirs(f"library-{case.method}-{kind}-{'native' if native else 'numba'}")
            stem, q0, v0 = WARMUP.get(case.method, WARMUP_DEFAULT)
            warm = Case(f"warm-up {stem}", stem, case.method, kind=kind, q0=q0, v0=v0)
            if kind == "control":
                warm, stem = WARMUP_CONTROL, WARMUP_CONTROL.stem
            row = run_child(child_spec(warm, self.models_dir, dirs["numba"].parent / "gen"),
                            child_env(dirs, native), case.timeout, dirs["numba"].parent)
            self.libraries[key] = (dirs, row)
            self.say(f"  library of {case.method} ({'native' if native else 'numba'} kernels) "
                     f"by {stem}: {describe(row)}")
        return self.libraries[key][0]

    def say(self, text):
        if self.progress:
            print(text, file=sys.stderr, flush=True)

    def measure(self, case, variant):
        """The row of ``case`` under ``variant`` (see the module docstring)."""
        native = not variant.endswith("numba")
        tag = f"{len(self.case_dirs)}"
        if variant == "again":
            base = case.after or case.label
            dirs, gen = self.case_dirs.get((base, "library")) or self.case_dirs[(base, "empty")]
        elif variant.startswith("library"):
            dirs, gen = self.library(case, native), self.root / f"gen{tag}"
        else:
            dirs, gen = self.dirs(f"empty{tag}"), self.root / f"gen{tag}"
        self.case_dirs[(case.label, variant)] = (dirs, gen)
        row = run_child(child_spec(case, self.models_dir, gen), child_env(dirs, native),
                        case.timeout, self.root / f"work{tag}")
        self.say(f"{case.label} [{variant}]: {describe(row)}")
        return row


def child_spec(case, models_dir, gen_dir):
    return {"model": str(Path(models_dir) / f"{case.stem}.py"), "options": case.options,
            "method": case.method, "kind": case.kind, "q0": case.q0, "v0": case.v0,
            "out_dir": str(gen_dir), "jit": case.jit, "gains": list(case.gains)}


def describe(row):
    """One line of a row for the progress output."""
    if row.get("timeout"):
        return f"> {row['timeout']:.0f} s (killed {row['where']})"
    if row.get("error"):
        return f"failed {row['where']}: {row['error']}"
    phases = ", ".join(f"{k} {v:.2f}" for k, v in row["phases"].items())
    return f"{row['cpu']:.2f} CPU s ({phases}), {row['rss_mb']:.0f} MB, {row.get('jit', '')}"


def measure_cases(cases, root, models_dir, progress=True, after_case=None):
    """{case label: {variant: row}} and the library warm-up rows {(method, kind, native): row};
    after_case(results, libraries) is called after each case (the report is written as the
    bench goes: a long run stopped midway keeps what it measured)."""
    space = Workspace(root, models_dir, progress)
    results = {}
    for case in cases:
        results[case.label] = {v: space.measure(case, v) for v in case.variants}
        if after_case is not None:
            after_case(results, _library_rows(space))
    return results, _library_rows(space)


def _library_rows(space):
    return {key: row for key, (_, row) in space.libraries.items()}


def measure_percall(root, models_dir, quick=False, timeout=900):
    """ns per call and per step once compiled (module docstring), one child process: the
    native and the numba-compiled kernels side by side in the same process, timed in
    alternating rounds, so that the load of a shared machine weighs on both alike."""
    dirs = {"numba": Path(root) / "percall" / "numba", "portable": Path(root) / "percall" / "portable"}
    spec = {"kind": "percall", "models_dir": str(models_dir), "quick": quick,
            "out_dir": str(Path(root) / "percall" / "gen")}
    from ..jit.background import BACKGROUND_ENV
    # every kernel at LLVM's level 1 at once: the cost per call of what every later run loads
    env = dict(child_env(dirs, True), **{BACKGROUND_ENV: "0"})
    return run_child(spec, env, timeout, Path(root) / "percall")


def run_firstrun_bench(models_dir="models", reports_dir="reports", quick=False, cases=None,
                       percall=True, progress=True, command=None):
    """Measure every case (child processes) and the cost per call, write
    reports_dir/firstrun.md; returns {"results", "libraries", "percall", "report"}."""
    from .firstrun_report import markdown
    from .common import write_report
    from ..jit.speedups import numba_version
    cases = cases if cases is not None else (QUICK_CASES if quick else CASES)
    command = command or ("lagrange-gen bench firstrun" + (" --quick" if quick else ""))
    target = Path(reports_dir) / "firstrun.md"

    def write(results, libraries, calls):
        info = {"command": command, "numba": numba_version(), "cpus": os.cpu_count(),
                "load": _load_average(), "goals": GOALS, "first_steps": FIRST_STEPS, "h": H,
                "warmup_default": WARMUP_DEFAULT[0],
                "warmups": {method: stem for method, (stem, _, _) in WARMUP.items()}}
        done = [case for case in cases if case.label in results]
        return write_report(target, markdown(done, results, libraries, calls, info))

    with tempfile.TemporaryDirectory(prefix="lagrange-gen-firstrun-") as tmp:
        results, libraries = measure_cases(
            cases, tmp, models_dir, progress,
            after_case=lambda res, lib: write(res, lib, None) if len(res) < len(cases) else None)
        calls = measure_percall(tmp, models_dir, quick) if percall else None
    path = write(results, libraries, calls)
    return {"results": results, "libraries": libraries, "percall": calls, "report": path}


def _load_average():
    try:
        return os.getloadavg()
    except OSError:
        return None


# ---------------------------------------------------------------- the child


def _emit(**fields):
    print(json.dumps(fields), flush=True)


class _Phases:
    """Reports the CPU seconds of each phase as it ends (and which phase is running)."""

    def __init__(self):
        self.last = time.process_time()

    def enter(self, name):
        _emit(enter=name)

    def done(self, name):
        now = time.process_time()
        _emit(phase=name, cpu=now - self.last)
        self.last = now


def _kernel_stats(table):
    """{"native_new", "native_cached", "native_level0", "native_s", "numba_kernels"} of a
    kernel table (native_level0: kernels running at LLVM's level 0 while a background process
    compiles their better level)."""
    stats = {"native_new": 0, "native_cached": 0, "native_level0": 0, "native_s": 0.0,
             "numba_kernels": 0}
    for entry in table:
        if hasattr(entry, "cached") and hasattr(entry, "seconds"):
            stats["native_cached" if entry.cached else "native_new"] += 1
            stats["native_level0"] += int(getattr(entry, "level", 1) < getattr(entry, "wanted", 1))
            stats["native_s"] += entry.seconds
        elif hasattr(entry, "dispatcher"):
            stats["numba_kernels"] += 1
    return stats


def _controller(gains):
    """A PD law on the pole angle, a force on the cart: u = kp q[1] + kd qd[1]; the gains are
    constants of the function (another pair: another controller)."""
    from numba import njit
    kp, kd = (float(g) for g in gains)

    @njit
    def balance(t, q, qd, p):
        return kp * q[1] + kd * qd[1]
    return balance


def _child(spec):
    phases = _Phases()
    kind = spec["kind"]
    if kind == "percall":
        return _percall_child(spec)
    phases.enter("imports")
    import numpy as np
    from ..jit.compile_notice import time_outermost_compiles
    from ..run.loader import GENERATED_MODULE_PREFIX, load
    from ..run.simulate import simulate
    phases.done("imports")
    # wall seconds of numba's outermost compiles: the model's kernels (called from Python, or
    # put in a kernel table by numba), the glue and stepper library, anything else
    compiles = time_outermost_compiles(lambda name: (
        "kernels" if name.startswith(GENERATED_MODULE_PREFIX) else "glue"
        if name.startswith(("lagrange_gen_portable", "lagrange_gen.steppers")) else "other"))
    phases.enter("model file to module")
    method = spec["method"]
    mod = load(spec["model"], out_dir=spec["out_dir"], methods=[method], options=spec["options"])
    phases.done("model file to module")
    n = mod.N_COORDS
    q0 = np.array(spec["q0"] if spec["q0"] is not None else [0.1] * n, dtype=float)
    v0 = np.array(spec["v0"] if spec["v0"] is not None else [0.0] * n, dtype=float)
    result = {}
    if kind == "linearize":
        phases.enter("first linearize_nonholonomic")
        from ..linear.nonholonomic import linearize_nonholonomic
        lin = linearize_nonholonomic(mod, q0, v0)
        phases.done("first linearize_nonholonomic")
        result["size"] = int(np.asarray(lin.mass).shape[0])
        _emit(result={**result, "numba_compiles": dict(compiles), "done": True})
        return
    if kind == "simulate":
        from ..jit import portable
        phases.enter("kernels")
        table = portable.kernel_table(mod, method)
        phases.done("kernels")
        result.update(_kernel_stats(table))
    phases.enter("first simulate")
    control = _controller(spec.get("gains", (20.0, 3.0))) if kind == "control" else None
    traj = simulate(mod, method, q0, v0, t_end=FIRST_STEPS * H, h=H, control=control,
                    jit=spec.get("jit", "auto"))
    phases.done("first simulate")
    result.update(jit=str(traj.jit), final_finite=bool(np.isfinite(traj.q[-1]).all()),
                  numba_compiles=dict(compiles))
    _emit(result={**result, "done": True})


# -------- cost per call once compiled

PERCALL_ROBOT = ("ur5", {})
PERCALL_CHAIN_N = 16
PERCALL_METHODS = ("rk4", "verlet")
#: alternating timing rounds; each number is the best round
ROUNDS = 7


def _loop_caller():
    """A jitted loop calling ``kernel`` ``count`` times: the cost of one call inside compiled
    code (kernel a first-class function, a native or numba-compiled kernel's address, or a numba
    dispatcher, which numba calls directly)."""
    from numba import njit

    @njit
    def repeat(kernel, count, q, v, p, H, qdd):
        for _ in range(count):
            kernel(q, v, 0.0, p, H, qdd)
        return qdd[0]
    return repeat


def _interleaved(timers, rounds=ROUNDS):
    """{name: best seconds} of ``timers`` {name: () -> seconds}, run one after the other in
    each of ``rounds`` rounds."""
    best = {name: float("inf") for name in timers}
    for _ in range(rounds):
        for name, timer in timers.items():
            best[name] = min(best[name], timer())
    return best


def _with_native(on, fn):
    """fn() with $LAGRANGE_GEN_NATIVE on or off (read when a kernel table is built)."""
    from ..jit.native import NATIVE_ENV
    saved = os.environ.get(NATIVE_ENV)
    os.environ[NATIVE_ENV] = "1" if on else "0"
    try:
        return fn()
    finally:
        if saved is None:
            os.environ.pop(NATIVE_ENV, None)
        else:
            os.environ[NATIVE_ENV] = saved


def _percall_child(spec):
    """The per-call row: forward dynamics of PERCALL_ROBOT from Python and in a jitted loop
    (through the native kernel's and the numba-compiled kernel's address, and called directly),
    then ns per step of the chain's PERCALL_METHODS on the specialized glue and on the portable
    glue with native and with numba-compiled kernels (two imports of the same module, one
    kernel table each)."""
    import numpy as np
    from ..jit import portable
    from ..jit.python_calls import unchecked
    from ..run.loader import import_generated, load
    from ..run.simulate import simulate
    from .robots import per_call_ns
    models_dir, quick, out = Path(spec["models_dir"]), spec["quick"], Path(spec["out_dir"])
    stem, options = ("cart_pendulum", {}) if quick else PERCALL_ROBOT
    mod = load(models_dir / f"{stem}.py", out_dir=out, methods=["rk4"], options=options)
    n = mod.N_COORDS
    rng = np.random.default_rng(0)
    q, v, p = rng.uniform(-1, 1, n), rng.normal(size=n), mod.DEFAULT_PARAMS.copy()
    Hbuf, qdd = np.zeros((n, n)), np.zeros(n)
    fd = mod.forward_dynamics
    bare = unchecked(fd)                 # without the argument check of a call from Python
    result = {"robot": stem, "fd_python_ns": per_call_ns(lambda: fd(q, v, 0.0, p, Hbuf, qdd)),
              "fd_python_unchecked_ns": per_call_ns(lambda: bare(q, v, 0.0, p, Hbuf, qdd))}
    # the kernel as a portable kernel table holds it, native and numba-compiled
    kernels = {"fd_native_ns": _with_native(True, lambda: portable.table_kernel(
                   mod, "forward_dynamics")),
               "fd_numba_ns": _with_native(False, lambda: portable.table_kernel(
                   mod, "forward_dynamics")),
               "fd_direct_ns": fd}
    result["fd_native_kind"] = type(kernels["fd_native_ns"]).__name__
    repeat, count = _loop_caller(), (20_000 if quick else 100_000)

    def timer(kernel):
        def run():
            start = time.perf_counter()
            repeat(kernel, count, q, v, p, Hbuf, qdd)
            return (time.perf_counter() - start) / count
        return run
    for kernel in kernels.values():
        repeat(kernel, 10, q, v, p, Hbuf, qdd)
    best = _interleaved({name: timer(kernel) for name, kernel in kernels.items()})
    result.update({name: 1e9 * s for name, s in best.items()})
    _emit(result=result)

    chain_n = 4 if quick else PERCALL_CHAIN_N
    methods = list(PERCALL_METHODS)
    chain = load(models_dir / "n_link_pendulum.py", out_dir=out, methods=methods,
                 options={"n": chain_n})
    twin_dir = out / "twin"              # the same module imported again: its own kernel table
    twin_dir.mkdir(parents=True, exist_ok=True)
    twin_path = twin_dir / Path(chain.__file__).name
    twin_path.write_text(Path(chain.__file__).read_text())
    twin = import_generated(twin_path)
    th0, w0 = 0.3 * np.sin(np.arange(1, chain_n + 1)), np.zeros(chain_n)
    steps = 2_000 if quick else 20_000
    runs = {}
    for method in methods:
        runs[f"{method}_specialized_ns"] = (chain, method, "specialized", True)
        runs[f"{method}_portable_native_ns"] = (chain, method, "portable", True)
        runs[f"{method}_portable_numba_ns"] = (twin, method, "portable", False)

    def step_timer(module, method, jit):
        def run():
            traj = simulate(module, method, th0, w0, t_end=steps * H, h=H, save_every=steps,
                            jit=jit)
            return traj.wall_time / steps
        return run
    timers = {}
    for name, (module, method, jit, native) in runs.items():
        timers[name] = step_timer(module, method, jit)
        _with_native(native, timers[name])        # compile or load; builds the kernel table
    best = _interleaved(timers)
    _emit(result={**{name: 1e9 * s for name, s in best.items()}, "chain_n": chain_n,
                  "done": True})


if __name__ == "__main__" and sys.argv[1:2] == ["--child"]:
    _child(json.loads(sys.argv[2]))
