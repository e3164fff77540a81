"""bench robots (issue 28) machinery without its measurements: a child that runs past its limit
is recorded as a timeout with the stage it was in, and the report marks goals from the rows
(no timing asserts)."""

import json

from lg_test_support import MODELS_DIR
from lagrange_gen.bench import robots, robots_report


def _lines(*events):
    return "\n".join(json.dumps(e) for e in events) + "\n"


def test_events_fold_into_a_row_and_name_the_stage_that_did_not_finish():
    out = _lines({"stage": "model file", "at": 0.1}, {"result": {"model_file": 2.0, "n": 8}, "at": 2.1},
                 {"stage": "derive", "at": 2.1}, {"result": {"derive": 1.0}, "at": 3.1},
                 {"stage": "emit", "at": 3.1}, {"detail": "kernel 5/8 rhs_jacobian", "at": 4.0})
    row = robots.parse_events(out + "not json\n")
    assert row["model_file"] == 2.0 and row["n"] == 8 and row["derive"] == 1.0
    assert row["where"] == "emit: kernel 5/8 rhs_jacobian"
    assert "done" not in row


def test_a_child_past_its_limit_is_a_timeout_row(tmp_path):
    row = robots.measure_case(MODELS_DIR / "spatial_chain.py", {"n": 3}, tmp_path / "case", limit=1.0)
    assert row["timeout"] and row["wall"] < 30
    assert row["where"] in ("start", "model file", "derive", "emit") or row["where"].startswith("emit")


def test_report_marks_the_goals_from_the_rows():
    done = {"label": "UR5", "stem": "ur5", "n": 6, "model_file": 1.0, "derive": 1.0, "emit": 1.0,
            "kernel_compile": 1.0, "first_step": 1.0, "lines": 100, "kb": 5.0, "done": True,
            "fd_ns": 3000.0, "accel_ns": 9000.0, "pin_aba_ns": 4000.0, "dqdd_py_ns": 1.0,
            "dqdd_jit_ns": 1.0, "pin_daba_ns": 1.0, "rk4_ns": 1.0, "pin_rk4_py_ns": 1.0,
            "err_H": 1e-16, "err_qdd": 1e-16, "err_dq": 1e-15, "err_dv": 1e-15}
    slow = {"label": "spatial chain, 12 links", "stem": "spatial_chain", "n": 12, "model_file": 39.0,
            "timeout": True, "limit": 300.0, "where": "derive"}
    text = "\n".join(robots_report.markdown([done, slow]))
    assert "| UR5 `mod.accelerations` per call | 9.00 us (2.2x pin.aba) | <= 1.5x pin.aba | **not met** |" in text
    assert "| UR5 forward dynamics per call from Python | 3.00 us vs pin.aba 4.00 us | faster than pin.aba | **met** |" in text
    assert "timeout after 300 s (in derive)" in text
    assert "| spatial chain, 12 links: generate + compile + first step | timeout after 300 s (in derive) | <= 30 s | **not met** |" in text
