"""Dormand-Prince 8(5,3): adaptive explicit Runge-Kutta of order 8 with 7th-order dense output.

The method of Hairer, Norsett & Wanner, Solving ODEs I (2nd ed.), sec. II.5 and II.10, code
dop853.f: 12 stages (the 13th, the derivative at the step end, is reused as the first stage of
the next step: FSAL) give the 8th-order solution; two embedded estimates, of order 5 (E5) and 3
(E3), combine into the error norm

    err = |h| |e5|^2 / sqrt(N (|e5|^2 + 0.01 |e3|^2)),   e_i = sum_j E_j K_j,i / sk_i,
    sk_i = atol + rtol max(|y_i|, |y_new,i|)   over the N = 2n components of y = (q, v),

and a step is accepted when err <= 1 (adaptive.py holds the step-size control). Three more
stages give the continuous extension of order 7 (``dense``, ``interpolate``).

The system is the second-order q' = v, v' = a(q, v, t) (a = H^-1 rhs, the generated
forward_dynamics) as a first-order ODE in y = (q, v): stage K_j = (V_j, a_j), stepped by
explicit_rk's tableau-driven core. The coefficients are the published ones (Hairer's dop853.f,
also in scipy.integrate's dop853_coefficients.py), indexed as there: K[0..11] the stages,
K[12] = f(t + h, y_new), K[13..15] the dense-output stages.

The work W (steppers/core/work.py: E - E0 - W = 0 along a motion) on a model with kern.WORK:
the ODE is augmented with W' = P(q, v, t), the generated ``power`` kernel at every stage (the
stage states recomputed from the stages, P_j into pk), so W is stepped by the same tableau
(order 8), its error estimate joins the error norm (N = 2n + 1 components, W the last) and its
dense output is the same interpolant (P at the three dense stages). W does not feed back into
q, v. On a model without WORK none of it runs (no power call, N = 2n).

The adaptive loop (adaptive.run_adaptive) calls the functions below; their contract is in its
module docstring. Not symplectic, not symmetric: energy drifts with the error tolerance.

Over 300 lines: about 80 of them are the published coefficients.
"""

import math
import sys
from collections import namedtuple
from typing import NamedTuple

import numpy as np
from ...jit.cache import njit

from ..core.legendre import accel
from ..core.options import FAST
from ..core.explicit_rk import stage_state, rk_step
from ..core.method_spec import Spec
from ..core.status import OK

N_STAGES = 12           # stages of the 8th-order step (without the FSAL stage)
N_DENSE = 16            # stages including the FSAL one and the three dense-output ones
STAGE_EVALS = 11        # acceleration evaluations per attempted step (stage 0 is carried over)
ACCEPT_EVALS = 1        # the FSAL evaluation at the end of an accepted step
DENSE_EVALS = 3         # the extra stages of the dense output
ERROR_EXPONENT = 1.0 / 8.0      # err ~ h^8: the controller's exponent (adaptive.py)

C = np.array([0.0, 0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01,
              0.118350341907227396726757197510, 0.281649658092772603273242802490,
              1.0 / 3.0, 0.25, 0.307692307692307692307692307692,
              0.651282051282051282051282051282, 0.6, 0.857142857142857142857142857142,
              1.0, 1.0, 0.1, 0.2, 0.777777777777777777777777777778])


def _tableau():
    """A (16, 16): rows 1-11 the stages, row 12 the weights b, rows 13-15 the dense stages."""
    rows = {
        1: {0: 5.26001519587677318785587544488e-2},
        2: {0: 1.97250569845378994544595329183e-2, 1: 5.91751709536136983633785987549e-2},
        3: {0: 2.95875854768068491816892993775e-2, 2: 8.87627564304205475450678981324e-2},
        4: {0: 2.41365134159266685502369798665e-1, 2: -8.84549479328286085344864962717e-1,
            3: 9.24834003261792003115737966543e-1},
        5: {0: 3.7037037037037037037037037037e-2, 3: 1.70828608729473871279604482173e-1,
            4: 1.25467687566822425016691814123e-1},
        6: {0: 3.7109375e-2, 3: 1.70252211019544039314978060272e-1,
            4: 6.02165389804559606850219397283e-2, 5: -1.7578125e-2},
        7: {0: 3.70920001185047927108779319836e-2, 3: 1.70383925712239993810214054705e-1,
            4: 1.07262030446373284651809199168e-1, 5: -1.53194377486244017527936158236e-2,
            6: 8.27378916381402288758473766002e-3},
        8: {0: 6.24110958716075717114429577812e-1, 3: -3.36089262944694129406857109825,
            4: -8.68219346841726006818189891453e-1, 5: 2.75920996994467083049415600797e1,
            6: 2.01540675504778934086186788979e1, 7: -4.34898841810699588477366255144e1},
        9: {0: 4.77662536438264365890433908527e-1, 3: -2.48811461997166764192642586468,
            4: -5.90290826836842996371446475743e-1, 5: 2.12300514481811942347288949897e1,
            6: 1.52792336328824235832596922938e1, 7: -3.32882109689848629194453265587e1,
            8: -2.03312017085086261358222928593e-2},
        10: {0: -9.3714243008598732571704021658e-1, 3: 5.18637242884406370830023853209,
             4: 1.09143734899672957818500254654, 5: -8.14978701074692612513997267357,
             6: -1.85200656599969598641566180701e1, 7: 2.27394870993505042818970056734e1,
             8: 2.49360555267965238987089396762, 9: -3.0467644718982195003823669022},
        11: {0: 2.27331014751653820792359768449, 3: -1.05344954667372501984066689879e1,
             4: -2.00087205822486249909675718444, 5: -1.79589318631187989172765950534e1,
             6: 2.79488845294199600508499808837e1, 7: -2.85899827713502369474065508674,
             8: -8.87285693353062954433549289258, 9: 1.23605671757943030647266201528e1,
             10: 6.43392746015763530355970484046e-1},
        12: {0: 5.42937341165687622380535766363e-2, 5: 4.45031289275240888144113950566,
             6: 1.89151789931450038304281599044, 7: -5.8012039600105847814672114227,
             8: 3.1116436695781989440891606237e-1, 9: -1.52160949662516078556178806805e-1,
             10: 2.01365400804030348374776537501e-1, 11: 4.47106157277725905176885569043e-2},
        13: {0: 5.61675022830479523392909219681e-2, 6: 2.53500210216624811088794765333e-1,
             7: -2.46239037470802489917441475441e-1, 8: -1.24191423263816360469010140626e-1,
             9: 1.5329179827876569731206322685e-1, 10: 8.20105229563468988491666602057e-3,
             11: 7.56789766054569976138603589584e-3, 12: -8.298e-3},
        14: {0: 3.18346481635021405060768473261e-2, 5: 2.83009096723667755288322961402e-2,
             6: 5.35419883074385676223797384372e-2, 7: -5.49237485713909884646569340306e-2,
             10: -1.08347328697249322858509316994e-4, 11: 3.82571090835658412954920192323e-4,
             12: -3.40465008687404560802977114492e-4, 13: 1.41312443674632500278074618366e-1},
        15: {0: -4.28896301583791923408573538692e-1, 5: -4.69762141536116384314449447206,
             6: 7.68342119606259904184240953878, 7: 4.06898981839711007970213554331,
             8: 3.56727187455281109270669543021e-1, 12: -1.39902416515901462129418009734e-3,
             13: 2.9475147891527723389556272149, 14: -9.15095847217987001081870187138},
    }
    a = np.zeros((N_DENSE, N_DENSE))
    for i, row in rows.items():
        for j, value in row.items():
            a[i, j] = value
    return a


A = _tableau()
B = A[N_STAGES, :N_STAGES].copy()

#: Error estimators over the stages K[0..11]: E5 of order 5, E3 = b - bhh of order 3.
E5 = np.zeros(N_STAGES)
E5[[0, 5, 6, 7, 8, 9, 10, 11]] = [
    0.1312004499419488073250102996e-1, -0.1225156446376204440720569753e+1,
    -0.4957589496572501915214079952, 0.1664377182454986536961530415e+1,
    -0.3503288487499736816886487290, 0.3341791187130174790297318841,
    0.8192320648511571246570742613e-1, -0.2235530786388629525884427845e-1]
E3 = B.copy()
E3[0] -= 0.244094488188976377952755905512
E3[8] -= 0.733846688281611857341361741547
E3[11] -= 0.220588235294117647058823529412e-1

#: Dense output: rows 3-6 of the interpolant are h D K over the 16 stages (rows 0-2 come from
#: y_old, y_new and the end-point derivatives).
D = np.zeros((4, N_DENSE))
D[0, [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]] = [
    -0.84289382761090128651353491142e+1, 0.56671495351937776962531783590,
    -0.30689499459498916912797304727e+1, 0.23846676565120698287728149680e+1,
    0.21170345824450282767155149946e+1, -0.87139158377797299206789907490,
    0.22404374302607882758541771650e+1, 0.63157877876946881815570249290,
    -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e+2,
    -0.91946323924783554000451984436e+1, -0.44360363875948939664310572000e+1]
D[1, [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]] = [
    0.10427508642579134603413151009e+2, 0.24228349177525818288430175319e+3,
    0.16520045171727028198505394887e+3, -0.37454675472269020279518312152e+3,
    -0.22113666853125306036270938578e+2, 0.77334326684722638389603898808e+1,
    -0.30674084731089398182061213626e+2, -0.93321305264302278729567221706e+1,
    0.15697238121770843886131091075e+2, -0.31139403219565177677282850411e+2,
    -0.93529243588444783865713862664e+1, 0.35816841486394083752465898540e+2]
D[2, [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]] = [
    0.19985053242002433820987653617e+2, -0.38703730874935176555105901742e+3,
    -0.18917813819516756882830838328e+3, 0.52780815920542364900561016686e+3,
    -0.11573902539959630126141871134e+2, 0.68812326946963000169666922661e+1,
    -0.10006050966910838403183860980e+1, 0.77771377980534432092869265740,
    -0.27782057523535084065932004339e+1, -0.60196695231264120758267380846e+2,
    0.84320405506677161018159903784e+2, 0.11992291136182789328035130030e+2]
D[3, [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]] = [
    -0.25693933462703749003312586129e+2, -0.15418974869023643374053993627e+3,
    -0.23152937917604549567536039109e+3, 0.35763911791061412378285349910e+3,
    0.93405324183624310003907691704e+2, -0.37458323136451633156875139351e+2,
    0.10409964950896230045147246184e+3, 0.29840293426660503123344363579e+2,
    -0.43533456590011143754432175058e+2, 0.96324553959188282948394950600e+2,
    -0.39177261675615439165231486172e+2, -0.14972683625798562581422125276e+3]


class Settings(NamedTuple):
    """Settings of dop853 (simulate's keywords)."""

    rtol: float = 1e-9              # relative tolerance of the local error estimate
    atol: float = 1e-12             # absolute tolerance (same units as q and v)
    h_max: float = math.inf         # largest step size
    max_steps: int = 100000         # cap on attempted (accepted + rejected) steps per call
    blowup_bound: float = 1e150     # UNSTABLE when max(|q|, |v|) exceeds it


#: Scratch of one run: stage velocities kv and accelerations ka (16, n) (row 0 carries
#: a(q, v, t) from the end of the previous step), stage position qs, the trial state q_new,
#: v_new, an interpolated state q_int, v_int, H; the dense output of the last accepted step:
#: coefficients dense_q, dense_v (7, n), its start q_old, v_old and span = [t_old, h].
#: The work W as a one-component half of the state (module docstring): the stage powers pk
#: (16, 1) (row 0 carries P(q, v, t) like ka), W at the current state w, at the trial state
#: w_new, at the dense output's start w_old (1,), its coefficients dense_w (7, 1); pw
#: (2n + 2,) the power kernel's output.
Workspace = namedtuple("Workspace", "kv ka qs q_new v_new q_int v_int H dense_q dense_v "
                                    "q_old v_old span pk w w_new w_old dense_w pw")


@njit
def workspace(kern, n):
    """Allocated once per run by adaptive.run_adaptive."""
    return Workspace(np.zeros((N_DENSE, n)), np.zeros((N_DENSE, n)), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((n, n)),
                     np.zeros((7, n)), np.zeros((7, n)), np.zeros(n), np.zeros(n), np.zeros(2),
                     *work_fields(n))


@njit
def work_fields(n):
    """The work's fields of the workspace, in its order: pk (16, 1), w, w_new, w_old (1,),
    dense_w (7, 1), pw (2n + 2,) (what dop853_impacts' workspace holds too)."""
    return (np.zeros((N_DENSE, 1)), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros((7, 1)),
            np.zeros(2 * n + 2))


@njit(**FAST)
def stage_acceleration(kern, ctx, q, v, t, a):
    """explicit_rk's callback: a (n,) from the generated forward dynamics; ctx = (p, H)."""
    p, H = ctx
    return accel(kern, q, v, t, p, H, a)


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws):
    """The first stage of the first step, ka[0] = a(q, v, t) (and pk[0]: start_work); OK or
    SINGULAR_MASS."""
    start_work(kern, q, v, t, p, ws)
    return accel(kern, q, v, t, p, ws.H, ws.ka[0])


@njit(inline="always")
def _power(kern, ws, q, v, t, p):
    """P(q, v, t) (generated power kernel; its derivatives, also written, are not used)."""
    kern.power(q, v, t, p, ws.pw)
    return ws.pw[0]


@njit(**FAST)
def start_work(kern, q, v, t, p, ws):
    """The work's first stage pk[0] = P(q, v, t) at the state a step starts from (a model
    with kern.WORK; nothing otherwise)."""
    if kern.WORK:
        ws.pk[0, 0] = _power(kern, ws, q, v, t, p)


@njit(**FAST)
def _scaled_sums(q, v, dq, dv, atol, rtol):
    """(sum (y_i / sk_i)^2, sum (dy_i / sk_i)^2) over y = (q, v), sk_i = atol + rtol |y_i|."""
    sy = 0.0
    sd = 0.0
    for i in range(q.shape[0]):
        sk = atol + rtol * abs(q[i])
        sy += (q[i] / sk) ** 2
        sd += (dq[i] / sk) ** 2
        sk = atol + rtol * abs(v[i])
        sy += (v[i] / sk) ** 2
        sd += (dv[i] / sk) ** 2
    return sy, sd


@njit(**FAST)
def initial_step(kern, q, v, t, direction, p, settings, ws):
    """Hairer's starting step (dop853.f, HINIT): h such that h^8 max(|f|, |f'|) = 0.01 in the
    tolerance-scaled norm, f' estimated by one explicit Euler step. Needs prepare first; uses
    kv[1], ka[1], qs as scratch. Returns (status, |h|); one acceleration evaluation."""
    n = q.shape[0]
    f0q, f0v = v, ws.ka[0]
    dny, dnf = _scaled_sums(q, v, f0q, f0v, settings.atol, settings.rtol)
    h = 1e-6 if dnf <= 1e-10 or dny <= 1e-10 else math.sqrt(dny / dnf) * 0.01
    h = min(h, settings.h_max) * direction
    q1, v1, a1 = ws.qs, ws.kv[1], ws.ka[1]
    for i in range(n):
        q1[i] = q[i] + h * f0q[i]
        v1[i] = v[i] + h * f0v[i]
    status = accel(kern, q1, v1, t + h, p, ws.H, a1)
    if status != OK:
        return status, 0.0
    der2 = 0.0
    for i in range(n):       # f1 - f0 = (v1 - v, a1 - a0)
        sk = settings.atol + settings.rtol * abs(q[i])
        der2 += ((v1[i] - f0q[i]) / sk) ** 2
        sk = settings.atol + settings.rtol * abs(v[i])
        der2 += ((a1[i] - f0v[i]) / sk) ** 2
    der12 = max(math.sqrt(der2) / abs(h), math.sqrt(dnf))
    if der12 <= 1e-15:
        h1 = max(1e-6, abs(h) * 1e-3)
    else:
        h1 = (0.01 / der12) ** ERROR_EXPONENT
    return OK, min(100.0 * abs(h), h1, settings.h_max)


@njit(**FAST)
def _error_sums(K, i, y_old, y_new, atol, rtol):
    """(e5^2, e3^2) of component i of one half of y (K (16, n) its stage derivatives)."""
    e5 = 0.0
    e3 = 0.0
    for j in range(N_STAGES):
        e5 += E5[j] * K[j, i]
        e3 += E3[j] * K[j, i]
    sk = atol + rtol * max(abs(y_old[i]), abs(y_new[i]))
    return (e5 / sk) ** 2, (e3 / sk) ** 2


@njit(**FAST)
def attempt(kern, q, v, t, h, p, settings, ws):
    """One trial step of size h from (q, v) at t (ka[0] = a(q, v, t)) into ws.q_new, ws.v_new
    (and W into ws.w_new on a model with WORK). Returns (status, err): err the scaled error
    norm (accept when err <= 1; NaN when the trial went non-finite); status OK or the stage
    acceleration's failure. STAGE_EVALS evaluations (and as many power kernel calls)."""
    return attempt_on(_THIS, kern, (p, ws.H), p, q, v, t, h, settings, ws)


@njit(**FAST)
def attempt_on(source, kern, ctx, p, q, v, t, h, settings, ws):
    """attempt with the accelerations of ``source.stage_acceleration(kern, ctx, ...)``
    (explicit_rk's contract): what a method stepping another right-hand side with this
    tableau (dop853_impacts) calls. p: the parameters (the power kernel's)."""
    status = rk_step(source, kern, ctx, A, B, C, q, v, t, h, ws.kv, ws.ka, ws.qs,
                     ws.q_new, ws.v_new, True)
    if status != OK:
        return status, 0.0
    n = q.shape[0]
    s5 = 0.0
    s3 = 0.0
    for i in range(n):
        a5, a3 = _error_sums(ws.kv, i, q, ws.q_new, settings.atol, settings.rtol)
        b5, b3 = _error_sums(ws.ka, i, v, ws.v_new, settings.atol, settings.rtol)
        s5 += a5 + b5
        s3 += a3 + b3
    components = 2 * n
    if kern.WORK:
        _work_stages(kern, q, v, t, h, p, ws)
        w5, w3 = _error_sums(ws.pk, 0, ws.w, ws.w_new, settings.atol, settings.rtol)
        s5 += w5
        s3 += w3
        components += 1
    deno = s5 + 0.01 * s3
    if deno <= 0.0:
        deno = 1.0
    return OK, abs(h) * s5 / math.sqrt(components * deno)


@njit(**FAST)
def _work_stages(kern, q, v, t, h, p, ws):
    """The stage powers pk[1..11] at the stage states of the trial step (recomputed from its
    stages kv, ka as rk_step made them) and W at its end, ws.w_new = w + h sum_j b_j P_j."""
    n = kern.N_COORDS
    for i in range(1, N_STAGES):
        stage_state(A, i, q, v, h, ws.kv, ws.ka, ws.qs, n)
        ws.pk[i, 0] = _power(kern, ws, ws.qs, ws.kv[i], t + C[i] * h, p)
    ws.w_new[0] = ws.w[0] + stage_integral(ws.pk, h)


@njit(**FAST)
def stage_integral(K, h):
    """h sum_j b_j K[j, 0]: the integral over a step of size h of a scalar rate whose stage
    values are K (16, 1) (K[0..11]), as the tableau steps it (order 8)."""
    s = 0.0
    for j in range(N_STAGES):
        s += B[j] * K[j, 0]
    return h * s


@njit(**FAST)
def dense_integral(K, h, x, F, ends):
    """The integral of that rate from the step's start to x h, 0 <= x <= 1, from the dense
    output (K[12..15] too: the FSAL and dense stages); F (7, 1), ends (2,) scratch."""
    ends[0] = 0.0
    ends[1] = stage_integral(K, h)
    _coefficients(K, ends[0:1], ends[1:2], h, F)
    return _interpolant(F, ends[0:1], 0, x)


@njit(**FAST)
def accept(kern, t_new, p, ws):
    """After an accepted trial: the FSAL stage K[12] = f(t_new, y_new) (kv[12], ka[12]; pk[12]
    with WORK). ACCEPT_EVALS evaluations; OK or SINGULAR_MASS."""
    return accept_on(_THIS, kern, (p, ws.H), p, t_new, ws)


@njit(**FAST)
def accept_on(source, kern, ctx, p, t_new, ws):
    """accept with the accelerations of ``source`` (see attempt_on)."""
    for i in range(ws.v_new.shape[0]):
        ws.kv[N_STAGES, i] = ws.v_new[i]
    if kern.WORK:
        ws.pk[N_STAGES, 0] = _power(kern, ws, ws.q_new, ws.v_new, t_new, p)
    return source.stage_acceleration(kern, ctx, ws.q_new, ws.v_new, t_new, ws.ka[N_STAGES])


@njit(**FAST)
def _coefficients(K, y_old, y_new, h, F):
    """The 7 interpolant rows F (7, n) of one half of y from its stage derivatives K (16, n)."""
    for i in range(y_old.shape[0]):
        dy = y_new[i] - y_old[i]
        F[0, i] = dy
        F[1, i] = h * K[0, i] - dy
        F[2, i] = 2.0 * dy - h * (K[N_STAGES, i] + K[0, i])
        for r in range(4):
            s = 0.0
            for j in range(N_DENSE):
                if D[r, j] != 0.0:
                    s += D[r, j] * K[j, i]
            F[3 + r, i] = h * s


@njit(**FAST)
def dense(kern, q, v, t, h, p, ws):
    """Build the 7th-order interpolant of the accepted step (q, v) at t -> (q_new, v_new) at
    t + h: the stages K[13..15], then the coefficients, the start state and span into ws (and
    W's with WORK). Call after accept, before advance. DENSE_EVALS evaluations; OK or
    SINGULAR_MASS."""
    return dense_on(_THIS, kern, (p, ws.H), p, q, v, t, h, ws)


@njit(**FAST)
def dense_on(source, kern, ctx, p, q, v, t, h, ws):
    """dense with the accelerations of ``source`` (see attempt_on)."""
    for i in range(N_STAGES + 1, N_DENSE):
        stage_state(A, i, q, v, h, ws.kv, ws.ka, ws.qs, kern.N_COORDS)
        status = source.stage_acceleration(kern, ctx, ws.qs, ws.kv[i], t + C[i] * h, ws.ka[i])
        if status != OK:
            return status
        if kern.WORK:
            ws.pk[i, 0] = _power(kern, ws, ws.qs, ws.kv[i], t + C[i] * h, p)
    _coefficients(ws.kv, q, ws.q_new, h, ws.dense_q)
    _coefficients(ws.ka, v, ws.v_new, h, ws.dense_v)
    if kern.WORK:
        _coefficients(ws.pk, ws.w, ws.w_new, h, ws.dense_w)
        ws.w_old[0] = ws.w[0]
    for i in range(q.shape[0]):
        ws.q_old[i] = q[i]
        ws.v_old[i] = v[i]
    ws.span[0] = t
    ws.span[1] = h
    return OK


@njit(**FAST)
def interpolate(ws, t, q_out, v_out):
    """The dense output of the last step ``dense`` was built for, at t in [t_old, t_old + h]:
    q_out, v_out (n,). Accurate to order 7 in h (the step values themselves are order 8)."""
    x = (t - ws.span[0]) / ws.span[1]
    for i in range(ws.q_old.shape[0]):
        q_out[i] = _interpolant(ws.dense_q, ws.q_old, i, x)
        v_out[i] = _interpolant(ws.dense_v, ws.v_old, i, x)


@njit(inline="always")
def _interpolant(F, y0, i, x):
    """Component i of the dense output y0 + x (F0 + (1 - x) (F1 + x (F2 + ...))) at the step
    fraction x (F (7, N) the coefficients, y0 (N,) the step's start)."""
    y = 1.0 - x
    r = F[6, i] * x
    r = (r + F[5, i]) * y
    r = (r + F[4, i]) * x
    r = (r + F[3, i]) * y
    r = (r + F[2, i]) * x
    r = (r + F[1, i]) * y
    r = (r + F[0, i]) * x
    return y0[i] + r


@njit(**FAST)
def interpolate_work(ws, t):
    """W at t from the dense output ``dense`` built (a model with WORK; order 7 like q, v)."""
    return _interpolant(ws.dense_w, ws.w_old, 0, (t - ws.span[0]) / ws.span[1])


@njit(**FAST)
def advance(q, v, ws):
    """Make the accepted trial the current state: q, v <- q_new, v_new; ka[0] <- ka[12]; the
    same for the work: w <- w_new, pk[0] <- pk[12]."""
    for i in range(q.shape[0]):
        q[i] = ws.q_new[i]
        v[i] = ws.v_new[i]
        ws.ka[0, i] = ws.ka[N_STAGES, i]
    ws.w[0] = ws.w_new[0]
    ws.pk[0, 0] = ws.pk[N_STAGES, 0]


#: Rows one accepted step may output in every-step mode (adaptive.run_adaptive's room check).
ROWS_PER_STEP = 1


@njit(inline="always")
def switch_point(kern, ws, q, v, t, h, t_new, p, extra, counters):
    """adaptive.run_adaptive's hook for a right-hand side that switches at located states
    (dop853_impacts): this one never switches. Returns (status, switched, t_new)."""
    return OK, False, t_new


@njit(inline="always")
def apply_switch(kern, ws, q, v, t, p, settings, extra):
    """adaptive.run_adaptive's hook (see switch_point): nothing to apply. Returns status."""
    return OK


# This module as a value for rk_step (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="dop853", order=8, family="explicit", implicit=False, symplectic=False,
    symmetric=False, adaptive=True,
    summary="Dormand-Prince 8(5,3), adaptive, 7th-order dense output",
    stable="stable for tau <= 5.96 (the step control keeps h omega well inside for accuracy)",
    settings=Settings,
    limits={"rtol": (100 * 2.220446049250313e-16, True, False), "atol": (0.0, False, False),
            "h_max": (0.0, False, True), "max_steps": (1, True, False)},
    kernels=("forward_dynamics", "power"))
