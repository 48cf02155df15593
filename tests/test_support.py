"""Tests of the small support modules: paths, report, exercise, notebook."""

from __future__ import annotations

import pytest

from beatlite import exercise, notebook, paths, report


def test_paths_read_environment_at_call_time(monkeypatch, tmp_path):
    monkeypatch.setenv("BEATLITE_DATA", str(tmp_path))
    assert paths.data_dir() == tmp_path
    monkeypatch.delenv("BEATLITE_DATA")
    assert paths.data_dir() == paths.repo_root() / "data_samples"


@pytest.mark.parametrize("value", ["0", "-1", "two"])
def test_bad_thread_count_is_a_clear_error(monkeypatch, value):
    monkeypatch.setenv("BEATLITE_THREADS", value)
    with pytest.raises(ValueError, match="BEATLITE_THREADS"):
        paths.n_threads()


def test_mode(monkeypatch):
    monkeypatch.delenv("BEATLITE_MODE", raising=False)
    assert paths.mode() == "lecture"
    monkeypatch.setenv("BEATLITE_MODE", "FULL")
    assert paths.mode() == "full"
    monkeypatch.setenv("BEATLITE_MODE", "fast")
    with pytest.raises(ValueError, match="lecture"):
        paths.mode()


def test_save_table_is_atomic_and_validated(monkeypatch, tmp_path):
    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path))
    out = report.save_table("02_table1", "| a |\n|---|\n| 1 |", title="Table 1")
    assert out == tmp_path / "tables" / "02_table1.md"
    assert out.read_text() == "### Table 1\n\n| a |\n|---|\n| 1 |\n"
    assert [p.name for p in out.parent.iterdir()] == ["02_table1.md"]  # no temp file left behind
    with pytest.raises(ValueError, match="name"):
        report.save_table("../evil", "x")


def _square(x):
    return x * x


def test_exercise_resolve_and_check(capsys):
    def stub(x):
        raise NotImplementedError

    def wrong(x):
        return x + x

    assert exercise.resolve(stub, _square)(3) == 9
    assert "not done yet" in capsys.readouterr().out
    assert exercise.resolve(_square, lambda x: -1)(3) == 9
    assert exercise.check("square", stub, _square, [(2,)]) is None
    assert exercise.check("square", wrong, _square, [(2,), (3,)]) is False  # 2+2 == 2*2 but 3+3 != 9
    assert "case 1 differs" in capsys.readouterr().out
    assert exercise.check("square", _square, _square, [((4,), {})]) is True


def test_require_and_setup(capsys):
    notebook.require("0.0.1")
    with pytest.raises(RuntimeError, match="beatlite >= 99"):
        notebook.require("99.0")
    info = notebook.setup(seed=1)
    assert info["mode"] in paths.MODES
    assert "beatlite" in capsys.readouterr().out
