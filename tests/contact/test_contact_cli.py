"""The CLI on a model with contacts: the summary names what moreau_jean counts (projected
Gauss-Seidel sweeps, not Newton iterations) and gives the energy balance E - E0 - W with W the
work of the contact impulses, not a bare max |E - E0| (the impacts dissipate)."""

import re

import pytest

from lagrange_gen.cli.main import main


def test_summary_of_a_bouncing_ball(generated, capsys):
    module = generated("bouncing_ball")
    assert main(["simulate", module.__file__, "--method", "moreau_jean", "--h", "1e-3",
                 "--t-end", "5", "--q0", "1"]) == 0
    out = capsys.readouterr().out
    assert "Gauss-Seidel sweeps per step: " in out and "Newton iterations" not in out
    balance = re.search(r"max \|E - E0 - W\| = (\S+) \(E0 = 9.81, W the work of the contact "
                        r"impulses, final W = (\S+)\)", out)
    assert balance, out
    # theta = 1/2 closes the balance to rounding under constant gravity (test_moreau_jean.py);
    # at rest (after the Zeno time 2.7 s) the impacts took all of m g h0 = 9.81 but h V0 g.
    assert float(balance.group(1)) <= 1e-11 * 9.81
    assert abs(float(balance.group(2)) + 9.81) <= 9.81 * 1e-3 * 4.43


def test_summary_of_an_event_driven_bouncing_ball(generated, capsys):
    """dop853_impacts: the same balance line, closed to rounding (exact parabolas, impacts at
    located times), and no solver-sweep line (an adaptive run counts steps)."""
    module = generated("bouncing_ball")
    assert main(["simulate", module.__file__, "--method", "dop853_impacts", "--t-end", "5",
                 "--q0", "1"]) == 0
    out = capsys.readouterr().out
    assert "Gauss-Seidel" not in out and "Newton iterations" not in out
    first = re.search(r"impacts: (\d+); first t = (\S+) \(contact 0, p_N = (\S+)\)", out)
    assert first, out
    assert float(first.group(2)) == pytest.approx((2 / 9.81) ** 0.5, abs=1e-10)
    assert float(first.group(3)) == pytest.approx((1 + 0.8) * (2 * 9.81) ** 0.5, rel=1e-5)  # 6 digits
    balance = re.search(r"max \|E - E0 - W\| = (\S+) \(E0 = 9.81, W the work of the contact "
                        r"impulses and of the persistent contacts' forces, final W = (\S+)\)", out)
    assert balance, out
    assert float(balance.group(1)) <= 1e-11 * 9.81
    # at rest from the Zeno time (2.7 s) on: all of m g h0 went into the impacts
    assert abs(float(balance.group(2)) + 9.81) <= 1e-9
