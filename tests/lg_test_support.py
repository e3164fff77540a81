"""What the test files share besides fixtures: the repository's paths, the model files, the
robots, and the portable glue the stepper tests run. A module of its own, not conftest.py:
pytest imports every conftest.py under the one module name "conftest", so ``from conftest
import ...`` finds whichever folder's conftest was imported last."""

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MODELS_DIR = ROOT / "models"
MODEL_FILES = sorted(MODELS_DIR.glob("*.py"))
#: The 3D robots of models/ (trees of bodies, 6 to 30 coordinates). Their equations written out in
#: sympy do not fit in memory, so the suites that check every model through sympy or compile every
#: kernel skip them; tests/derive/test_structured.py and tests/interop/test_pinocchio_trees.py check
#: the same identities on spatial trees of 2 to 6 bodies.
ROBOT_MODELS = ("humanoid", "spatial_chain", "ur5")


def glue(module, method):
    """What the tests call instead of ``module.run_<method>`` (same arguments and returns): the
    portable glue of ``method`` on ``module``'s kernels (lagrange_gen.jit.portable). It is compiled
    once per method for every model, where each model's own glue compiles the whole stepper
    again (several seconds per model and method, the bulk of this suite's time).
    tests/test_portable.py checks, for every method, that the module's own glue gives the same
    trajectory bit for bit; the step API, control and ensemble tests run the module's own glue."""
    from lagrange_gen.jit import portable
    return portable.runner(module, method)
