"""bench firstrun (issue 40 item 7) machinery: one real case (the cart pendulum's first rk4 step
on empty caches, then again in a new process) writes a report whose numbers are positive and
finite; a child past its limit is a timeout row naming its phase; the goals are judged from the
rows. No timing asserts."""

import json
import math
import re

from lg_test_support import MODELS_DIR
from lagrange_gen.bench import firstrun, firstrun_report


def _row(cpu, **extra):
    return {"cpu": cpu, "rss_mb": 300.0, "wall": cpu, "phases": {"first simulate": cpu / 2},
            "done": True, "where": "after first simulate", **extra}


def test_cart_pendulum_first_step_report_has_positive_finite_numbers(tmp_path):
    case = firstrun.Case("cart pendulum, rk4", "cart_pendulum", "rk4", q0=(0.1, 1.0),
                         variants=("empty", "again"))
    command = firstrun.Case("lagrange-gen, unchanged", "cart_pendulum", "rk4", kind="cli",
                            variants=("again",), after=case.label)
    out = firstrun.run_firstrun_bench(MODELS_DIR, tmp_path, cases=[case, command],
                                      percall=False, progress=False, command="test")
    unchanged = out["results"][command.label]["again"]      # the module the case generated
    assert unchanged.get("done") and unchanged["cpu"] > 0, unchanged
    rows = out["results"][case.label]
    for variant in ("empty", "again"):
        row = rows[variant]
        assert row.get("done") and not row.get("error") and not row.get("timeout"), row
        assert math.isfinite(row["cpu"]) and row["cpu"] > 0
        assert math.isfinite(row["rss_mb"]) and row["rss_mb"] > 0
        assert set(row["phases"]) == {"imports", "model file to module", "kernels",
                                      "first simulate"}
        assert all(math.isfinite(s) and s >= 0 for s in row["phases"].values())
        assert row["final_finite"]
    # the new process finds the module and the kernels' object code cached
    assert rows["empty"]["native_new"] > 0 and rows["again"]["native_new"] == 0
    assert rows["again"]["native_cached"] == rows["empty"]["native_new"]
    text = out["report"].read_text()
    assert text.startswith("# From model file to first step")
    line = next(x for x in text.splitlines() if x.startswith("| cart pendulum, rk4 |"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    empty, again = float(cells[1]), float(cells[2])     # columns: the variants measured
    assert empty > 0 and again > 0
    for goal in firstrun.GOALS:                      # every goal of the issue has its row
        assert f"| {goal[0]} | {goal[1]} | {goal[2]} |" in text
    assert "peak memory of any generation or compile" in text
    assert re.search(r"\| cart pendulum, rk4 \| empty caches \| imports [0-9.]+; model file", text)


def test_a_child_past_its_limit_is_a_timeout_row_naming_its_phase(tmp_path):
    case = firstrun.Case("x", "cart_pendulum", "rk4")
    dirs = {"numba": tmp_path / "numba", "portable": tmp_path / "portable"}
    row = firstrun.run_child(firstrun.child_spec(case, MODELS_DIR, tmp_path / "gen"),
                             firstrun.child_env(dirs), timeout=0.3, work=tmp_path / "work")
    assert row["timeout"] == 0.3 and "done" not in row
    assert row["cpu"] >= 0 and row["where"] in ("start", "imports")
    assert firstrun_report.seconds(row).startswith("> 0 s (")


def test_events_fold_into_phases_and_results():
    out = "\n".join(json.dumps(e) for e in (
        {"enter": "imports"}, {"phase": "imports", "cpu": 0.5},
        {"enter": "kernels"}, {"result": {"native_new": 3}})) + "\nnot json\n"
    row = firstrun.parse_events(out)
    assert row["phases"] == {"imports": 0.5} and row["native_new"] == 3
    assert row["where"] == "kernels" and "done" not in row


def test_goals_are_judged_on_the_warm_library_and_new_process_rows():
    results = {
        "spatial chain, 8 links, rk4": {"empty": _row(20.0), "library": _row(2.5),
                                        "library, numba": _row(30.0)},
        "spatial chain, 12 links, midpoint": {"library": _row(9.0)},
        "controlled cart pendulum (cart pole), midpoint": {"library": _row(0.5),
                                                           "again": _row(4.0)},
        "humanoid, 30 DoF, implicit_euler": {"library": {"cpu": 400.0, "rss_mb": 3000.0,
                                                         "timeout": 400.0, "phases": {},
                                                         "where": "kernels"}},
    }
    rows = {r[0]: r for r in firstrun_report.goal_rows(firstrun.GOALS, results)}
    chain8 = rows["8-link spatial chain, model file to first rk4 step"]
    assert chain8[3:5] == ["2.50", "**met**"]
    assert "empty caches (the method's glue compiled too): 20.00" in chain8[5]
    assert "numba kernels: 30.00" in chain8[5]
    assert rows["12-link chain, first midpoint step (implicit: Jacobians)"][4] == "**not met**"
    # "a new process" is judged on the run that finds everything cached
    assert rows["controlled cart pendulum, a new process"][3:5] == ["4.00", "**not met**"]
    humanoid = rows["30-DoF humanoid, first implicit_euler step"]
    assert humanoid[3].startswith("> 400 s") and humanoid[4] == "**not met**"
    assert rows["bouncing ball, first dop853_impacts step"][4] == "not measured"
    memory = firstrun_report.memory_row(results)
    assert memory[3] == "3000 MB" and memory[4] == "**not met**" and "humanoid" in memory[5]
