"""`lagrange-gen bench contact`: work-precision of the contact methods against closed forms.

Three cases, each with an error measured against a closed form:

* bouncing ball (models/bouncing_ball.py, h0 = 1, e = 0.8, g = 9.81) at t_end = 3, in the
  flight after the 6th impact: max(|y - y_exact|, |v - v_exact|) at t_end, the exact motion
  being the parabolas between the impacts t_1 = sqrt(2 h0 / g), t_(k+1) = t_k + 2 e^k V0 / g;
* rocking block (models/rocking_block.py, Housner: b = 0.2, c = 0.6, e = 0, mu = 1) released at
  rest tilted by 0.15 rad on its left corner, at t_end = 1.5, after 3 impacts: between impacts
  the energy is conserved (the pivot sticks) and each plastic impact keeps the fraction
  r = (1 - 3/2 sin^2 alpha)^2 of the kinetic energy at phi = 0, so
  (E(t) - m g c) / (E0 - m g c) = r^k after k impacts; the error is that ratio's distance
  from r^3.

* puck on a table (models/puck_on_table.py, the 3D friction cone: mu = 0.3, launched at 2 m/s
  at 0.6 rad from the x axis) at t_end = 1, at rest since V0 / (mu g) = 0.68: the distance of
  (x, y) from the stop point V0^2 / (2 mu g) along the launch direction;
* slider-crank with clearance (models/slider_crank_clearance.py, Flores, Leine, Glocker 2010,
  e = 0.4, mu = 0.01, the crank at 150 rad/s) at t_end = 0.2: no closed form, so the
  difference of the crank's revolutions q1 / (2 pi) at t_end from Siconos' published reference
  run (siconos/siconos, examples/Mechanics/SliderCrank/
  SliderCrankMoreauJeanDirectProjectionOSI.ref, last row: 3.064804887294570 revolutions;
  Moreau-Jean with position projection at h = 1e-4 and a randomized contact solver). Not a
  convergence error: the motion after the first impacts depends on the impact sequence (with
  both corners of a wall hit at once the slider stays untilted in our runs, Siconos' run tilts
  it), so the row says how far apart two methods end, not which is right.
* woodpecker toy (models/woodpecker.py, Glocker; Siconos' example, constants of
  siconos/siconos-tutorials examples/mechanics/Woodpecker/WoodPeckerConsts.h) at
  t_end = 0.29998: the sleeve's height y against the last row of Siconos' published reference
  run Woodpecker.ref (Moreau-Jean, theta = 1/2, h = 2e-5): y = -0.04134818676833654. The
  reference is itself a numerical solution (its own error unknown), so the row is a distance
  between two methods; the descent over 0.3 s is a cumulative quantity, robust to the phase
  of the jam-slip cycle. Its start lies 8.8e-7 inside the sleeve's upper contact (the
  example's phi_M_0 = -0.1036 rounded), which simulate projects out with a warning.

Methods: the fixed-step moreau_jean and spook_contacts (h = t_end / (n0 2^k) each) and
dop853_impacts (rtol sweep, atol = rtol / 100).
Siconos (Moreau-Jean time stepping, the reference peer) runs when the package ``siconos`` is
importable; the report says so when it is not. Time: simulate's integration wall time (the glue
compiled before the clock starts), the fastest of ``repeats``.
"""

from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import common
from ..analysis import runs

G = 9.81

#: The fixed-step contact methods the suite sweeps in h (their markers in the figure).
FIXED_STEP = (("moreau_jean", "o"), ("spook_contacts", "^"))


@dataclass(frozen=True)
class Case:
    """One model of the suite: start, end time, parameters, the error of a run (a function of
    the Trajectory) and what it measures."""

    stem: str
    title: str
    q0: tuple
    v0: tuple
    t_end: float
    params: tuple
    error: object
    measures: str


def ball_state(t, h0=1.0, e=0.8, g=G):
    """The exact (y, v) of the ball dropped from rest at h0 on the floor y = 0, at time t
    (before the accumulation time)."""
    v0 = math.sqrt(2 * g * h0)
    t_impact = math.sqrt(2 * h0 / g)
    if t < t_impact:
        return h0 - g * t * t / 2, -g * t
    speed = e * v0
    while t >= t_impact + 2 * speed / g:
        t_impact += 2 * speed / g
        speed *= e
    s = t - t_impact
    return speed * s - g * s * s / 2, speed - g * s


def _ball_error(traj):
    y, v = ball_state(float(traj.t[-1]))
    return max(abs(traj.q[-1, 0] - y), abs(traj.v[-1, 0] - v))


B, C, PHI0, ROCK_IMPACTS = 0.2, 0.6, 0.15, 3


def rocking_ratio(k):
    """Housner's energy fraction after k plastic impacts, r^k, r = (1 - 3/2 sin^2 alpha)^2."""
    alpha = math.atan2(B, C)
    return (1 - 1.5 * math.sin(alpha) ** 2) ** (2 * k)


def rocking_start():
    """(x, y, phi) with the left corner at the origin, tilted by PHI0."""
    return (-B + B * math.cos(PHI0) - C * math.sin(PHI0), B * math.sin(PHI0) + C * math.cos(PHI0),
            PHI0)


def _rocking_error(traj):
    rest = G * C                                    # m = 1: E of the block flat at rest
    ratio = (traj.energy[-1] - rest) / (traj.energy[0] - rest)
    return abs(ratio - rocking_ratio(ROCK_IMPACTS))


PUCK_SPEED, PUCK_ANGLE, PUCK_MU = 2.0, 0.6, 0.3


def _puck_error(traj):
    """Distance of the puck's final (x, y) from where Coulomb's disk stops it."""
    reach = PUCK_SPEED**2 / (2 * PUCK_MU * G)
    return math.hypot(traj.q[-1, 0] - reach * math.cos(PUCK_ANGLE),
                      traj.q[-1, 1] - reach * math.sin(PUCK_ANGLE))


#: Siconos' reference run of the slider-crank with clearance (the module docstring): crank
#: revolutions at t = 0.2.
SICONOS_SLIDER_CRANK_REVOLUTIONS = 3.064804887294570


def _slider_crank_difference(traj):
    return abs(traj.q[-1, 0] / (2 * math.pi) - SICONOS_SLIDER_CRANK_REVOLUTIONS)


#: Siconos' woodpecker reference (the module docstring): its start and the sleeve's height
#: in its last row.
WOODPECKER_START = ((0.0, -0.1036, -0.2788), (-0.3411, 4.8572e-15, -7.4583))
WOODPECKER_T_END = 0.29998
SICONOS_WOODPECKER_Y = -4.134818676833654e-02


def _woodpecker_difference(traj):
    return abs(traj.q[-1, 0] - SICONOS_WOODPECKER_Y)


CASES = (
    Case("bouncing_ball", "Bouncing ball (e = 0.8), t = 3 after 6 impacts", (1.0,), (0.0,), 3.0,
         (("g", G), ("e", 0.8)), _ball_error, "max(|y - y_exact|, |v - v_exact|) at t_end"),
    Case("rocking_block", "Rocking block (Housner, e = 0), t = 1.5 after 3 impacts",
         rocking_start(), (0.0, 0.0, 0.0), 1.5,
         (("g", G), ("b", B), ("c", C), ("e", 0.0), ("mu", 1.0), ("a_ground", 0.0)),
         _rocking_error, "|(E - m g c) / (E0 - m g c) - r^3| at t_end"),
    Case("puck_on_table", "Puck on a table (3D friction cone, mu = 0.3), t = 1 after its stop",
         (0.0, 0.0, 0.0), (PUCK_SPEED * math.cos(PUCK_ANGLE), PUCK_SPEED * math.sin(PUCK_ANGLE),
                           0.0), 1.0, (("g", G), ("mu", PUCK_MU)), _puck_error,
         "distance of (x, y) at t_end from the stop point V0^2 / (2 mu g) along v0"),
    Case("slider_crank_clearance", "Slider-crank with clearance (Flores et al. 2010), t = 0.2",
         (0.0, 0.0, 0.0), (150.0, -75.0, 0.0), 0.2, (("e", 0.4), ("mu", 0.01)),
         _slider_crank_difference,
         "|q1 / (2 pi) - 3.0648| at t_end, the crank's revolutions against Siconos' reference "
         "run (SliderCrankMoreauJeanDirectProjectionOSI.ref; a difference between two "
         "methods on a motion sensitive to its impact sequence, not an error)"),
    Case("woodpecker", "Woodpecker toy (Glocker; Siconos' example), t = 0.29998",
         *WOODPECKER_START, WOODPECKER_T_END, (), _woodpecker_difference,
         "|y - y_Siconos| at t_end, the sleeve's height against Siconos' reference run "
         "(Woodpecker.ref, Moreau-Jean at h = 2e-5: y = -0.0413482)"),
)


@dataclass(frozen=True)
class Settings:
    n0: int             # the fixed-step methods' steps at k = 0
    k_max: int
    rtols: tuple
    repeats: int
    budget: float       # stop a sweep after a run slower than this (s)


FULL = Settings(n0=100, k_max=9, rtols=tuple(10.0 ** -k for k in range(3, 13)), repeats=3,
                budget=5.0)
QUICK = Settings(n0=50, k_max=1, rtols=(1e-4, 1e-8), repeats=1, budget=1.0)


@dataclass
class Point:
    method: str
    param: float        # h (fixed-step methods) or rtol (dop853_impacts)
    wall: float
    error: float = math.nan
    failed: str = ""


def _runs(case, settings):
    """[(method, param, simulate keywords)] of the sweeps, in order."""
    out = []
    for method, _ in FIXED_STEP:
        for k in range(settings.k_max + 1):
            n = settings.n0 * 2 ** k
            h = case.t_end / n
            out.append((method, h, dict(h=h, save_every=n)))
    for rtol in settings.rtols:
        out.append(("dop853_impacts", rtol, dict(h=None, rtol=rtol, atol=rtol / 100)))
    return out


def sweep(mod, case, settings, progress):
    """The runs of one case -> [Point]; a method's sweep stops after a run over the budget."""
    p = runs.params_of(mod, **dict(case.params))
    q0, v0 = np.array(case.q0, float), np.array(case.v0, float)
    points, slow = [], set()
    for method, param, kwargs in _runs(case, settings):
        progress.step(f"{case.stem} {method} {param:.1e}")
        if method in slow:
            continue
        h = kwargs.pop("h")
        run = runs.guarded_run(mod, method, q0, v0, h, case.t_end, p,
                               repeats=settings.repeats, **kwargs)
        if not run.ok:
            points.append(Point(method, param, run.wall, failed=runs.short_error(run.error)))
            continue
        points.append(Point(method, param, run.wall, case.error(run.traj)))
        if run.wall > settings.budget:
            slow.add(method)
    return points


def fitted_order(points, method="moreau_jean"):
    """The slope of log(error) against log(h) over a method's fixed-step points (None with
    fewer than 3 finite ones)."""
    xs = [(math.log(pt.param), math.log(pt.error)) for pt in points
          if pt.method == method and pt.error > 0 and math.isfinite(pt.error)]
    if len(xs) < 3:
        return None
    x, y = np.array(xs).T
    return float(np.polyfit(x, y, 1)[0])


def figure(results, path):
    """Error against wall time, one panel per case, one line per method."""
    fig, axes = common.new_figure(1, len(results), figsize=(5.5 * len(results), 4.2))
    axes = np.atleast_1d(axes)
    for ax, (case, points) in zip(axes, results):
        for method, marker in (*FIXED_STEP, ("dop853_impacts", "s")):
            pts = [pt for pt in points if pt.method == method and not pt.failed]
            if pts:
                ax.loglog([max(pt.wall, 1e-7) for pt in pts],
                          [max(pt.error, 1e-17) for pt in pts], marker=marker, label=method)
        ax.set_title(case.title, fontsize=9)
        ax.set_xlabel("integration wall time (s)")
        ax.set_ylabel("error against the closed form")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    common.save_figure(fig, path)


def _table(points):
    rows = [(pt.method, f"{pt.param:.2e}", runs.fmt(pt.wall * 1e3, ".3g"),
             pt.failed or runs.fmt(pt.error)) for pt in points]
    return runs.md_table(["method", "h or rtol", "wall (ms)", "error"], rows)


def siconos_line():
    """What the report says about the Siconos peer."""
    if importlib.util.find_spec("siconos") is None:
        return ("Siconos (the reference Moreau-Jean implementation) is not installed in this "
                "environment, so it is not compared here.")
    return ("Siconos is installed, but this suite does not drive it yet: its runs are not in "
            "the tables.")


def run_contact(models_dir="models", gen_dir="generated", reports_dir="reports", quick=False,
                progress=True):
    """Run the suite; writes reports_dir/contact.md and contact_precision.png. Returns
    {"results": [(case, [Point])], "report": path}."""
    settings = QUICK if quick else FULL
    cases = [c for c in CASES if runs.model_available(models_dir, c.stem)]
    total = len(cases) * (len(FIXED_STEP) * (settings.k_max + 1) + len(settings.rtols))
    bar = common.Progress(total, "contact", enabled=progress)
    lines = ["# Contact and impacts: work-precision", "",
             "moreau_jean and spook_contacts (order 1, fixed step) against dop853_impacts "
             "(event-driven, "
             "adaptive), each run's error against a closed form; time is simulate's "
             "integration wall time (fastest of "
             f"{settings.repeats}){' (--quick settings)' if quick else ''}.", "",
             siconos_line(), ""]
    results = []
    for case in cases:
        mod = runs.load_module(models_dir, case.stem, gen_dir)
        points = sweep(mod, case, settings, bar)
        results.append((case, points))
        lines += [f"## {case.title}", "", f"Error: {case.measures}.", ""]
        for method, _ in FIXED_STEP:
            order = fitted_order(points, method)
            if order is not None:
                lines += [f"{method}'s fitted order (slope of log error against log h): "
                          f"{order:.2f}.", ""]
        lines += [*_table(points), ""]
    bar.finish()
    missing = [c.stem for c in CASES if c not in cases]
    if missing:
        lines += [f"Model files missing from {models_dir}: {', '.join(missing)}.", ""]
    if results:
        figure(results, Path(reports_dir) / "contact_precision.png")
        lines += ["![work-precision](contact_precision.png)", ""]
    path = common.write_report(Path(reports_dir) / "contact.md", lines)
    return {"results": results, "report": path}
