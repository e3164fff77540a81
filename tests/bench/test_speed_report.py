"""The speed report's first-use rows (bench/speed_report.py) from a results dict with the keys
bench/speed.measure_cold returns: the verdict of a model just written and of the fully cold
first model are both stated, each against the goal, and the detail table carries the three
totals. Made-up numbers: this checks the report's logic, never a timing."""

from lagrange_gen.bench import speed, speed_report


def _cold_row(label, goal, library_cached, total):
    return {"label": label, "method": "verlet", "goal": goal, "cache": "/tmp/x", "path": "m.py",
            "imports": 0.3, "generate": 0.4, "first_simulate": total - 0.4, "jit": "portable",
            "total": total, "library_cached": library_cached, "library_generate": 0.4,
            "library_jit": "portable", "specialized": 12.0}


def _results():
    return {
        "quick": True, "mujoco": False, "case": speed.CASE, "chain_n": speed.CHAIN_N,
        "precision": {"ours": {"rk4": 5e-4}, "peers": {}, "pydy": None},
        "steps": [{"method": "rk4", "ours_ns": 130.0, "hand_ns": 76.0, "iters": 0.0,
                   "portable_ns": 195.0}],
        "chain": {"ours": {"symplectic_euler": 4800.0, "verlet": 8600.0, "rk4": 6800.0},
                  "portable": {"symplectic_euler": 5000.0, "verlet": 9000.0, "rk4": 7000.0},
                  "mujoco": None, "equivalence": None},
        "cold": [_cold_row("cart pendulum, verlet", 3.0, 1.7, 15.2),
                 _cold_row("10-link chain, verlet", 10.0, 11.0, 21.0)],
        "warm": {"imports": 0.25, "module_import": 0.05, "first_step": 0.25, "wall": 0.7},
    }


def test_first_use_rows_state_both_verdicts():
    lines = speed_report.markdown(_results())
    rows = [line for line in lines if line.startswith("| first simulate of a model just written")]
    assert len(rows) == 2
    assert "| 1.7 s (first model after an install, everything cold: 15.2 s) | <= 3 s | met " \
           "(everything cold: not met) |" in rows[0]
    assert "| 11.0 s (first model after an install, everything cold: 21.0 s) | <= 10 s | " \
           "not met (everything cold: not met) |" in rows[1]
    detail = [line for line in lines if line.startswith("| cart pendulum, verlet |")]
    assert detail == ["| cart pendulum, verlet | 0.40 | 1.30 | 1.70 | portable | 15.20 | 12.00 "
                      "| <= 3 |"]
    assert "| rk4 | 130 | 76 | 1.71 | 0.00 | 195 (1.50x) |" in lines
    assert "- ours verlet: 8600 ns (portable loop: 9000 ns)" in lines


def test_cold_cases_cover_the_issue_goals():
    goals = {label: goal for label, _, _, _, _, goal in speed.COLD}
    assert goals == {"cart pendulum, midpoint": 3.0, "cart pendulum, verlet": 3.0,
                     "cart pendulum, rk4": 3.0, "Cartesian pendulum, rattle": 5.0,
                     "10-link chain, verlet": 10.0}
