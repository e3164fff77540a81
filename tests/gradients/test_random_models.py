"""Forward sensitivities of random models drawn as the differential harness draws them
(tests/harness/strategies.py: T, V, forces and dissipation over the grammar users write,
explicit time included) against central differences of simulate, for every method that has them
and applies (T1 terms refuse the momentum-form methods; a draw whose run fails, e.g. a singular
mass matrix on the way, is skipped for that method)."""

import numpy as np
from hypothesis import HealthCheck, given, settings, strategies as st

import lagrange_gen as lg
from lagrange_gen.codegen.generate import generate_text
from lagrange_gen.errors import SimulationError
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.sensitivity import SENSITIVITY_METHODS
from harness.strategies import models, sample_state

EPS, RTOL = 1e-6, 1e-6
#: Sensitivities below this are compared absolutely (to RTOL * FLOOR): a parameter that scales T
#: and V alike leaves the motion alone, and its difference quotient is rounding noise (~1e-10).
FLOOR = 1e-3
RUN = dict(t_end=0.05, h=0.005)


def _states(traj):
    return np.hstack((traj.q, traj.v))


def _central(module, method, q0, v0, name, value):
    step = EPS * max(1.0, abs(value))
    plus = lg.simulate(module, method, q0, v0, params={name: value + step}, **RUN)
    minus = lg.simulate(module, method, q0, v0, params={name: value - step}, **RUN)
    return (_states(plus) - _states(minus)) / (2 * step)


@settings(max_examples=3, deadline=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_sensitivities_of_random_models(data, tmp_path_factory):
    drawn = data.draw(models(), label="model")
    drawn.events = []                            # a run with sensitivities locates no events
    out = tmp_path_factory.mktemp("random_sensitivities")
    model = drawn.build()
    model.source_path = str(out / f"{drawn.name}_model.py")    # never written
    text, _, target = generate_text(model, out, methods=list(SENSITIVITY_METHODS),
                                    sensitivities=True)
    target.write_text(text)
    module = import_generated(target)
    q0, v0, _ = sample_state(drawn, np.random.default_rng(data.draw(st.integers(0, 2**16))))
    names = list(module.PARAMS)[:2]
    ran = 0
    for method in SENSITIVITY_METHODS:
        try:
            traj = lg.simulate(module, method, q0, v0, sensitivities=names + ["q0"], **RUN)
        except SimulationError:
            continue
        ran += 1
        for name in names:
            value = float(module.DEFAULT_PARAMS[list(module.PARAMS).index(name)])
            fd = _central(module, method, q0, v0, name, value)
            err = np.abs(traj.sensitivity(name) - fd).max() / max(np.abs(fd).max(), FLOOR)
            assert err < RTOL, (drawn.name, method, name, err)
        direction = np.random.default_rng(0).normal(size=len(q0))
        plus = lg.simulate(module, method, q0 + EPS * direction, v0, **RUN)
        minus = lg.simulate(module, method, q0 - EPS * direction, v0, **RUN)
        fd = (_states(plus) - _states(minus)) / (2 * EPS)
        err = np.abs(traj.sensitivity("q0") @ direction - fd).max() / max(np.abs(fd).max(), FLOOR)
        assert err < RTOL, (drawn.name, method, "q0", err)
    assert ran >= 3                              # explicit_euler, rk4, implicit_euler at least
