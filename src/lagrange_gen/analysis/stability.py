"""Linear stability measured from the steppers themselves (HARD_CASES case 3, Lacoursiere's
slides), and the closed forms it must match.

Step matrix: one step of the real stepper, through ``simulate``, applied to the basis vectors
(x, v) = (1, 0) and (0, 1) of the oscillator x'' = -omega^2 x (models/damped_oscillator.py with
b = 0, c = 1 / omega^2); the two results are the columns of A(tau) (2, 2), tau = h omega.
rho(A) = max |eig(A)| decides: > 1 grows, = 1 neither grows nor damps, < 1 damps. The phase of
the eigenvalues per step, against the exact tau, is the method's frequency error.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from . import runs
from ..errors import EnergyWarning
from ..steppers.core import registry

OMEGA = 3.0        # not 1, so that h and tau differ and a wrong scaling would show
TAUS = (0.1, 1.0, 1.9, 1.99, 2.01, 10.0, 1000.0)       # HARD_CASES case 3


def oscillator(models_dir="models", gen_dir="generated"):
    """Generated module of the damped oscillator (the linear test system)."""
    return runs.load_module(models_dir, "damped_oscillator", gen_dir)


def step_matrix(mod, method, tau, omega=OMEGA):
    """A (2, 2): columns are one step of ``method`` from (x, v) = (1, 0) and (0, 1) on
    x'' = -omega^2 x with h = tau / omega. Raises SimulationError when the step fails."""
    from ..run.simulate import simulate
    p = runs.params_of(mod, m=1.0, c=1.0 / omega**2, b=0.0)
    h = tau / omega
    cols = []
    for x, v in ((1.0, 0.0), (0.0, 1.0)):
        with warnings.catch_warnings():   # unstable tau are the point of the scan
            warnings.simplefilter("ignore", EnergyWarning)
            tr = simulate(mod, method, [x], [v], t_end=h, h=h, params=p)
        cols.append([tr.q[-1, 0], tr.v[-1, 0]])
    return np.array(cols).T


def spectral_radius(A):
    """max |eig(A)| of a square matrix A (k, k)."""
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def phase_per_step(A):
    """Largest |arg(eig(A))| of A (k, k): the angle the method turns per step (exact: tau)."""
    return float(np.max(np.abs(np.angle(np.linalg.eigvals(A)))))


#: rho(tau) of each method's step matrix, method name -> f(tau) -> float: the closed forms the
#: methods declare (SPEC.rho, in their modules; HARD_CASES case 3 and Lacoursiere's slides).
CLOSED_FORMS = {m: registry.spec(m).rho for m in registry.METHODS
                if registry.spec(m).rho is not None}


def stability_limit(taus, rho, tol=1e-10):
    """Largest tau of the grid taus (T,) below which every measured rho (T,) <= 1 + tol; inf
    when the whole grid is stable, 0 when the first point already grows."""
    bad = np.nonzero(~(rho <= 1.0 + tol))[0]
    if len(bad) == 0:
        return math.inf
    return float(taus[bad[0] - 1]) if bad[0] > 0 else 0.0


def tau_table(mod, methods, taus=TAUS):
    """Rows (method, tau, measured rho, closed-form rho or None) at HARD_CASES case 3's taus."""
    rows = []
    for method in methods:
        closed = CLOSED_FORMS.get(method)
        for tau in taus:
            rho = spectral_radius(step_matrix(mod, method, tau))
            rows.append((method, tau, rho, closed(tau) if closed else None))
    return rows
