"""The import graph of the package files kept on disk (jit/sources.py, IMPORT_MEMO_FILE): a
new process reads it instead of parsing the files its glue compiles from, and an entry counts
only for the content it was made from."""

import json

import pytest

from lagrange_gen.jit import folders, sources


@pytest.fixture
def memo_dir(tmp_path, monkeypatch):
    monkeypatch.setattr(folders, "portable_dir", lambda: tmp_path)
    monkeypatch.setitem(sources._IMPORT_MEMO, "entries", None)
    return tmp_path


def _fresh_process(monkeypatch):
    """What a new process starts with: no memo in memory, no parse memoized."""
    monkeypatch.setitem(sources._IMPORT_MEMO, "entries", None)
    sources._imports_of.cache_clear()


def test_the_closure_is_written_and_read_back(memo_dir, monkeypatch):
    files = sources.source_closure(["run.control"])
    saved = json.loads((memo_dir / sources.IMPORT_MEMO_FILE).read_text())
    assert set(saved) == set(files)
    assert "steppers/core/options.py" in files and "jit/folders.py" in files
    _fresh_process(monkeypatch)
    monkeypatch.setattr(sources, "_imports_of", lambda *args: pytest.fail(f"parsed {args[0]}"))
    assert sources.source_closure(["run.control"]) == files


def test_an_entry_of_other_content_is_parsed_again(memo_dir, monkeypatch):
    files = sources.source_closure(["run.control"])
    saved = json.loads((memo_dir / sources.IMPORT_MEMO_FILE).read_text())
    # the memo claims control.py imports nothing: believed for its content, not for another
    saved["run/control.py"] = [saved["run/control.py"][0], []]
    (memo_dir / sources.IMPORT_MEMO_FILE).write_text(json.dumps(saved))
    _fresh_process(monkeypatch)
    assert sources.source_closure(["run.control"]) == ("run/control.py",)
    saved["run/control.py"] = ["0" * 16, []]
    (memo_dir / sources.IMPORT_MEMO_FILE).write_text(json.dumps(saved))
    _fresh_process(monkeypatch)
    assert sources.source_closure(["run.control"]) == files
    assert json.loads((memo_dir / sources.IMPORT_MEMO_FILE).read_text())["run/control.py"][0] != "0" * 16


@pytest.mark.parametrize("junk", ["", "not json", "[1, 2]", '{"run/control.py": 3}'])
def test_a_broken_memo_is_no_memo(memo_dir, monkeypatch, junk):
    (memo_dir / sources.IMPORT_MEMO_FILE).write_text(junk)
    expected = sources.source_closure(["run.control"])
    _fresh_process(monkeypatch)
    (memo_dir / sources.IMPORT_MEMO_FILE).write_text(junk)
    monkeypatch.setitem(sources._IMPORT_MEMO, "entries", None)
    assert sources.source_closure(["run.control"]) == expected
