"""Identification of the generalized Prandtl model with linear hardening from a loading half-cycle.

Model (Lamarque's lecture, slides 19-26)::

    m x'' + c x' + k0 x + sum_{i=1}^n k_i u_i = F(t),    u_i' + dpsi_[-eta_i, eta_i](u_i) ∋ x'.

Method. In the plane (x, y) with y = F - m x'' - c x' = k0 x + sum k_i u_i, take a loading
branch: x increasing from a turning point x_turn at which every element is saturated at
u_i = -eta_i. Element i then follows u_i = -eta_i + (x - x_turn) until it saturates at +eta_i, at
x - x_turn = 2 eta_i. With eta_1 < ... < eta_n the branch is continuous and piecewise linear
with slopes p_j = k0 + sum_{l>=j} k_l (decreasing) and breakpoints at x_turn + 2 eta_j. Hence::

    k0 = p_{n+1},   k_j = p_j - p_{j+1},   eta_j = (breakpoint_j - x_turn) / 2.

The slopes and breakpoints come from a continuous piecewise-linear least-squares fit with free
breakpoints (module piecewise: global dynamic-programming segmentation, then joint refinement), or
from the lecture's wavelet localisation of the kinks (module wavelet) refined by the same least
squares. The number of elements is given, or chosen by the Bayesian information criterion.

Records longer than a half-cycle are cut into monotone runs at the turning points of x. The
loading branch is the rise that best satisfies the saturation assumption below; every other run
(falling ones mirrored, by the centre symmetry of the cycle) that starts after an excursion of
at least 2 max(eta) obeys the same law, so all of them are refitted jointly (shared slopes and
breakpoints, an offset each), which averages the noise over the recorded cycles. Inside a run,
samples of minor loops (x retreating less than the turning-point threshold) are dropped: by the
return-point memory of the play operator the state is back on the branch once x passes its
previous extreme.

Assumptions: the element thresholds are distinct; the damping c is known (pass it with velocities
or times; c = 0 by default) and m x'' is already subtracted; a branch starts at a turning point
reached after a monotone excursion of at least 2 max(eta) (true on a steady symmetric cycle that
unlocks every element), otherwise the elements are not all saturated there and the breakpoints
move (checked when the record shows the excursion, a warning otherwise); noise is additive on
y, and x is much less noisy than its advance per sample.

Over 300 lines with its documentation: a quarter of the module is the derivation above and
the reasons of each step; the code is about 270 lines.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import IdentificationError
from .piecewise import fit_hinges, fit_piecewise

MIN_POINTS = 3          # samples per linear piece: two fix a line, one more to see its residual
SIGNIFICANCE = 4.0      # a slope change counts when it exceeds this many standard errors ...
RELATIVE_CHANGE = 1e-6  # ... and this fraction of the largest slope (clean data: round-off level)
REVERSAL = 0.01         # x must retreat by this fraction of its range to count as a turning point


@dataclass
class PrandtlFit:
    """Identified parameters; n = number of elements, arrays sorted by increasing threshold.

    k0: hardening stiffness; k: (n,) element stiffnesses; eta: (n,) thresholds (alpha = k eta is
    the yield force); slopes: (n+1,) branch slopes p_j; breakpoints: (n,) abscissae of the kinks
    (x_turn + 2 eta); *_stderr: standard errors of the estimates; noise: noise level of y used;
    rms: residual root mean square; branches: [(start, stop)] index ranges of the runs used, the
    loading branch first (x_turn and breakpoints refer to it); warnings: checks of the
    assumptions that could not be confirmed, one sentence each.
    """

    k0: float
    k: np.ndarray
    eta: np.ndarray
    slopes: np.ndarray
    breakpoints: np.ndarray
    x_turn: float
    k0_stderr: float
    k_stderr: np.ndarray
    eta_stderr: np.ndarray
    noise: float
    rms: float
    n_samples: int
    branches: list
    method: str
    warnings: list = field(default_factory=list)

    @property
    def n_elements(self):
        return len(self.k)

    @property
    def alpha(self):
        """(n,) yield forces k_i eta_i."""
        return self.k * self.eta

    def summary(self):
        """Multi-line text table of the parameters (what the CLI prints)."""
        lines = [f"generalized Prandtl model, {self.n_elements} element(s), from "
                 f"{self.n_samples} samples of {len(self.branches)} branch(es) "
                 f"({self.method} fit, residual rms {self.rms:.3g})",
                 f"k0 = {self.k0:.6g} +- {self.k0_stderr:.2g}",
                 f"{'i':>3} {'k_i':>12} {'+-':>8} {'eta_i':>12} {'+-':>8} {'alpha_i':>12}"]
        for i, (k, dk, e, de, a) in enumerate(zip(self.k, self.k_stderr, self.eta,
                                                  self.eta_stderr, self.alpha), 1):
            lines.append(f"{i:>3} {k:>12.6g} {dk:>8.2g} {e:>12.6g} {de:>8.2g} {a:>12.6g}")
        lines.append("slopes p_j: " + ", ".join(f"{p:.6g}" for p in self.slopes))
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)


def _samples(x, y):
    """Validated float arrays of shape (N,)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.ndim != 1 or x.shape != y.shape:
        raise IdentificationError(f"x and F - m x'' must be 1-D of the same length, got shapes "
                                  f"{x.shape} and {y.shape}")
    if len(x) < 8:
        raise IdentificationError(f"too few samples: {len(x)}, need at least 8")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise IdentificationError("x or F - m x'' holds NaN or infinite samples; remove them first")
    return x, y


def _turning_points(x, delta):
    """Indices of alternating extrema of x (N,); a reversal counts once x retreats by > delta."""
    lo = hi = 0
    direction, pivots, ext = 0, [], 0
    for i in range(1, len(x)):
        if direction == 0:
            lo = i if x[i] < x[lo] else lo
            hi = i if x[i] > x[hi] else hi
            if x[hi] - x[lo] > delta:  # the first clear move sets the direction
                direction = 1 if hi > lo else -1
                pivots.append(min(lo, hi))
                ext = max(lo, hi)
        elif direction * (x[i] - x[ext]) >= 0:
            ext = i
        elif direction * (x[ext] - x[i]) > delta:
            pivots.append(ext)
            ext, direction = i, -direction
    return pivots + [ext] if direction else pivots


def monotone_runs(x, reversal=REVERSAL):
    """Monotone runs of x (N,) between turning points: list of (start, stop, preceding excursion).

    A reversal counts once x retreats by more than `reversal` times its range, so noise on x does
    not split a run. The preceding excursion is |x[start] - x at the turning point before start|;
    it is 0 for the first run, which starts from the initial state rather than a turning point.
    """
    x = np.asarray(x, dtype=float)
    span = float(np.ptp(x)) if len(x) else 0.0
    if span == 0.0:
        raise IdentificationError("no loading phase: x is constant, so it never increases")
    pivots = _turning_points(x, reversal * span)
    before = [0.0] + [abs(x[p] - x[o]) for o, p in zip(pivots, pivots[1:])]
    return [(p, q, e) for p, q, e in zip(pivots, pivots[1:], before)]


def loading_branch(x, reversal=REVERSAL):
    """(start, stop) indices of the loading branch of x (N,): a rise from a minimum to a maximum.

    The rising run chosen maximizes min(rise, preceding fall): the branch must show every kink and
    start where every element is saturated, which needs both to exceed 2 max(eta). So a steady
    cycle wins over a first loading from the initial state, and over a rise after a minor loop; a
    lone rising half-cycle is taken as it is. Among equal scores (a steady cycle) the last wins.
    """
    x = np.asarray(x, dtype=float)
    runs = [(p, q, min(x[q] - x[p], e)) for p, q, e in monotone_runs(x, reversal) if x[q] > x[p]]
    if not runs:
        raise IdentificationError(
            f"no loading phase: x never increases by more than {reversal:.0%} of its range; "
            f"need x rising from a turning point")
    score = np.array([max(s, 0.0) for _, _, s in runs])
    if score.max() == 0.0:  # no rise follows a recorded fall: take the widest rise
        score = np.array([x[q] - x[p] for p, q, _ in runs])
    best = np.flatnonzero(score >= score.max() * (1 - 1e-6))[-1]
    return runs[best][:2]


def _restoring_force(x, y, damping, velocity, t):
    """y - c x' with x' given, or from times t by second-order differences; shapes (N,)."""
    if not damping:
        return y
    if velocity is None and t is None:
        raise IdentificationError("damping given but neither velocity nor t: cannot form c x'")
    given = np.asarray(velocity if velocity is not None else t, dtype=float)
    if given.shape != x.shape:
        raise IdentificationError(f"velocity/t has shape {given.shape}, x has {x.shape}")
    v = given if velocity is not None else np.gradient(x, given)
    return y - damping * v


def identify_prandtl(x, F_minus_mxdd, n_elements=None, noise=None, *, damping=0.0, velocity=None,
                     t=None, method="pwl", branches="all", max_elements=7):
    """Identify k0, k_i, eta_i from samples of the (x, F - m x'') curve.

    x, F_minus_mxdd: (N,) samples of a loading half-cycle, or of longer records (full cycles).
    The loading branch of x (see loading_branch) is identified first; with branches="all" every
    other monotone run (rising, or falling and mirrored) that starts after an excursion of at least
    2 max(eta) is then fitted jointly with it (shared slopes and breakpoints), which averages the
    noise over all recorded cycles; branches="one" uses the loading branch only. n_elements:
    number of Saint-Venant elements, or None to choose it (BIC, at most max_elements). noise:
    standard deviation of the noise on F - m x'' (None: estimated). damping: known viscous
    coefficient c, subtracted as c x' with x' from velocity (N,) or from times t (N,). method:
    "pwl" (dynamic-programming segmentation) or "wavelet" (kinks located by the Mexican-hat
    transform); both end with the same least-squares refinement. Returns a PrandtlFit; raises
    IdentificationError when the data do not determine the parameters.
    """
    x, y = _samples(x, F_minus_mxdd)
    if method not in ("pwl", "wavelet") or branches not in ("all", "one"):
        raise IdentificationError(f"method must be 'pwl' or 'wavelet' and branches 'all' or "
                                  f"'one', got {method!r} and {branches!r}")
    if n_elements is not None and int(n_elements) < 1:
        raise IdentificationError(f"n_elements must be at least 1, got {n_elements}")
    if noise is not None and not (np.isfinite(noise) and noise >= 0):
        raise IdentificationError(f"noise {noise!r}: must be a finite number >= 0 "
                                  "(the standard deviation of the noise on F - m x'')")
    y = _restoring_force(x, y, damping, velocity, t)
    start, stop = loading_branch(x)
    notes = []
    keep = _advancing(x, start, stop, notes)
    fit = _fit_branch(x[keep], y[keep], n_elements, noise, method, max_elements)
    notes += _warnings(x, start, fit)
    runs = [(start, stop)]
    if branches == "all":
        fit, runs = _pool_branches(x, y, fit, runs[0], noise, notes)
    return _prandtl_fit(fit, runs, method, notes, x[start])


def _advancing(x, p, q, notes):
    """Indices in [p, q] where x reaches a new extreme in the direction of the run (p to q).

    Inside a run x may retreat by less than the reversal threshold (a minor loop). The minor loop
    leaves the branch, but by return-point memory of the play operator the state is back on it
    when x passes its previous extreme, so only the advancing samples lie on the branch. Assumes
    the noise on x is small against its advance per sample; a large loss is reported in notes.
    """
    sign = 1.0 if x[q] >= x[p] else -1.0
    run = sign * x[p:q + 1]
    ahead = np.r_[True, run[1:] > np.maximum.accumulate(run)[:-1]]
    dropped = len(run) - int(ahead.sum())
    if dropped > 0.1 * len(run):
        notes.append(f"x is not monotone on the branch x[{p}:{q + 1}]: kept the "
                     f"{len(run) - dropped} samples where it advances, dropped {dropped} "
                     f"(minor loops or noise on x)")
    return np.flatnonzero(ahead) + p


def _fit_branch(xb, yb, n_elements, noise, method, max_elements):
    """Piecewise-linear fit of one rising branch (N,) whose every kink is a real slope drop."""
    order = np.argsort(xb, kind="stable")
    xb, yb = xb[order], yb[order]
    need = max(8, MIN_POINTS * ((n_elements or 1) + 1))
    if len(xb) < need:
        raise IdentificationError(f"too few samples: the loading branch has {len(xb)}, need at "
                                  f"least {need} ({MIN_POINTS} per linear piece)")
    init = _wavelet_init(xb, yb) if method == "wavelet" else None
    pieces = None if n_elements is None else int(n_elements) + 1
    fit, _ = fit_piecewise(xb, yb, pieces, noise, init, max_segments=max_elements + 1,
                           min_points=MIN_POINTS)
    if fit is None:  # the samples pile up on too few distinct x for the pieces asked
        raise IdentificationError(f"too few samples: the loading branch cannot hold {pieces} "
                                  f"pieces of {MIN_POINTS} samples")
    n_good = _count_kinks(fit)
    if n_elements is None and 0 < n_good < len(fit.breakpoints):
        # BIC kept a kink that fails the significance test: refit with the significant ones only.
        fit, _ = fit_piecewise(xb, yb, n_good + 1, noise, init, min_points=MIN_POINTS)
        n_good = _count_kinks(fit)
    if n_good == 0 and n_elements is None:
        raise IdentificationError("no slope change on the loading branch: no element slips "
                                  "(purely elastic response, or forcing too weak)")
    if n_good < len(fit.breakpoints):
        raise IdentificationError(
            f"fewer breakpoints than elements: {n_good} significant slope change(s) on the "
            f"loading branch, {len(fit.breakpoints)} element(s) asked for (forcing too weak to "
            f"unlock them all, or ask for fewer)")
    return fit


def _pool_branches(x, y, fit, branch, noise, notes):
    """Joint refit over the loading branch and every run that starts after a full excursion.

    A falling run is mirrored (x_turn - x, -y): by the centre symmetry of the cycle it is then a
    loading branch with the same slopes and breakpoints. Returns (fit, runs used).
    """
    need = (fit.breakpoints[-1] - fit.x_lo) * 1.02  # margin for the breakpoint's own error
    runs = [branch] + [(p, q) for p, q, before in monotone_runs(x)
                       if before >= need and (p, q) != branch]
    if len(runs) == 1:
        return fit, runs
    dx, dy, groups = [], [], []
    for g, (p, q) in enumerate(runs):
        sign = 1.0 if x[q] > x[p] else -1.0
        keep = _advancing(x, p, q, notes if g else [])  # the loading branch was reported already
        dx.append(sign * (x[keep] - x[p]))
        dy.append(sign * y[keep])
        groups.append(np.full(len(keep), g))
    joint = fit_hinges(np.concatenate(dx), np.concatenate(dy), fit.breakpoints - fit.x_lo, noise,
                       np.concatenate(groups))
    if _count_kinks(joint) < len(fit.breakpoints):
        notes.append(f"the {len(runs)} branches disagree (a kink vanishes in their joint fit): "
                     f"kept the loading branch alone")
        return fit, [branch]
    return joint, runs


def _wavelet_init(xb, yb):
    """Initial breakpoints for K pieces: the K-1 strongest wavelet kinks, sorted (None: too few)."""
    from .wavelet import wavelet_breakpoints
    locations, _ = wavelet_breakpoints(xb, yb)

    def init(k):
        return np.sort(locations[:k - 1]) if len(locations) >= k - 1 else None
    return init


def _count_kinks(fit):
    """Number of slope changes that are decreases, significant, and flanked by enough samples.

    Raises IdentificationError on a significant slope increase or a negative last slope: neither
    can occur on a loading branch of the model (k_i > 0, k0 >= 0).
    """
    change = fit.slope_changes
    real = (np.abs(change) > SIGNIFICANCE * fit.change_stderr()) & (
        np.abs(change) > RELATIVE_CHANGE * np.abs(fit.slopes).max())
    flanked = (fit.counts[:-1] >= MIN_POINTS) & (fit.counts[1:] >= MIN_POINTS)
    rising = real & flanked & (change > 0)
    if rising.any():
        j = int(np.flatnonzero(rising)[0])
        raise IdentificationError(
            f"slope increases by {change[j]:.3g} at x = {fit.breakpoints[j]:.6g}: not a loading "
            f"branch of a generalized Prandtl model (slopes must decrease, k_i > 0)")
    if fit.slopes[-1] < -SIGNIFICANCE * fit.last_slope_stderr():
        raise IdentificationError(f"last slope {fit.slopes[-1]:.3g} is negative: k0 >= 0 fails, "
                                  f"not a loading branch of a generalized Prandtl model")
    return int(np.count_nonzero(real & flanked))


def _prandtl_fit(fit, runs, method, warnings, x_turn):
    """PrandtlFit from a HingeFit whose every kink is a significant slope decrease.

    fit.x_lo is the turning point of the fitted abscissae (0 for a joint fit, whose abscissae are
    distances from each run's turning point); x_turn is that of the loading branch.
    """
    eta = (fit.breakpoints - fit.x_lo) / 2
    return PrandtlFit(
        k0=float(fit.slopes[-1]), k=-fit.slope_changes, eta=eta, slopes=fit.slopes,
        breakpoints=x_turn + 2 * eta, x_turn=float(x_turn),
        k0_stderr=fit.last_slope_stderr(), k_stderr=fit.change_stderr(),
        eta_stderr=fit.breakpoint_stderr() / 2, noise=fit.sigma,
        rms=float(np.sqrt(fit.sse / fit.n_samples)), n_samples=fit.n_samples,
        branches=[(int(p), int(q)) for p, q in runs], method=method, warnings=warnings)


def _warnings(x, start, fit):
    """Checks of the saturation assumption that the data can support (list of messages)."""
    if not len(fit.breakpoints):
        return []
    need = fit.breakpoints[-1] - fit.x_lo
    fall = next(before for p, _, before in monotone_runs(x) if p == start)
    if fall == 0.0:
        return [f"no fall recorded before the turning point: assumed it was at least "
                f"2 max(eta) = {need:.4g}, so that every element starts saturated"]
    if fall < need:
        return [f"x fell by only {fall:.4g} before the turning point, less than 2 max(eta) = "
                f"{need:.4g}: the largest elements may not be saturated there"]
    return []
