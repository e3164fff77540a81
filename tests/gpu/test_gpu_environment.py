"""What the GPU path says when it cannot run (numba-cuda missing, no driver or GPU: one line,
never a traceback, from the API and from `lagrange-gen sweep --device cuda`), and that the
CUDA target compiles its members: lowering.py types and lowers the member of a method for the
CUDA target without a GPU, which the simulator tests cannot show (the simulator runs the member
compiled for the CPU). Each check runs in a fresh process: numba chooses the simulator or the
CUDA target once, at import."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("numba_cuda", reason="numba-cuda is not installed (the gpu or test extra)")

ROOT = Path(__file__).resolve().parents[2]
CART = str(ROOT / "generated" / "cart_pendulum.py")

ENSEMBLE = ("import lagrange_gen as lg\n"
            "from lagrange_gen.errors import SimulationError\n"
            "try:\n"
            f"    lg.ensemble({CART!r}, 'rk4', q0=[0.1, 0.2], t_end=0.002, h=1e-3, device='cuda')\n"
            "except SimulationError as exc:\n"
            "    print('REFUSED', exc)\n"
            "else:\n"
            "    print('RAN')\n")


def _python(code, simulator="0", timeout=600):
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": simulator}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, env=env, timeout=timeout)


def _gpu_here():
    out = _python("from numba import cuda; print(cuda.is_available())")
    return out.stdout.strip() == "True"


def test_without_numba_cuda_one_line():
    out = _python("import sys\nsys.modules['numba.cuda'] = None\n" + ENSEMBLE)
    assert out.returncode == 0, out.stderr
    line = out.stdout.strip()
    assert line.startswith("REFUSED device='cuda' needs numba-cuda, which is not installed")
    assert "pip install 'lagrange-gen[gpu]'" in line and "\n" not in line


def test_without_a_gpu_one_line():
    if _gpu_here():
        pytest.skip("a CUDA GPU is present")
    out = _python(ENSEMBLE)
    assert out.returncode == 0, out.stderr
    line = out.stdout.strip()
    assert line.startswith("REFUSED device='cuda': no usable CUDA GPU (") and "\n" not in line
    assert "NUMBA_ENABLE_CUDASIM=1" in line


def test_sweep_without_a_gpu_says_so_in_one_line():
    if _gpu_here():
        pytest.skip("a CUDA GPU is present")
    out = _python("from lagrange_gen.cli.main import main\n"
                  f"raise SystemExit(main(['sweep', {CART!r}, '--grid', 'k=5:10:2', "
                  "'--h', '1e-3', '--t-end', '0.002', '--device', 'cuda']))")
    assert out.returncode != 0
    assert "Traceback" not in out.stderr
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "no usable CUDA GPU" in lines[0], out.stderr


#: (method, generated model, dtype) lowered by default: an explicit core, the dense LU solve, a
#: float32 member, and one method of each kind with saved extras; --thorough lowers every GPU
#: method.
LOWERED = [("rk4", "cart_pendulum", "float64"), ("implicit_euler", "cart_pendulum", "float64"),
           ("rk4", "cart_pendulum", "float32"), ("rattle", "cartesian_pendulum", "float64"),
           ("moreau_jean", "bouncing_ball", "float64")]
EVERY_KIND = {"constrained_midpoint": "cartesian_pendulum",
              "constrained_implicit_euler": "cartesian_pendulum", "spook": "cartesian_pendulum",
              "index1": "cartesian_pendulum", "nonsmooth_euler": "coulomb_oscillator",
              "nonholonomic_rk4": "chaplygin_sleigh", "explicit_euler": "cart_pendulum",
              "symplectic_euler": "cart_pendulum", "verlet": "cart_pendulum",
              "midpoint": "cart_pendulum", "spook_contacts": "pendulum_wall_cartesian"}
THOROUGH = [(m, model, "float64") for m, model in EVERY_KIND.items()]


@pytest.mark.parametrize("method, model, dtype", LOWERED + THOROUGH)
def test_members_lower_for_the_cuda_target(method, model, dtype, request):
    """The member of the method on the model types and lowers for the CUDA target, without an
    allocation (numba's runtime, NRT, would be called for one): rk4 (explicit_rk's core),
    implicit Euler (newton.solve, the dense LU solve), the constrained, nonsmooth, contact and
    nonholonomic cores with the multipliers and impulses they save."""
    if (method, model, dtype) not in LOWERED and not request.config.getoption("thorough",
                                                                             default=False):
        pytest.skip("--thorough lowers every GPU method")
    path = str(ROOT / "generated" / f"{model}.py")
    out = _python(
        "import lagrange_gen as lg\n"
        "from lagrange_gen.gpu.lowering import lower_member, missing_hook\n"
        "from lagrange_gen.steppers.core import registry\n"
        "reason = missing_hook()\n"
        "if reason:\n"
        "    print('SKIP', reason)\n"
        "else:\n"
        f"    module = lg.import_generated({path!r})\n"
        f"    spec = registry.spec({method!r})\n"
        "    n_saved = spec.n_saved(module.N_COORDS, module.N_CONSTRAINTS, module.N_ELEMENTS,\n"
        "                           getattr(module, 'N_CONTACTS', 0),\n"
        "                           getattr(module, 'N_NONHOLONOMIC', 0))\n"
        f"    ir = lower_member(module, {method!r}, n_saved, dtype={dtype!r})\n"
        "    print('NRT' if 'NRT_' in ir else 'LOWERED', len(ir))\n")
    assert out.returncode == 0, out.stderr[-3000:]
    if out.stdout.startswith("SKIP"):
        pytest.skip(out.stdout.strip())
    assert out.stdout.startswith("LOWERED"), out.stdout


def test_every_gpu_method_is_lowered_by_some_profile():
    from lagrange_gen.steppers.core import registry
    assert {m for m, _, _ in LOWERED + THOROUGH} == set(registry.GPU_METHODS)
