"""Wavelet detection of slope changes of a curve y(x) (the lecture's breakpoint localisation).

The Mexican hat (second derivative of a Gaussian, two vanishing moments) annihilates affine pieces,
so the continuous wavelet transform of a piecewise-linear signal is zero away from its kinks and, at
a kink of slope change dp, is a Gaussian bump centred on the kink: integrating by parts twice,
W(b, s) = -C dp s^{3/2} exp(-(x_kink - b)^2 / (2 s^2)). Dividing each scale by the response to a
unit kink, computed with the same transform, turns every scale into an estimate of dp at the kink;
averaging over a band of scales (weighted by the inverse noise variance) keeps the bumps (they are
centred on the kink at every scale) and averages the noise down.

Assumptions: y is sampled on a branch where x is (nearly) monotone; the samples are resampled onto
a uniform x grid by bin averaging (which also filters noise), and the grid is extended linearly
beyond both ends so that the ends of the data do not read as kinks. Kinks closer to each other, or
to an end, than a few analysing scales are not separated. Needs PyWavelets.
"""

from __future__ import annotations

import numpy as np

from ..errors import LagrangeGenError


def import_pywt():
    try:
        import pywt
    except ImportError as exc:  # optional dependency: say how to get it
        raise LagrangeGenError("wavelet identification needs PyWavelets "
                               "(pip install 'lagrange-gen[wavelets]')") from exc
    return pywt


def _uniform_grid(x, y, n_grid):
    """Bin averages of y on n_grid equal bins of [x.min(), x.max()]; returns (centres, values)."""
    edges = np.linspace(x.min(), x.max(), n_grid + 1)
    which = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, n_grid - 1)
    counts = np.bincount(which, minlength=n_grid)
    sums = np.bincount(which, weights=y, minlength=n_grid)
    centres = 0.5 * (edges[:-1] + edges[1:])
    filled = counts > 0
    # Empty bins (sparse sampling) take the linear interpolation of their neighbours.
    values = np.interp(centres, centres[filled], sums[filled] / counts[filled])
    return centres, values


def _extend_linearly(values, pad, window):
    """Append pad samples at each end continuing the least-squares line of the end windows."""
    i = np.arange(window)
    head = np.polyfit(i, values[:window], 1)
    tail = np.polyfit(i, values[-window:], 1)
    before = np.polyval(head, np.arange(-pad, 0))
    after = np.polyval(tail, np.arange(window, window + pad))
    return np.concatenate([before, values, after])


def _default_scales(n_grid):
    """Analysing scales in grid cells: fine enough to separate kinks 10% of the range apart."""
    return np.geomspace(max(2.0, n_grid / 200), max(3.0, n_grid / 25), 6)


def slope_change_profile(x, y, n_grid=None, scales=None):
    """Wavelet estimate of the slope change around each grid point.

    x, y: (N,) samples. n_grid: grid size (default min(1024, N // 2)). scales: analysing scales in
    grid cells (default 6 scales from n_grid/200 to n_grid/25). Returns (grid (G,), profile (G,)),
    where profile peaks at a kink with about its slope change dp (negative when the slope drops).
    """
    pywt = import_pywt()
    n_grid = int(n_grid or max(16, min(1024, len(x) // 2)))
    scales = _default_scales(n_grid) if scales is None else np.asarray(scales, dtype=float)
    grid, values = _uniform_grid(np.asarray(x, float), np.asarray(y, float), n_grid)
    pad = int(np.ceil(5 * scales.max()))
    signal = _extend_linearly(values, pad, max(3, n_grid // 20))
    coef = pywt.cwt(signal, scales, "mexh", method="fft")[0][:, pad:pad + n_grid]
    # Calibration: the same transform of a unit kink (slope change 1 per grid cell) at the centre.
    ref = np.maximum(0.0, np.arange(2 * pad + 1) - pad).astype(float)
    unit = pywt.cwt(ref, scales, "mexh", method="fft")[0][:, pad]
    dx = grid[1] - grid[0]
    # Every calibrated row estimates the same dp, but white noise in the row falls like s^{-3/2}
    # (the L2-normalized transform of noise does not depend on s, the kink response grows like
    # s^{3/2}): inverse-variance weights s^3.
    weights = scales**3 / np.sum(scales**3)
    return grid, weights @ (coef / unit[:, None]) / dx


def wavelet_breakpoints(x, y, n_grid=None, scales=None):
    """Candidate kinks of y(x), strongest first.

    x, y: (N,) samples. Returns (locations (P,), slope_changes (P,)): the local maxima of the
    modulus of slope_change_profile, at least two mean analysing scales apart, sorted by decreasing
    modulus. The caller keeps as many as it needs and refines them by least squares.
    """
    grid, profile = slope_change_profile(x, y, n_grid, scales)
    mag = np.abs(profile)
    peaks = np.flatnonzero((mag[1:-1] >= mag[:-2]) & (mag[1:-1] > mag[2:])) + 1
    scales = _default_scales(len(grid)) if scales is None else np.asarray(scales, dtype=float)
    gap = 2 * np.exp(np.mean(np.log(scales)))
    kept = []
    for p in peaks[np.argsort(-mag[peaks])]:
        # Non-maximum suppression: noise ripples on a bump are not separate kinks.
        if all(abs(p - q) >= gap for q in kept):
            kept.append(p)
    kept = np.array(kept, dtype=int)
    return grid[kept], profile[kept]
