"""A truncated, corrupted or inconsistent trajectory file is one line naming the file, through
Trajectory.load and ``lagrange-gen animate`` (issue 34, item 6)."""

import json

import numpy as np
import pytest

from lagrange_gen import LagrangeGenError, Trajectory
from lagrange_gen.cli.main import main


@pytest.fixture(scope="module")
def good_file(run, tmp_path_factory):
    path = tmp_path_factory.mktemp("traj") / "good.npz"
    run("pendulum").save(path)
    return path


def _rewrite(good, path, change):
    with np.load(good, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    change(arrays)
    np.savez(path, **arrays)


def _bad_meta(text):
    def change(arrays):
        arrays["meta"] = np.array(text)
    return change


def _drop_meta_key(key):
    def change(arrays):
        meta = json.loads(str(arrays["meta"]))
        del meta[key]
        arrays["meta"] = np.array(json.dumps(meta))
    return change


def _short_q(arrays):
    arrays["q"] = arrays["q"][:-3]


BAD = {
    "truncated": lambda good, path: path.write_bytes(good.read_bytes()[: len(good.read_bytes()) // 2]),
    "corrupted": lambda good, path: path.write_bytes(
        good.read_bytes()[:200] + b"\x00" * 400 + good.read_bytes()[600:]),
    "meta_not_json": lambda good, path: _rewrite(good, path, _bad_meta("{not json")),
    "meta_not_a_dict": lambda good, path: _rewrite(good, path, _bad_meta("[1, 2]")),
    "meta_without_saved": lambda good, path: _rewrite(good, path, _drop_meta_key("saved")),
    "q_rows_do_not_match_t": lambda good, path: _rewrite(good, path, _short_q),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_file_is_one_line_naming_it(good_file, tmp_path, case):
    path = tmp_path / f"{case}.npz"
    BAD[case](good_file, path)
    with pytest.raises(LagrangeGenError) as err:
        Trajectory.load(path)
    text = str(err.value)
    assert "\n" not in text and str(path) in text, text


@pytest.mark.parametrize("case", ["truncated", "meta_not_json", "q_rows_do_not_match_t"])
def test_animate_of_a_bad_file_exits_with_one_line(good_file, tmp_path, capsys, case):
    path = tmp_path / f"{case}.npz"
    BAD[case](good_file, path)
    code = main(["animate", str(path), "--out", str(tmp_path / "out.gif")])
    err = capsys.readouterr().err
    assert code != 0 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert f"{case}.npz" in err


def test_the_good_file_still_loads(good_file):
    assert Trajectory.load(good_file).q.shape[1] == 2
