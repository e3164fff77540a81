"""The differential harness on spatial trees of rigid bodies and particles (issue 28, item 4):
trees drawn the ways users write them with sympy.physics.mechanics (trees.py), 3 to 10 bodies,
revolute and prismatic joints, random axes, offsets and full inertia tensors.

- 3-4 bodies: every kernel the generated module has against trees.TreeReference (Lagrange's
  equations of sympy's own kinematics, never through lagrange_gen.model.bodies or derive/),
  the Jacobian kernels against finite differences; as printed Python, and compiled in the
  thorough profile.
- 5-10 bodies: the invariants of tree_check.check_invariants (H symmetric positive definite,
  the energy identity under joint torques, inverse(forward) = tau, finite-difference Jacobians).

Counts per profile: profiles.py ("trees", "trees_njit", "large_trees"). The tests can fail:
test_reference_sees_a_wrong_inertia and test_invariants_see_a_wrong_kernel.
"""

import numpy as np
import pytest
from hypothesis import given, strategies as st

from . import profiles
from .check import CHECKED, CONTRACT, generate, pure_kernels
from .tree_check import check_against_reference, check_invariants, tree_states
from .trees import BodySpec, DrawnTree, TreeReference, spatial_trees
from .test_differential import _verdict

#: functions a module from bodies has beside KERNELS, each checked by check_against_reference
FORWARD = ("forward_dynamics", "forward_dynamics_torques", "forward_dynamics_jacobian", "accelerations")


def _against_reference(drawn, seed, out_dir, modes):
    mod = generate(drawn, out_dir, [])
    ref = TreeReference(drawn)
    unknown = sorted(set(mod.KERNELS) - set(CONTRACT))
    failures = [f"kernels without a contract in check.CONTRACT: {unknown}"] if unknown else []
    for mode in modes:
        kern = mod if mode == "njit" else pure_kernels(mod)
        for state in tree_states(drawn, mod, ref.params, seed, profiles.current()["states"]):
            failures += [f"{mode}: {f}" for f in check_against_reference(mod, kern, ref, state, mode)]
    return failures


@profiles.hypothesis_settings("trees")
@given(drawn=spatial_trees(3, 4), seed=st.integers(0, 2**32 - 1))
def test_small_tree_kernels_as_python_match_reference(drawn, seed, tmp_path_factory):
    _verdict(_against_reference(drawn, seed, tmp_path_factory.mktemp("trees"), ("py_func",)))


@pytest.mark.skipif(profiles.current()["trees_njit"] == 0, reason="compiled tree kernels: --thorough")
@profiles.hypothesis_settings("trees_njit")
@given(drawn=spatial_trees(3, 3), seed=st.integers(0, 2**32 - 1))
def test_small_tree_compiled_kernels_match_reference(drawn, seed, tmp_path_factory):
    _verdict(_against_reference(drawn, seed, tmp_path_factory.mktemp("trees"), ("py_func", "njit")))


@profiles.hypothesis_settings("large_trees")
@given(drawn=spatial_trees(5, 10), seed=st.integers(0, 2**32 - 1))
def test_large_tree_kernels_keep_the_invariants(drawn, seed, tmp_path_factory):
    mod = generate(drawn, tmp_path_factory.mktemp("trees"), [])
    kern = pure_kernels(mod)
    params = [type("P", (), {"name": n, "default": d}) for n, d in zip(mod.PARAMS, mod.DEFAULTS)]
    failures = []
    for state in tree_states(drawn, mod, params, seed, 2):
        failures += [f"py_func: {f}" for f in check_invariants(mod, kern, state, "py_func")]
    _verdict(failures)


def _one_tree():
    """A fixed 3-body tree: a chain with a branch, a slide, a particle, random axes."""
    inertia = (0.12, 0.1, 0.09, 0.01, -0.02, 0.005)
    return DrawnTree("tree_fixed", [
        BodySpec(-1, "revolute", "orient_axis", (0.6, 0.0, 0.8), (0.1, 0.0, 0.2), (0.2, 0.1, -0.1), 1.5, inertia),
        BodySpec(0, "prismatic", "none", (0.0, 0.6, 0.8), (0.3, 0.1, 0.0), (0.05, 0.0, 0.1), 1.2, inertia,
                 inertia_about_joint=True),
        BodySpec(0, "revolute", "body_fixed", (0.4, -0.7), (0.0, 0.2, -0.3), (0.25, 0.0, 0.1), 0.8, None)])


@pytest.fixture(scope="module")
def fixed_tree(tmp_path_factory):
    """(drawn, generated module) of _one_tree()."""
    drawn = _one_tree()
    return drawn, generate(drawn, tmp_path_factory.mktemp("fixed_tree"), [])


def test_reference_sees_a_wrong_inertia(fixed_tree):
    """The harness can fail: the product of inertia izx of the first body (which turns about
    (0.6, 0, 0.8), so izx enters H) off by 0.01 in the reference's tree."""
    drawn, mod = fixed_tree
    wrong = _one_tree()
    wrong.bodies[0].inertia = (0.12, 0.1, 0.09, 0.01, -0.02, 0.015)
    state = tree_states(drawn, mod, TreeReference(drawn).params, 1, 1)[0]
    kern = pure_kernels(mod)
    assert not check_against_reference(mod, kern, TreeReference(drawn), state, "py_func")
    failures = check_against_reference(mod, kern, TreeReference(wrong), state, "py_func")
    assert any(f.startswith("mass_matrix.H") for f in failures), failures


def test_invariants_see_a_wrong_kernel(fixed_tree):
    """The invariants can fail: inverse_dynamics off by 1e-7 in one entry, bias forces that
    forget gravity."""
    drawn, mod = fixed_tree
    kern = pure_kernels(mod)
    state = tree_states(drawn, mod, TreeReference(drawn).params, 2, 1)[0]
    assert not check_invariants(mod, kern, state, "py_func")

    def inverse_dynamics(q, qd, qdd, t, p, tau):
        kern_inverse(q, qd, qdd, t, p, tau)
        tau[1] += 1e-7

    def bias_forces(q, qd, t, p, out):
        kern_bias(q, qd, t, p, out)
        gravity = np.empty(len(q))
        kern.gravity_forces(q, t, p, gravity)
        out -= gravity

    kern_inverse, kern_bias = kern.inverse_dynamics, kern.bias_forces
    kern.inverse_dynamics, kern.bias_forces = inverse_dynamics, bias_forces
    failures = check_invariants(mod, kern, state, "py_func")
    assert any(f.startswith("inverse_dynamics(forward_dynamics_torques(tau))") for f in failures), failures
    assert any(f.startswith("bias_forces(q, 0)") for f in failures), failures


def test_every_kernel_of_a_tree_module_was_checked(fixed_tree):
    """Coverage: on one tree module, every kernel it has (KERNELS and the forward functions)
    is compared with the reference, as Python."""
    drawn, mod = fixed_tree
    before = CHECKED.copy()
    failures = []
    for state in tree_states(drawn, mod, TreeReference(drawn).params, 3, 2):
        failures += check_against_reference(mod, pure_kernels(mod), TreeReference(drawn), state, "py_func")
    assert not failures, failures
    ran = {kind for (kind, mode), count in CHECKED.items() if mode == "py_func" and count > before[(kind, mode)]}
    names = set(mod.KERNELS) | {f for f in FORWARD if hasattr(mod, f)}
    names = {n for n in names if not n.startswith(("constraint", "elements", "events"))}   # empty here
    kinds = {k.split("[")[0] for k in ran}
    assert names <= kinds, f"never checked: {sorted(names - kinds)}"
