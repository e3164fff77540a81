"""A start inside a contact (gap < 0): one warning line naming the contact and its gap, then the
projection out of it (default: no launch, no energy gained during the run) or a one-line
refusal (penetration="refuse"); run/contact_start.py.

Before the check, spook_contacts launched the bouncing ball released 0.5 m inside the floor to
hundreds of metres and moreau_jean / dop853_impacts kept it inside, all silently.

The projected start of a ball at rest inside the floor is y = 0, v = 0 (the nearest point of
y >= 0; nothing approaches), so from there the ball rests: its energy stays m g 0 = 0 and its
height 0 up to the method's rounding.
"""

import warnings

import numpy as np
import pytest

from lagrange_gen.run.contact_start import ContactPenetration, metric_projection
from lagrange_gen.run.simulate import simulate

G = 9.81
METHODS = {"spook_contacts": {"h": 1e-3}, "moreau_jean": {"h": 1e-3}, "dop853_impacts": {}}


def _ball(generated, method, y0, v0=0.0, **options):
    return simulate(generated("bouncing_ball"), method=method, q0=[y0], v0=[v0], t_end=0.5,
                    params={"g": G, "e": 0.8}, **METHODS[method], **options)


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("depth", [0.5, 1e-3])
def test_start_inside_the_floor_warns_and_never_gains_energy(generated, method, depth):
    with pytest.warns(UserWarning) as record:
        traj = _ball(generated, method, -depth)
    lines = [str(w.message) for w in record if "inside contact" in str(w.message)]
    assert len(lines) == 1 and "\n" not in lines[0]
    assert f"inside contact 'floor' (gap = {-depth:.6g} < 0)" in lines[0]
    assert traj.q[0, 0] == pytest.approx(0.0, abs=1e-9) and traj.v[0, 0] == 0.0
    # Nothing launches it: it rests on the floor, its energy never above the projected start's.
    assert np.abs(traj.q[:, 0]).max() <= 1e-6
    assert traj.energy.max() <= traj.energy[0] + 1e-9 * G


@pytest.mark.parametrize("method", sorted(METHODS))
def test_approaching_velocity_inside_is_removed_not_reversed(generated, method):
    """Released 1 mm inside, moving down at 2 m/s: projected to y = 0 with v = 0 (an inelastic
    impulse), not bounced back up at 2 e m/s."""
    with pytest.warns(UserWarning, match="inside contact 'floor'"):
        traj = _ball(generated, method, -1e-3, v0=-2.0)
    assert traj.v[0, 0] == 0.0
    assert traj.q[:, 0].max() <= 1e-6


@pytest.mark.parametrize("method", sorted(METHODS))
def test_refuse_mode_raises_one_line(generated, method):
    with pytest.raises(ContactPenetration) as info:
        _ball(generated, method, -0.5, penetration="refuse")
    message = str(info.value)
    assert "\n" not in message
    assert "inside contact 'floor' (gap = -0.5 < 0)" in message and "penetration=" in message


def test_start_on_or_above_the_floor_is_left_alone(generated):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        traj = _ball(generated, "moreau_jean", 0.0)
    assert traj.q[0, 0] == 0.0


def test_unknown_penetration_mode_is_refused(generated):
    with pytest.raises(Exception, match="penetration='bounce'"):
        _ball(generated, "moreau_jean", -0.5, penetration="bounce")


def test_metric_projection_hand_derived():
    """min x^T H x / 2 with x1 + x2 >= 1, H = diag(1, 4): x = H^-1 W^T lam on the line
    x1 + x2 = 1, lam (1 + 1/4) = 1, lam = 0.8, x = (0.8, 0.2). A second row x2 >= -5 stays
    inactive (lam 0); with x1 - x2 = 0 as an equality x = (0.5, 0.5)."""
    H, W = np.diag([1.0, 4.0]), np.array([[1.0, 1.0], [0.0, 1.0]])
    x, lam = metric_projection(H, W, np.array([-1.0, 5.0]))
    assert np.allclose(x, [0.8, 0.2]) and np.allclose(lam, [0.8, 0.0])
    x, _ = metric_projection(H, W[:1], np.array([-1.0]), np.array([[1.0, -1.0]]), np.zeros(1))
    assert np.allclose(x, [0.5, 0.5])
    # a row violated at the start whose multiplier turns negative leaves the active set
    x, lam = metric_projection(np.eye(2), np.array([[1.0, 0.0], [1.0, 0.0]]),
                               np.array([-2.0, -1.0]))
    assert np.allclose(x, [2.0, 0.0]) and lam.min() >= 0.0


def test_cli_penetration_option(generated, capsys):
    """lagrange-gen simulate --penetration refuse: exit status 1 and the one line; the default
    warns in one line and runs from the projected start."""
    from lagrange_gen.cli.main import main
    path = generated("bouncing_ball").__file__
    common = ["simulate", path, "--method", "moreau_jean", "--h", "1e-3", "--t-end", "0.01",
              "--q0", "-0.5"]
    assert main(common + ["--penetration", "refuse"]) != 0
    err = capsys.readouterr().err
    assert "inside contact 'floor' (gap = -0.5 < 0); penetration='refuse'" in err
    assert main(common) == 0
    captured = capsys.readouterr()
    lines = [line for line in (captured.err + captured.out).splitlines()
             if "inside contact 'floor'" in line]
    assert len(lines) == 1 and "projected onto g(q) >= 0" in lines[0]
