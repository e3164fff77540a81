"""A controller's hooks cached across processes (run/controller_hooks.py) under the content
key of jit/function_key.py: a new process running a controller it ran before compiles
nothing, and a controller whose compiled code would differ (a global read at run time, a
callee edited, a closure's value) never gets the old code."""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.jit.function_key import content_key

Q0, H, T_END = [0.0, 0.2], 0.01, 0.3


def _jitted(source, **namespace):
    """f of ``source``, jitted, with the globals ``namespace`` (and np)."""
    scope = {"np": np, **namespace}
    exec(textwrap.dedent(source), scope)  # noqa: S102  the test's own text
    return numba.njit(scope["f"])


_READS_GAIN = """
def f(t, q, qd, p):
    return GAIN * q[1] + np.sin(t)
"""


def test_the_key_follows_the_globals_a_controller_reads():
    assert content_key(_jitted(_READS_GAIN, GAIN=2.0)) == content_key(_jitted(_READS_GAIN, GAIN=2.0))
    assert content_key(_jitted(_READS_GAIN, GAIN=2.0)) != content_key(_jitted(_READS_GAIN, GAIN=3.0))
    assert content_key(_jitted(_READS_GAIN, GAIN=2.0)) != content_key(_jitted(_READS_GAIN, GAIN=2))
    array = "def f(t, q, qd, p):\n    return K[0] * q[0] + K[1] * qd[0]\n"
    assert content_key(_jitted(array, K=np.array([1.0, 2.0]))) != \
        content_key(_jitted(array, K=np.array([1.0, 2.5])))


def test_the_key_follows_the_code_a_controller_calls():
    calls = "def f(t, q, qd, p):\n    return helper(q[0])\n"
    one = _jitted(calls, helper=_jitted("def f(x):\n    return 2.0 * x\n"))
    same = _jitted(calls, helper=_jitted("def f(x):\n    return 2.0 * x\n"))
    other = _jitted(calls, helper=_jitted("def f(x):\n    return 3.0 * x\n"))
    assert content_key(one) == content_key(same) != content_key(other)


def test_the_key_follows_closures_defaults_and_options():
    def closed(gain):
        @numba.njit
        def f(t, q, qd, p):
            return gain * q[0]
        return f

    assert content_key(closed(1.0)) == content_key(closed(1.0)) != content_key(closed(4.0))
    body = "def f(t, q, qd, p, c=DEFAULT):\n    return c * q[0]\n"
    assert content_key(_jitted(body, DEFAULT=1.0)) != content_key(_jitted(body, DEFAULT=2.0))
    scope = {}
    exec("def f(t, q, qd, p):\n    return q[0]\n", scope)  # noqa: S102
    assert content_key(numba.njit(scope["f"])) != content_key(numba.njit(fastmath=True)(scope["f"]))


def test_what_the_key_cannot_vouch_for_is_not_keyed():
    reads = "def f(t, q, qd, p):\n    return GAINS[0] * q[0]\n"
    assert content_key(_jitted(reads, GAINS=[1.0, 2.0])) is None          # a list: mutable
    assert content_key(_jitted(reads, GAINS={0: 1.0})) is None            # a dict
    module = "def f(t, q, qd, p):\n    return mine.gain * q[0]\n"
    assert content_key(_jitted(module, mine=textwrap)) is None            # not a stable package
    assert content_key(_jitted("def f(t, q, qd, p):\n    return np.pi * q[0]\n")) is not None


@pytest.fixture(scope="module")
def cart_pole(generated):
    return generated("cart_pole")


_SCRIPT = '''
import json, sys
import numba
import numpy as np
import lagrange_gen as lg
from lagrange_gen.jit.compile_notice import time_outermost_compiles
from lagrange_gen.run.loader import import_generated

GAIN = float(sys.argv[2])        # read at run time: numba's own cache would freeze it

@numba.njit
def helper(x):
    return 3.0 * x

@numba.njit
def balance(t, q, qd, p):
    return GAIN * q[1] + helper(qd[1])

mod = import_generated(sys.argv[1])
compiles = time_outermost_compiles(lambda name: name)
traj = lg.simulate(mod, "midpoint", q0=[0.0, 0.2], t_end=0.3, h=0.01, control=balance,
                   jit="portable")
print(json.dumps(dict(jit=traj.jit, compiled=sorted(compiles), q=traj.q.tolist())))
'''


def _child(script, module, gain):
    env = dict(os.environ)
    src = str(Path(lg.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([src] + [p for p in env.get("PYTHONPATH", "").split(
        os.pathsep) if p])
    env["LAGRANGE_GEN_BACKGROUND_COMPILE"] = "0"
    done = subprocess.run([sys.executable, str(script), module.__file__, repr(gain)], env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_controller_run_before_compiles_nothing_in_a_new_process(cart_pole, tmp_path):
    """Three processes run the same file: the second compiles nothing (its hooks load from the
    cache), the third reads another gain and gets its own answer, not the cached one: the
    answers are the specialized loop's of this process, bit for bit."""
    gain = 17.0 + os.getpid() % 1000 / 1000      # a key no earlier test session left behind
    script = tmp_path / "balance.py"
    script.write_text(_SCRIPT)
    first = _child(script, cart_pole, gain)
    again = _child(script, cart_pole, gain)
    other = _child(script, cart_pole, gain / 2)
    assert first["jit"] == again["jit"] == other["jit"] == "portable"
    assert first["compiled"], "the first process compiles the controller's hooks"
    assert again["compiled"] == [], again["compiled"]
    helper = numba.njit(lambda x: 3.0 * x)
    for result, g in ((again, gain), (other, gain / 2)):
        @numba.njit
        def balance(t, q, qd, p):
            return g * q[1] + helper(qd[1])
        expected = lg.simulate(cart_pole, "midpoint", q0=Q0, t_end=T_END, h=H, control=balance,
                               jit="specialized")
        np.testing.assert_array_equal(np.array(result["q"]), expected.q)
    assert not np.array_equal(np.array(other["q"]), np.array(again["q"]))
