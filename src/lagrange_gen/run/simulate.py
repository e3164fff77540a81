"""Python driver: integrate a generated module with a stepper, get a Trajectory.

    from lagrange_gen.run.simulate import simulate
    traj = simulate("models/cart_pendulum.py", method="midpoint", q0=[0.1, 0.5], t_end=10, h=1e-3)
    traj.plot("traj.png"); traj.to_npz("traj.npz")

The integration itself runs inside the generated module's jitted ``run_<method>`` (see
codegen/glue.py), driven in chunks by run/fixed_driver.py or, for an adaptive method, by
run/adaptive_driver.py; this module only checks inputs (run_checks: element coefficients, step count,
time resolution, memory; the method's settings by its spec) and hands the finished run to
run/run_result.py, which builds the Trajectory from the method's declared saved fields and warns
when a conservative run lost its energy (run/energy_check.py). What a method is and which models it applies to is read from its spec
(steppers/core/method_spec.py), never from its name. What the module and the method alone fix
(the method that runs, whether it applies, its saved fields, default settings and parameters)
is worked out on the first call of the pair and kept (run/call_plan.py).
"""

from __future__ import annotations

import types
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import checks as run_checks
from .adaptive_driver import integrate_adaptive
from .call_plan import element_method, method_plan, run_params
from ..codegen.keys import regeneration_command_for
from .control import attach_inputs_outputs, blame_inputs, controlled_run
from ..errors import SimulationError
from .fixed_driver import allocate, integrate_fixed, n_steps_to
from ..jit.portable import choose, choose_controlled, jit_mode
from ..steppers.core import registry
from .run_result import adaptive_trajectory, fixed_step_trajectory
from .trajectory import Trajectory

__all__ = ["simulate", "Trajectory", "load_module"]


def load_module(module_or_path, out_dir=None, method=None, force=False, options=None,
                sensitivities=False):
    """A generated module from: the module itself, a generated .py, or a model file (generated
    into ``out_dir`` first when missing or stale, keeping the freeze, build options and methods
    of the module on disk, see loader.load). When the module lacks the glue of the method that
    runs ``method`` on it (e.g. nonsmooth_euler for implicit_euler on a model with elements), it
    is regenerated with that method added. ``force`` overwrites a module generated from another
    model file or with another freeze. ``options``: build() options of a model file (None: those
    of the module on disk). ``sensitivities``: a model file's module has the parameter
    derivatives of forward sensitivities (regenerated with them when it lacks them)."""
    if isinstance(module_or_path, types.ModuleType):
        return module_or_path
    from .loader import load, read_key
    if options and read_key(Path(module_or_path)) is not None:
        raise SimulationError(f"{module_or_path} is a generated module: build options "
                              f"({', '.join(options)}) apply to model files; pass the model file")
    module = load(Path(module_or_path), out_dir=out_dir, options=options, force=force,
                  sensitivities=sensitivities)
    if method is None or getattr(module, "KEY", None) is None:
        return module
    runs = element_method(module, method)
    if runs in registry.METHODS and not hasattr(module, f"run_{runs}"):
        module = load(Path(module_or_path), out_dir=out_dir, methods=[runs], options=options,
                      force=force, sensitivities=sensitivities)
    return module


def _runner(module, method):
    run = getattr(module, f"run_{method}", None)
    if run is None:
        have = ", ".join(getattr(module, "METHODS", ())) or "none"
        raise SimulationError(
            f"{module.NAME}: module {module.__file__} was generated without method {method!r} "
            f"(it has: {have}); run `{regeneration_command_for(module, methods=[method])}`")
    return run


def simulate(module_or_path, method="midpoint", q0=None, v0=None, *, t_end=None, h=None,
             params=None, save_every=1, t_eval=None, t0=0.0, progress=False, out_dir=None,
             element_state0=None, force=False, keep=None, control=None, control_params=None,
             jit=None, penetration="project", sensitivities=None, **settings) -> Trajectory:
    """Integrate a generated model from t0 to t_end.

    module_or_path: a generated module, the path of a generated .py, or a model file (generated
        into out_dir, default the model's own place, when missing or stale; see load_module, and
        ``force`` there).
    method: explicit_euler, symplectic_euler, verlet, midpoint, implicit_euler, rk4, dop853,
        composition, composition6, nonsmooth_euler, rattle, constrained_midpoint,
        constrained_implicit_euler, spook, index1, moreau_jean, spook_contacts, dop853_impacts,
        nonholonomic_rk4, nonholonomic_midpoint. (steppers/core/registry.py METHODS; which fit
        which model: docs/guides/choosing-a-method.md, ``lagrange-gen simulate --help``.)
    q0, v0: initial coordinates and velocities (n,), default zeros.
    t_end: the time the run ends (required).
    h: the step of a fixed-step method (required); for an adaptive method (dop853) only the
        first step tried (default: chosen automatically).
    params: dict {name: value} overriding the defaults, or a full sequence in PARAMS order; a
        parameter without default must be given.
    save_every: fixed-step methods keep every save_every-th state (the initial and the final
        state are always kept).
    t_eval: adaptive methods return the states at these increasing times in [t0, t_end] (from
        the dense output); default: the state after every accepted step.
    element_state0: initial states of the nonsmooth elements (ne,), default 0 (virgin material).
        On models with elements, method implicit_euler runs nonsmooth_euler; the trajectory's
        energy then includes the elastic energy k u^2 / 2 stored in Saint-Venant elements.
    settings: the method's settings by name (its SPEC.settings record; a name the method does
        not have is refused): blowup_bound (BlowUp when |q| or |v| exceeds it) for every method;
        newton_tol (relative to max(1, |unknown|), see steppers.core.newton.newton_converged) and
        max_iter for the implicit ones; newton_always (the Newton path of the partitioned
        methods even when the model allows the explicit one); spook's compliance (epsilon >= 0)
        and relaxation (d > 0); index1's baumgarte = (alpha, beta); dop853's rtol, atol, h_max.
    control: the model's inputs (Model inputs=) inside the loop: a numba-jitted controller
        u = f(t, q, qd, p) or a lagrange_gen.run.control.Signal (see lagrange_gen.run.control); constant
        inputs are given in params. The Trajectory then saves "input_<name>" and, for a model
        with outputs, "output_<name>" (Trajectory.saved).
    jit: which compiled loop runs (lagrange_gen.jit.portable). "specialized": the generated
        module's run_<method>, the model's kernels inlined into the stepper (fastest per step;
        its first use compiles the stepper for this model, seconds). "portable": the stepper
        compiled once for every model, calling this model's kernels through pointers (a new
        model compiles only its kernels; 1.4x to 2.2x the specialized step time on the cart
        pendulum, within 10 % on the 16-link chain; the same results bit for bit). "auto" (default): specialized when numba's cache already
        holds it, else portable, switching to specialized between chunks of a fixed-step run
        whose remaining time would pay for the compile (fixed_run.SPECIALIZE_AFTER_S); a
        fixed-step run whose method numba has compiled nowhere yet starts "interpreted" (the
        same code as Python, jit/interpreted.py) and compiles only when that would pay. A run
        with control= takes the portable controlled glue (compiled once per method for every
        model and controller, the controller reached through a pointer) when numba's cache
        holds it and the specialized loop of this controller is not compiled in this process,
        else that specialized loop (lagrange_gen.run.control). None: the environment variable
        LAGRANGE_GEN_JIT, else "auto". Trajectory.jit says what ran.
    control_params: parameters of the controller (a 1-D sequence of numbers c, e.g. gains),
        which then takes them last: u = f(t, q, qd, p, c). New values of c run the loop
        compiled for the controller without compiling.
    Constrained models (``constraints=`` in the model) need a constrained method
    (steppers.registry.CONSTRAINED_METHODS); q0, v0 off the constraints are projected onto them
    with a warning (lagrange_gen.run.consistent), and the Trajectory carries the multipliers and
    max|Phi|, max|J v| per saved state. ``keep``: names of velocities (``theta_dot``, or the
    coordinate ``theta``) whose v0 the projection keeps; the others are solved from J v = 0.
    A contact method whose q0 lies inside a contact (a gap < 0) warns in one line naming the
    contact and its gap, then by ``penetration``: "project" (default) moves q0 to the nearest
    point with every gap >= 0 and removes the approaching normal velocity there (an inelastic
    impulse: no kinetic energy added), "refuse" raises ContactPenetration, "keep" leaves it
    there (lagrange_gen.run.contact_start).
    sensitivities: names of parameters, "q0" and "v0" whose forward sensitivities the run
        computes (run/sensitivities.py; explicit_euler, symplectic_euler, verlet, midpoint,
        implicit_euler, rk4): ``traj.sensitivity(name)`` is d(q, v)/d name at each saved row,
        (S, 2n) for a parameter, (S, 2n, n) for q0 and v0; the exact derivative of the
        method's steps. A model file is generated with the parameter derivatives of its kernels
        (lagrange-gen --sensitivities). Not with control= or on models with events; the
        Trajectory then has no work column nor energy warning.
    A fixed-step run ends at t0 + n_steps h with n_steps = (t_end - t0) / h rounded up.
    Raises SimulationError (bad input, one line naming it), NewtonDivergence (its subclass
    SingularNewtonMatrix: a singular Newton matrix), SingularMass, BlowUp (non-finite or past
    blowup_bound), StepSizeTooSmall (adaptive). A conservative run whose energy error passes
    energy_check.ENERGY_FRACTION of its energy scale warns (EnergyWarning, the line also in
    Trajectory.warnings).
    """
    check_required("simulate", t_end=t_end)
    if method not in registry.METHODS:
        raise SimulationError(registry.unknown_method(method))
    jit = jit_mode(jit)
    if sensitivities is not None:
        from .sensitivities import check_method
        check_method(method)
    module = load_module(module_or_path, out_dir, method, force,
                         sensitivities=sensitivities is not None)
    plan = method_plan(module, method)      # element_method, check_method, spec: once each
    method, spec = plan.runs, plan.spec
    run = _runner(module, method)
    n = module.N_COORDS
    h = check_times(spec, h, t0, t_end, save_every, t_eval)
    config = run_checks.method_settings(spec, settings) if settings else plan.default_settings
    q = run_checks.vector("q0", q0, n, module.COORDS)
    v = run_checks.vector("v0", v0, n, module.COORDS)
    p, hook, data = run_params(plan, module, params, control, control_params, h, t0, q, v)
    loop = None
    if hook is not None:          # the specialized loop of (model, method, hook); compiled on use
        loop = controlled_run(module, method, hook)
        run = _with_data(loop, data)
    run_checks.check_element_coefficients(module, p)
    run_checks.check_contact_coefficients(module, p, q)
    t0, t_end, save_every = float(t0), float(t_end), int(save_every)
    n_saved = plan.n_saved
    initial = np.zeros(0)
    constrained = spec.saves_constraints(module.N_CONSTRAINTS)
    if keep and not constrained:
        raise SimulationError(f"{module.NAME}: keep= ({', '.join(keep)}) chooses the velocities "
                              "kept when v0 is projected onto J v = 0; this model has no "
                              "constraints")
    if spec.constraints:
        q, v, initial = _constrained_start(module, q, v, p, t0,
                                           getattr(config, "newton_tol", 1e-12), keep)
    elif spec.contacts:          # (its prepare fills row 0; the contact work starts at 0)
        from .contact_start import contact_start
        q, v = contact_start(module, q, v, p, t0, penetration, stacklevel=3)
        initial = np.zeros(n_saved)
        if getattr(module, "N_NONHOLONOMIC", 0):   # v0 onto A v + b = 0 (moreau_jean)
            from .consistent import nonholonomic_start
            q, v = nonholonomic_start(module, q, v, p, t0, stacklevel=3)
        if constrained:          # the constrained fields come last (contact_kkt.CONTACT_SAVED)
            q, v, start = _constrained_start(module, q, v, p, t0, 1e-12, keep)
            initial[n_saved - start.shape[0]:] = start
    elif spec.nonholonomic:      # q0 onto Phi = 0, v0 onto A v + b = 0; prepare fills row 0
        from .consistent import nonholonomic_start
        q, v = nonholonomic_start(module, q, v, p, t0, stacklevel=3)
        initial = np.zeros(n_saved)
    elif n_saved:
        initial = run_checks.vector("element_state0", element_state0, n_saved, module.ELEMENTS)
    run_checks.check_events_at_start(module, q, v, t0, p)
    if spec.adaptive:
        task = _Task(module, spec, run, p, config, h, t0, 0, 1, jit=jit, layout=plan.layout)
        wanted = None if t_eval is None else np.asarray(t_eval, dtype=np.float64)
        out, compile_time, wall = integrate_adaptive(
            task, q, v, initial, t_end, None if wanted is None else wanted[wanted > t0], progress)
        return attach_inputs_outputs(adaptive_trajectory(task, out, wanted, wall, compile_time),
                                     module, p, hook, data)
    n_steps = n_steps_to(t0, t_end, h)
    overshoot = run_checks.step_past_end(module.NAME, method, t0, t_end, h, n_steps)
    if overshoot:
        warnings.warn(overshoot, stacklevel=2)
    run_checks.check_time_resolution(t0, t0 + n_steps * h, h, n_steps)
    run_checks.check_memory(module.NAME, n_steps, save_every, n, n_saved)
    if sensitivities is not None:
        if hook is not None:
            raise SimulationError("simulate: sensitivities with control= are not covered (give "
                                  "the inputs as parameters)")
        from .sensitivities import simulate_sensitivities
        return simulate_sensitivities(module, method, q, v, p, config, h, t0, n_steps,
                                      save_every, sensitivities)
    task = _Task(module, spec, run, p, config, h, t0, n_steps, save_every, hook is not None,
                 jit=jit, hook=hook, layout=plan.layout, data=data, loop=loop)
    out = allocate(run_checks.saved_rows(n_steps, save_every), n, n_saved, initial,
                   getattr(module, "N_EVENTS", 0))
    try:
        compile_time, wall = integrate_fixed(task, q, v, out, progress)
    except SimulationError as exc:
        if hook is None:
            raise
        raise blame_inputs(exc, module, task.p, control,
                           None if control_params is None else data) from None
    traj = fixed_step_trajectory(task, out, wall, compile_time)
    if overshoot:
        traj.warnings.insert(0, overshoot)
    if constrained:
        violated = run_checks.constraint_violation(module.NAME, method, traj.t, traj.q,
                                                   traj.saved.get("constraint_error"))
        if violated:
            traj.warnings.append(violated)
            warnings.warn(violated, stacklevel=2)
    return attach_inputs_outputs(traj, module, p, hook, data)


def _with_data(run, data):
    """The glue signature of a run with an input hook (control.controlled_run): data bound."""
    return lambda *args: run(*args, data)


#: What each argument check_required asks for is, in the words of its line.
_REQUIRED = {"t_end": "the time the run ends, e.g. t_end=10.0",
             "h": "the step of the fixed-step method, e.g. h=1e-3"}


def check_required(function, **values):
    """SimulationError naming the first of ``values`` (argument name: value) that is None, in
    one line: "simulate: t_end (the time the run ends, e.g. t_end=10.0) is required"."""
    for name, value in values.items():
        if value is None:
            raise SimulationError(f"{function}: {name} ({_REQUIRED[name]}) is required")


def check_times(spec, h, t0, t_end, save_every, t_eval):
    """The step (float, or 0.0 for an adaptive method's automatic first step) after checking
    the time arguments; SimulationError naming the one that is wrong."""
    if spec.adaptive:
        run_checks.check_scalars(1.0 if h is None else h, t0, t_end, save_every)
        if save_every != 1:
            raise SimulationError(f"save_every is for the fixed-step methods; {spec.name} saves "
                                  f"every accepted step, or the times given as t_eval")
        if t_eval is not None:
            run_checks.check_t_eval(t_eval, t0, t_end)
        return 0.0 if h is None else float(h)
    if h is None:
        raise SimulationError(f"method {spec.name!r} has a fixed step: give h")
    if t_eval is not None:
        raise SimulationError(f"t_eval is for the adaptive methods "
                              f"({', '.join(registry.ADAPTIVE_METHODS)}); {spec.name} saves every "
                              f"save_every-th step")
    run_checks.check_scalars(h, t0, t_end, save_every)
    run_checks.check_step_count(float(t0), float(t_end), float(h))
    return float(h)


@dataclass
class _Task:
    """What one run integrates: the module, the method's spec and glue, and the run's numbers."""

    module: types.ModuleType
    spec: object        # the method's Spec
    run: object
    p: np.ndarray
    settings: tuple     # the method's settings record
    h: float            # the step (adaptive: the first step tried, 0 = automatic)
    t0: float
    n_steps: int        # fixed-step methods
    save_every: int
    controlled: bool = False    # inputs written by a controller or a signal (run/control.py)
    jit: str = "specialized"    # simulate(jit=): "auto", "specialized" or "portable"
    ran: str = ""               # what ran (Trajectory.jit), set by fixed_run / adaptive_run
    hook: object = None         # the input hook apply(data, t, q, v, p) (control.make_apply)
    layout: tuple = None        # ((name, start, width), ...) of the saved fields (MethodPlan)
    data: object = None         # the hook's data vector (control.resolve_inputs)
    loop: object = None         # the specialized loop with the hook (control.controlled_run),
    #                             which ``run`` calls with data bound

    def ready_key(self):
        """What the glue's choice and compile depend on, besides argument types that simulate
        makes the same for every run of a module and method (fresh writable float64 arrays, the
        method's settings record): the drivers remember the choice per key (ready_glue)."""
        m = self.module
        return (m.__name__, m.KEY, self.spec.name, self.jit, type(self.settings), self.hook)

    def glue(self, args):
        """The glue to run (``run`` or the portable one, see portable.choose, and for a run
        with an input hook portable.choose_controlled) for a first call with ``args``; records
        the choice in ``ran``."""
        if self.hook is not None:
            run, self.ran = choose_controlled(self.jit, self.run, bool(self.loop.overloads),
                                              self.module, self.method, self.hook, self.data)
        else:
            run, self.ran = choose(self.jit, self.run, self.module, self.method, args)
        return run

    @property
    def method(self):
        return self.spec.name

    @property
    def max_iter(self):
        return getattr(self.settings, "max_iter", 0)


def _constrained_start(module, q, v, p, t0, tol, keep=None):
    """The consistent initial state and row 0 of the saved fields of a constrained method:
    (q, v, [lam0, max|Phi|, max|J v|])."""
    from .consistent import consistent_initial_state
    # stacklevel 4: the warning points at the user's call of simulate().
    state = consistent_initial_state(module, q, v, p, t0, tol, stacklevel=4, keep=keep)
    initial = np.concatenate((state.lam, [state.phi_norm, state.jv_norm]))
    return np.ascontiguousarray(state.q), np.ascontiguousarray(state.v), initial
