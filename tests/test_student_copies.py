"""The student copies (``build/student/``: the notebooks without their ``solution`` cells) run end to end.

A student opens these with ``make lab LAB_FROM=build/student`` and runs them before solving anything: every
exercise stub is unsolved, so its check says "not done yet" and later cells fall back to the reference
(:func:`beatlite.exercise.resolve`). No cell may fail. Each copy is executed as ``make run`` executes a notebook
(its own kernel, in ``notebooks/`` so relative paths hold, ``BEATLITE_BUILD`` a temporary folder).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def _run_notebooks():
    spec = importlib.util.spec_from_file_location("run_notebooks", REPO / "scripts" / "run_notebooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_the_student_copy_runs_end_to_end(path, tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    from nbclient.exceptions import CellExecutionError
    from nbconvert.preprocessors import ExecutePreprocessor

    _run_notebooks().write_student_copy(path, tmp_path / "student")
    nb = nbformat.read(tmp_path / "student" / path.name, as_version=4)
    assert not [c for c in nb.cells if "solution" in c.get("metadata", {}).get("tags", [])]
    stubs = [c for c in nb.cells if c.cell_type == "code" and "NotImplementedError" in c.source]
    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    monkeypatch.setenv("BEATLITE_INTERACTIVE", "off")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    ep = ExecutePreprocessor(timeout=900, kernel_name="python3", store_widget_state=False)
    try:
        ep.preprocess(nb, {"metadata": {"path": str(path.parent)}})
    except CellExecutionError as exc:
        pytest.fail(f"{path.name}, student copy: {str(exc).strip().splitlines()[-1]}")
    outputs = "".join(
        o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
    )
    if stubs:  # the unsolved exercises say so (and the reference keeps the lecture going)
        assert "not done yet" in outputs or "[exercise]" in outputs, path.name


def _notebook(path: Path, solution: bool, text: str = "") -> None:
    cells = [{"cell_type": "code", "metadata": {"tags": ["solution"] if solution else []}, "source": text,
              "outputs": [], "execution_count": None}]  # fmt: skip
    path.write_text(
        __import__("json").dumps({"cells": cells, "metadata": {}, "nbformat": 4, "nbformat_minor": 5})
    )


def test_lab_copies_replace_solution_copies_with_a_backup_and_keep_student_work(tmp_path):
    spec = importlib.util.spec_from_file_location("lab_copies", REPO / "scripts" / "lab_copies.py")
    lab_copies = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(lab_copies)
    student, lab = tmp_path / "student", tmp_path / "lab"
    student.mkdir()
    lab.mkdir()
    _notebook(student / "00_a.ipynb", False, "stub")
    _notebook(student / "01_b.ipynb", False, "stub")
    _notebook(student / "02_c.ipynb", False, "stub")
    _notebook(lab / "00_a.ipynb", True, "instructor's copy")  # from notebooks/: holds the solutions
    _notebook(lab / "01_b.ipynb", False, "my answer")  # a student's edited copy
    done = lab_copies.refresh(student, lab, stamp="T")
    assert done == [
        "replaced 00_a.ipynb (it held the solutions; the old copy is backup/00_a.T.ipynb)",
        "copied 02_c.ipynb",
    ]
    assert "instructor's copy" in (lab / "backup" / "00_a.T.ipynb").read_text()
    assert "stub" in (lab / "00_a.ipynb").read_text() and "my answer" in (lab / "01_b.ipynb").read_text()
    assert lab_copies.refresh(student, lab, stamp="U") == []  # nothing left to do


def test_the_run_record_holds_each_notebook_s_times_and_the_epochs_it_printed(tmp_path, monkeypatch):
    """``run_notebooks.py --record``: the record docs/teaching.md's tables are checked against (two tiny notebooks
    run for real: wall and kernel CPU seconds, what a cell printed as ``N s per epoch``, a failed one marked)."""
    import json

    import nbformat

    folder = tmp_path / "notebooks"
    folder.mkdir()
    for name, code in (
        ("01_a", "print('trained: 2.5 s per CaMN epoch; 0.25 s per epoch')"),
        ("02_b", "1 / 0"),
    ):
        nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
        nbformat.write(nb, folder / f"{name}.ipynb")
    run = _run_notebooks()
    monkeypatch.setattr(
        run, "_instructor_sheet", lambda: type("S", (), {"write_sheets": staticmethod(lambda *a: None)})
    )
    record_path = tmp_path / "record.json"
    code = run.main(
        [
            "--out",
            str(tmp_path / "out"),
            "--record",
            str(record_path),
            *map(str, sorted(folder.glob("*.ipynb"))),
        ]
    )
    record = json.loads(record_path.read_text())
    assert code == 1  # one notebook failed
    assert [(r["notebook"], r["ok"], r["printed_epoch_seconds"]) for r in record["rows"]] == [
        ("01_a", True, [2.5, 0.25]),
        ("02_b", False, []),
    ]
    assert all(r["wall_seconds"] > 0 and r["kernel_user_seconds"] >= 0 for r in record["rows"])
    assert record["total_wall_seconds"] >= sum(r["wall_seconds"] for r in record["rows"])
    assert record["largest_kernel_gib"] > 0 and record["machine"]["cpus"] and record["revision"]
