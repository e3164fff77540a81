"""Continuous piecewise-linear least squares with free breakpoints (the hinge model).

Model, for samples (x, y) of shape (N,) sorted by x and K segments::

    y ≈ a + b (x - x_lo) + sum_{j=1}^{K-1} c_j max(0, x - beta_j)

so the slope is b on the first segment and changes by c_j at beta_j. Several branches can be
fitted together (groups): they share the slopes and breakpoints and each has its own intercept a.
The fit has two stages:

1. Coarse segmentation by dynamic programming: candidate boundaries on a grid of about 200 sample
   indices; each segment gets its own least-squares line (prefix sums make every segment cost O(1)),
   and the DP returns the K-segment partition of least total squared error. It is a global search,
   so the refinement starts in the right basin even on noisy data.
2. Refinement: nonlinear least squares on (a, b, c, beta) jointly (scipy's trust-region reflective
   solver, analytic Jacobian, beta kept inside the data range). On exact piecewise-linear data with
   samples on both sides of every kink the residual vanishes only at the true breakpoints, so the
   refinement recovers them to round-off.

When K is not given it is chosen by the Bayesian information criterion with a known or estimated
noise level: BIC_K = SSE_K / sigma^2 + 2 K log N (2K free parameters). Assumptions: the noise is
additive in y, independent, of one variance; x is exact (or much less noisy than y).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Relative floor on the noise level: clean data are exact to round-off, and without a floor the
# information criterion would reward any segment that shaves off round-off error.
_SIGMA_FLOOR = 1e-9


@dataclass
class HingeFit:
    """Fitted continuous piecewise-linear function, in the units of the data.

    x_lo: smallest x; intercepts: (G,) value at x_lo of each group; slopes: (K,) slope of each
    segment, left to right; breakpoints: (K-1,) sorted kink abscissae; counts: (K,) samples per
    segment; sse: residual sum of squares; sigma: noise level used for the standard errors;
    cov: (G + 2K - 1, G + 2K - 1) covariance of (intercepts, slopes[0], slope changes (K-1),
    breakpoints (K-1)); n_samples: N.
    """

    x_lo: float
    intercepts: np.ndarray
    slopes: np.ndarray
    breakpoints: np.ndarray
    counts: np.ndarray
    sse: float
    sigma: float
    cov: np.ndarray
    n_samples: int

    @property
    def slope_changes(self):
        """(K-1,) slopes[j+1] - slopes[j]."""
        return np.diff(self.slopes)

    def _std(self, start, stop):
        return np.sqrt(np.maximum(np.diag(self.cov)[start:stop], 0.0))

    def change_stderr(self):
        """(K-1,) standard errors of the slope changes."""
        g, m = len(self.intercepts), len(self.breakpoints)
        return self._std(g + 1, g + 1 + m)

    def breakpoint_stderr(self):
        """(K-1,) standard errors of the breakpoints."""
        g, m = len(self.intercepts), len(self.breakpoints)
        return self._std(g + 1 + m, g + 1 + 2 * m)

    def last_slope_stderr(self):
        """Standard error of slopes[-1] = slopes[0] + sum of the slope changes."""
        g, m = len(self.intercepts), len(self.breakpoints)
        grad = np.zeros(len(self.cov))
        grad[g:g + 1 + m] = 1.0
        return float(np.sqrt(max(grad @ self.cov @ grad, 0.0)))

    def predict(self, x, group=0):
        """Fitted values of one group at x (any shape)."""
        x = np.asarray(x, dtype=float)
        out = self.intercepts[group] + self.slopes[0] * (x - self.x_lo)
        for change, beta in zip(self.slope_changes, self.breakpoints):
            out = out + change * np.maximum(0.0, x - beta)
        return out


def noise_level(x, y):
    """Robust standard deviation of additive noise in y; x, y of shape (N,), x sorted.

    Each interior sample is compared with the chord through its two neighbours; on a piecewise
    linear signal that residual is pure noise except at the few samples next to a kink, which the
    median ignores. Returns 0 for fewer than 5 usable samples.
    """
    gap = x[2:] - x[:-2]
    ok = gap > 0
    if ok.sum() < 3:
        return 0.0
    w = (x[1:-1][ok] - x[:-2][ok]) / gap[ok]
    chord = (1.0 - w) * y[:-2][ok] + w * y[2:][ok]
    # Variance of y_i - chord_i is sigma^2 (1 + w^2 + (1 - w)^2); normalize before the median.
    r = (y[1:-1][ok] - chord) / np.sqrt(1.0 + w**2 + (1.0 - w) ** 2)
    return float(1.4826 * np.median(np.abs(r - np.median(r))))


def _segment_costs(x, y, bounds, min_points):
    """(M+1, M+1) squared error of one line over samples bounds[i]:bounds[j] (inf when invalid)."""
    xc, yc = x - x.mean(), y - y.mean()  # centring limits cancellation in the prefix sums
    sums = [np.concatenate(([0.0], np.cumsum(v))) for v in
            (np.ones_like(xc), xc, yc, xc * xc, xc * yc, yc * yc)]
    i, j = np.meshgrid(bounds, bounds, indexing="ij")
    n, sx, sy, sxx, sxy, syy = (s[j] - s[i] for s in sums)
    with np.errstate(divide="ignore", invalid="ignore"):
        vxx = sxx - sx * sx / n
        vxy = sxy - sx * sy / n
        vyy = syy - sy * sy / n
        cost = np.where(vxx > 0, vyy - vxy * vxy / vxx, vyy)
    cost = np.where(n >= min_points, np.maximum(cost, 0.0), np.inf)
    return np.where(j > i, cost, np.inf)


def dp_breakpoints(x, y, n_segments, min_points=3, n_candidates=200):
    """Initial breakpoints (n_segments - 1,) from the optimal partition into independent lines."""
    n = len(x)
    bounds = np.unique(np.round(np.linspace(0, n, min(n, n_candidates) + 1)).astype(int))
    cost = _segment_costs(x, y, bounds, min_points)
    best = cost[0].copy()
    back = []
    for _ in range(n_segments - 1):
        total = best[:, None] + cost
        back.append(np.argmin(total, axis=0))
        best = total[back[-1], np.arange(len(bounds))]
    if not np.isfinite(best[-1]):
        return None
    cuts, j = [], len(bounds) - 1
    for arg in reversed(back):
        j = arg[j]
        cuts.append(bounds[j])
    # A boundary index b splits samples b-1 | b: start the kink halfway between them.
    return np.array([0.5 * (x[b - 1] + x[b]) for b in reversed(cuts)])


def _design(xn, betas, onehot):
    return np.column_stack([onehot, xn] + [np.maximum(0.0, xn - b) for b in betas])


def _refine(xn, yn, betas0, onehot):
    """Joint least squares in normalized units; returns (params, jacobian, sse).

    Parameters: (G intercepts, first slope, m slope changes, m breakpoints in [0, 1]).
    """
    from scipy.optimize import least_squares  # deferred: scipy.optimize takes 0.3 s to import
    m, lead = len(betas0), onehot.shape[1] + 1
    lin0 = np.linalg.lstsq(_design(xn, betas0, onehot), yn, rcond=None)[0]

    def residual(p):
        return _design(xn, p[lead + m:], onehot) @ p[:lead + m] - yn

    def jacobian(p):
        betas, changes = p[lead + m:], p[lead:lead + m]
        kink = [-c * (xn > b) for c, b in zip(changes, betas)]
        return np.column_stack([_design(xn, betas, onehot)] + kink)

    lower = np.r_[np.full(lead + m, -np.inf), np.zeros(m)]
    upper = np.r_[np.full(lead + m, np.inf), np.ones(m)]
    p0 = np.r_[lin0, np.clip(betas0, 1e-12, 1 - 1e-12)]
    sol = least_squares(residual, p0, jac=jacobian, bounds=(lower, upper), method="trf",
                        xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=100 * (m + 1))
    return sol.x, jacobian(sol.x), float(sol.fun @ sol.fun)


def fit_hinges(x, y, betas0, sigma=None, groups=None):
    """Refine a continuous piecewise-linear fit from initial breakpoints betas0 (K-1,).

    x, y: (N,). groups: optional (N,) integers 0..G-1; each group gets its own intercept, the
    slopes and breakpoints are shared (several branches measured from their own turning points).
    sigma: known noise level of y (None: from the residuals). Returns a HingeFit with breakpoints
    sorted and covariance from the Gauss-Newton normal matrix.
    """
    groups = np.zeros(len(x), dtype=int) if groups is None else np.asarray(groups)
    onehot = (groups[:, None] == np.arange(groups.max() + 1)).astype(float)
    g, m, n = onehot.shape[1], len(betas0), len(x)
    x_lo, lx = x.min(), max(np.ptp(x), np.finfo(float).tiny)
    y_mid, ly = y.mean(), max(np.ptp(y), np.finfo(float).tiny)
    # Work on the unit box so that the solver tolerances and the bounds mean the same everywhere.
    p, jac, sse_n = _refine((x - x_lo) / lx, (y - y_mid) / ly,
                            (np.asarray(betas0, dtype=float) - x_lo) / lx, onehot)
    order = np.argsort(p[g + 1 + m:])
    perm = np.r_[np.arange(g + 1), g + 1 + order, g + 1 + m + order]
    p, jac = p[perm], jac[:, perm]
    scale = np.r_[np.full(g, ly), np.full(1 + m, ly / lx), np.full(m, lx)]
    sse = sse_n * ly**2
    dof = n - g - 1 - 2 * m
    used = max(sigma if sigma is not None else np.sqrt(sse / max(dof, 1)), _SIGMA_FLOOR * ly)
    cov = (used / ly) ** 2 * np.linalg.pinv(jac.T @ jac) * np.outer(scale, scale)
    betas = x_lo + lx * p[g + 1 + m:]
    slopes = np.cumsum(p[g:g + 1 + m]) * ly / lx
    edges = np.r_[-np.inf, betas, np.inf]
    counts = np.array([np.count_nonzero((x > lo) & (x <= hi)) for lo, hi in zip(edges, edges[1:])])
    return HingeFit(float(x_lo), y_mid + ly * p[:g], slopes, betas, counts, sse, used, cov, n)


def fit_piecewise(x, y, n_segments=None, sigma=None, init=None, max_segments=8, min_points=3):
    """Best continuous piecewise-linear fit of (x, y), shapes (N,), x sorted.

    n_segments: K, or None to choose K in 1..max_segments by BIC (the search stops two K past the
    best). sigma: noise level of y (None: estimated by noise_level). init: optional callable
    K -> initial breakpoints (K-1,) or None, tried before the dynamic-programming search.
    Returns (HingeFit, {K: BIC}); the fit is None when no K is feasible.
    """
    n = len(x)
    noise = noise_level(x, y) if sigma is None else float(sigma)
    noise = max(noise, _SIGMA_FLOOR * max(np.ptp(y), np.finfo(float).tiny))
    candidates = [n_segments] if n_segments else range(1, min(max_segments, n // min_points) + 1)
    best, scores = None, {}
    for k in candidates:
        if best is not None and k > len(best.slopes) + 2:
            break  # BIC rose twice after the best K: more pieces only fit noise, at growing cost
        start = np.empty(0) if k == 1 else (init(k) if init else None)
        if start is None:  # no initializer, or it found too few kinks: global DP search
            start = dp_breakpoints(x, y, k, min_points)
        if start is None:  # K pieces of min_points samples do not fit in the data
            continue
        fit = fit_hinges(x, y, start, sigma)
        scores[k] = fit.sse / noise**2 + 2 * k * np.log(n)
        if best is None or scores[k] < scores[len(best.slopes)]:
            best = fit
    return best, scores
