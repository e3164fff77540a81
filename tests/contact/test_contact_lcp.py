"""Lemke's method and the contact LCP (steppers/core/contact_lcp.py) alone, on problems with
hand-derived solutions, a degenerate two-contact problem where projected Gauss-Seidel stalls,
and Painleve's paradox (no solution)."""

import numpy as np
import pytest

from lagrange_gen.steppers.core.contact_lcp import (LCP_RAY, LCP_SOLVED, contact_solve,
                                                    lcp_arrays, lemke)
from lagrange_gen.steppers.core.contact_problem import (BILATERAL, COULOMB, SLIDE_POSITIVE,
                                                        UNILATERAL, gauss_seidel_sliding)
from lagrange_gen.steppers.core.status import CONTACT_NO_SOLUTION, OK


def _lemke(M, q):
    k = len(q)
    _, _, T, z, basis = lcp_arrays((k + 10) // 11)
    K = T.shape[0]
    T[:k, K:K + k] = -np.asarray(M, float)
    T[:k, 2 * K + 1] = q
    T[:k, 2 * K] = -1.0
    T[np.arange(k), np.arange(k)] = 1.0
    return lemke(k, T, basis, z, 100), z[:k].copy()


def test_lemke_hand_derived():
    """M = [[2, 1], [1, 2]], q = (-5, -6): both active, z = M^-1 (5, 6) = (4/3, 7/3); q = (-1, 3):
    z = (1/2, 0) with w2 = 3 + 1/2."""
    outcome, z = _lemke([[2, 1], [1, 2]], np.array([-5.0, -6.0]))
    assert outcome == LCP_SOLVED and np.allclose(z, [4 / 3, 7 / 3])
    outcome, z = _lemke([[2, 1], [1, 2]], np.array([-1.0, 3.0]))
    assert outcome == LCP_SOLVED and np.allclose(z, [0.5, 0.0])
    outcome, z = _lemke([[2, 1], [1, 2]], np.array([1.0, 3.0]))
    assert outcome == LCP_SOLVED and np.allclose(z, 0.0)


def test_lemke_no_solution_is_a_ray():
    """w = -z - 1 >= 0 has no z >= 0."""
    outcome, _ = _lemke([[-1.0]], np.array([-1.0]))
    assert outcome == LCP_RAY


def _problem(c, D, uf, coef, un=None, law=None, active=None):
    R = 3 * c
    law = np.array(law if law is not None else [UNILATERAL] * c + [COULOMB] * 2 * c, np.int64)
    active = np.ones(c) if active is None else np.asarray(active, float)
    un = np.zeros(c) if un is None else np.asarray(un, float)
    Dm = np.zeros((R, R))
    Dm[:len(D), :len(D)] = D
    ufv = np.zeros(R)
    ufv[:len(uf)] = uf
    return active, law, np.asarray(coef, float), un, ufv, Dm


def _solve(c, problem, max_sweeps=1000, tol=1e-12):
    active, law, coef, un, uf, D = problem
    r = np.zeros(3 * c)
    B, C, T, z, basis = lcp_arrays(c)
    status, sweeps, _ = contact_solve(c, tol, max_sweeps, active, law, coef, un, uf, D, r,
                                      np.zeros(2 * c), B, C, T, z, basis)
    return status, sweeps, r


def _lcp_only(c, problem):
    """The LCP's answer: Gauss-Seidel given no sweep."""
    return _solve(c, problem, max_sweeps=0)


def test_one_contact_impact_and_friction_hand_derived():
    """Impact: D_NN = 1, u_N- = -2, e = 1/2: p_N = -(uf + e un) / D = 3 (uf = -2).
    Friction (2D, rows N, T1 of contact 0): D = I, uf = (-1, 2), mu = 1/2: sticking needs
    p_T = -2, outside |p_T| <= mu p_N = 1/2, so it slides: p_N = 1, p_T = -1/2."""
    c = 1
    status, sweeps, r = _lcp_only(c, _problem(c, [[1.0]], [-2.0], [[0.5, 0.0]], un=[-2.0]))
    assert status == OK and sweeps == -1 and np.allclose(r, [3.0, 0.0, 0.0])
    status, _, r = _lcp_only(c, _problem(c, np.eye(2), [-1.0, 2.0], [[0.0, 0.5]]))
    assert status == OK and np.allclose(r, [1.0, -0.5, 0.0])
    # sticking when it fits: uf = (-1, 0.2): p_T = -0.2
    status, _, r = _lcp_only(c, _problem(c, np.eye(2), [-1.0, 0.2], [[0.0, 0.5]]))
    assert status == OK and np.allclose(r, [1.0, -0.2, 0.0])


def test_two_contacts_hand_derived():
    """Normals only, D = [[2, 1], [1, 2]], uf = (-3, -3): p = D^-1 (3, 3) = (1, 1); uf = (-3, 3):
    p = (3/2, 0)."""
    c = 2
    status, _, r = _lcp_only(c, _problem(c, [[2.0, 1.0], [1.0, 2.0]], [-3.0, -3.0],
                                         [[0, 0], [0, 0]]))
    assert status == OK and np.allclose(r[:2], [1.0, 1.0])
    status, _, r = _lcp_only(c, _problem(c, [[2.0, 1.0], [1.0, 2.0]], [-3.0, 3.0],
                                         [[0, 0], [0, 0]]))
    assert status == OK and np.allclose(r[:2], [1.5, 0.0])


def test_bilateral_normal_of_either_sign():
    """BILATERAL: u_N = 0 whatever the sign: D = 2, uf = 4 gives p_N = -2."""
    c = 1
    status, _, r = _lcp_only(c, _problem(c, [[2.0]], [4.0], [[0, 0]],
                                         law=[BILATERAL, COULOMB, COULOMB]))
    assert status == OK and np.isclose(r[0], -2.0)


def _corners_on_one_wall(eps):
    """Two corners of a slider on one wall, frictional (2D): the normal rows W_N = (1, +-eps)
    nearly dependent (the slider's tilt a lever of eps), the tangent rows both (0, 0, 1) with
    the same unit mass: rows N1, N2, T1, T2 of the local velocities."""
    W = np.array([[1.0, eps, 0.0], [1.0, -eps, 0.0], [0.3, 0.0, 1.0], [0.3, 0.0, 1.0]])
    D4 = W @ W.T
    D = np.zeros((6, 6))
    idx = [0, 1, 2, 3]
    D[np.ix_(idx, idx)] = D4
    uf = np.zeros(6)
    uf[:4] = W @ np.array([-1.0, 0.0, 2.0])
    return D, uf


def test_degenerate_two_corners_where_gauss_seidel_stalls():
    """Gauss-Seidel stalls (not converged in 1000 sweeps) on the two corners with friction;
    Lemke answers, and its answer meets the contact laws: u_N >= 0, p_N >= 0, complementary;
    |p_T| <= mu p_N, the slip opposite to p_T when |p_T| = mu p_N."""
    c, mu = 2, 0.5
    D, uf = _corners_on_one_wall(1e-4)
    coef = np.array([[0.0, mu], [0.0, mu]])
    law = np.array([UNILATERAL] * 2 + [COULOMB] * 4, np.int64)
    r = np.zeros(6)
    converged, _, _ = gauss_seidel_sliding(c, 1e-12, 1000, np.ones(2), law, coef, np.zeros(2),
                                           uf, D, r, np.zeros(4))
    assert not converged
    status, sweeps, r = _solve(c, (np.ones(2), law, coef, np.zeros(2), uf, D))
    assert status == OK and sweeps == -1
    u = uf + D @ r
    assert r[:2].min() >= -1e-12 and u[:2].min() >= -1e-9 and abs(r[:2] @ u[:2]) <= 1e-9
    for a in range(2):
        pn, pt, ut = r[a], r[2 + a], u[2 + a]
        assert abs(pt) <= mu * pn + 1e-9
        if abs(ut) > 1e-9:
            assert np.isclose(pt, -np.sign(ut) * mu * pn)


def test_painleve_has_no_solution():
    """A contact sliding with u_T > 0 (p_T = -mu p_N) whose normal acceleration falls as p_N
    grows: u_N = uf_N + (D_NN - mu D_NT) p_N = -1 + (1 - 1 * 2) p_N < 0 for every p_N >= 0."""
    c = 1
    problem = _problem(c, [[1.0, 2.0], [2.0, 5.0]], [-1.0, 0.0], [[0.0, 1.0]],
                       law=[UNILATERAL, SLIDE_POSITIVE, COULOMB])
    status, _, _ = _solve(c, problem)
    assert status == CONTACT_NO_SOLUTION
    # with mu = 0.2 it has one: p_N = 1 / (1 - 0.4)
    problem = _problem(c, [[1.0, 2.0], [2.0, 5.0]], [-1.0, 0.0], [[0.0, 0.2]],
                       law=[UNILATERAL, SLIDE_POSITIVE, COULOMB])
    status, _, r = _lcp_only(c, problem)
    assert status == OK and np.isclose(r[0], 1 / 0.6) and np.isclose(r[1], -0.2 / 0.6)


@pytest.mark.parametrize("facet", range(8))
def test_3d_faceted_cone_slides_along_a_facet_direction(facet):
    """3D, D = I: a slip along facet direction d_j of the octagon, uf_T = 3 d_j, p_N = 1 (uf_N =
    -1), mu = 1/2: p_T = -mu p_N d_j exactly (the octagon's vertex)."""
    c, mu = 1, 0.5
    d = np.array([np.cos(2 * np.pi * facet / 8), np.sin(2 * np.pi * facet / 8)])
    problem = _problem(c, np.eye(3), [-1.0, *(3 * d)], [[0.0, mu]])
    status, _, r = _lcp_only(c, problem)
    assert status == OK and np.isclose(r[0], 1.0) and np.allclose(r[1:], -mu * d)


def test_slider_crank_with_clearance_runs_to_its_end(generated):
    """models/slider_crank_clearance.py (Flores, Leine, Glocker 2010; e = 0.4, mu = 0.01) from
    q = 0, crank at 150 rad/s, rod at -75 rad/s: dop853_impacts stopped at t = 0.0341 (two
    lower corners on the wall near the crank's dead centre, Gauss-Seidel stalling on the
    persistent contacts' forces) before the exact fallback; now it reaches t = 0.2 with its gaps
    above -1e-6 (measured -6.2e-7: the drift of contacts held at the acceleration level, 6e-4
    of the clearance) and q1 = 18.08 rad at the end."""
    from lagrange_gen.run.simulate import simulate
    module = generated("slider_crank_clearance")
    traj = simulate(module, method="dop853_impacts", q0=[0.0, 0.0, 0.0], v0=[150.0, -75.0, 0.0],
                    t_end=0.2)
    assert traj.t[-1] == 0.2
    p = np.array([traj.params[name] for name in module.PARAMS], dtype=float)
    gaps = np.empty((len(traj.t), 4))
    for i, q in enumerate(traj.q):
        g, WN, WT, coef = np.empty(4), np.empty((4, 3)), np.empty((8, 3)), np.empty((4, 2))
        module.contacts(np.ascontiguousarray(q), traj.t[i], p, g, WN, WT, coef)
        gaps[i] = g
    assert gaps.min() >= -1e-6
    assert abs(traj.q[-1, 0] - 18.08) <= 0.05
    assert traj.saved["impacts"][-1, 0] > 0
    # moreau_jean (the same solver behind its impulses) runs it to the end too
    mj = simulate(module, method="moreau_jean", q0=[0.0, 0.0, 0.0], v0=[150.0, -75.0, 0.0],
                  t_end=0.2, h=1e-4, save_every=100)
    assert mj.t[-1] == pytest.approx(0.2) and np.isfinite(mj.q).all()


def test_painleve_rod_is_reported_in_one_line(generated):
    """models/painleve_rod.py at th = 30 degrees, the end on the floor sliding towards -x at
    1 m/s, mu = 3 > (1 + 3 cos^2 th) / (3 sin th cos th) = 2.5: the sliding contact's force
    problem has no solution; dop853_impacts stops at the start saying so. With mu = 0.3 it has
    one and the rod slides on (to t = 0.05)."""
    import math

    from lagrange_gen import SimulationError
    from lagrange_gen.run.simulate import simulate
    th, l = math.pi / 6, 0.5
    start = dict(q0=[0.0, l * math.sin(th), th], v0=[-1.0, 0.0, 0.0], t_end=0.05)
    with pytest.raises(SimulationError, match=r"t = 0\b.*contact problem has no solution.*"
                                              r"Painleve") as info:
        simulate(generated("painleve_rod"), method="dop853_impacts", **start)
    assert "\n" not in str(info.value)
    traj = simulate(generated("painleve_rod"), method="dop853_impacts", params={"mu": 0.3},
                    **start)
    assert traj.t[-1] == 0.05
