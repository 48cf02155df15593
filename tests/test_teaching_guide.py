"""docs/teaching.md agrees with the notebooks: its numbers come from the notebooks' header cells.

Each notebook's first cell says ``**Estimated time:** lecture ~N min; running it takes RUN on 2 CPU cores``, and
notebooks 05-07 and 10 add what ``full`` mode trains live (epochs, seconds per epoch, the extra wall time). The guide's
lecture plan and its full-mode table repeat these numbers; a header changed without the guide (or the other way
round) fails here. Notebook 00's map names every notebook, and the guide quotes the progress bar as
``beatlite.train`` formats it.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
GUIDE = REPO / "docs" / "teaching.md"
NOTEBOOKS = sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))

TIME = re.compile(r"\*\*Estimated time:\*\* lecture ~(\d+) min; running it takes (.+?) on 2 CPU cores")
FULL = re.compile(r"`full` mode also (.*)")
EPOCHS = re.compile(r"(\d+)[- ]epoch")
PER_EPOCH = re.compile(r"([\d.]+) s per (?:\w+ )?epoch")
EXTRA = re.compile(r"about (\d+) s more")


def _norm(text: str) -> str:
    """One line, one kind of dash, no spaces around it."""
    return re.sub(r"\s*[–-]\s*", "–", " ".join(text.split()))


def _header(path: Path) -> str:
    cell = json.loads(path.read_text())["cells"][0]
    assert cell["cell_type"] == "markdown", f"{path.name}: the first cell is the header (markdown)"
    return " ".join("".join(cell["source"]).split())


def header_times(path: Path) -> dict:
    """``lecture`` minutes and ``run`` time (text) of a header; ``full``: (epochs, s per epoch, extra s) or None."""
    text = _header(path).split("**Reproduces:**")[0]
    m = TIME.search(text)
    assert m, (
        f"{path.name}: the header has no '**Estimated time:** lecture ~N min; running it takes ...' line"
    )
    full = FULL.search(text)
    numbers = None
    if full:
        part = full.group(1)
        epochs, per_epoch, extra = EPOCHS.search(part), PER_EPOCH.search(part), EXTRA.search(part)
        assert epochs and per_epoch and extra, (
            f"{path.name}: the full-mode sentence lacks epochs, s/epoch or extra"
        )
        numbers = (int(epochs.group(1)), float(per_epoch.group(1)), int(extra.group(1)))
    return {"lecture": int(m.group(1)), "run": _norm(m.group(2)), "full": numbers}


def _table_rows(heading: str) -> list[list[str]]:
    """The cells of the first table after ``heading`` in the guide (header and separator rows dropped)."""
    text = GUIDE.read_text()
    start = text.index(heading)
    rows, seen = [], False
    for line in text[start:].splitlines()[1:]:
        if line.startswith("|"):
            seen = True
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not set("".join(cells)) <= set("-: "):
                rows.append(cells)
        elif seen:
            break
    return rows[1:]


def guide_plan() -> dict[str, dict]:
    plan = {}
    for cells in _table_rows("## The lecture plan"):
        plan[cells[0] or cells[1]] = {"lecture": cells[2], "run": cells[3]}
    return plan


def guide_full_mode() -> dict[str, tuple[int, float, int]]:
    found = {}
    for cells in _table_rows("### What `full` mode adds"):
        number = cells[0].split()[0]
        found[number] = (int(cells[2]), float(cells[3].split()[0]), int(cells[4].split()[0]))
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_plan_row_matches_the_notebook_header(path):
    header = header_times(path)
    row = guide_plan().get(path.name[:2])
    assert row, f"docs/teaching.md: the lecture plan has no row for {path.name}"
    assert row["lecture"] == f"{header['lecture']} min", (
        f"{path.name}: lecture {header['lecture']} min in its header, {row['lecture']!r} in docs/teaching.md"
    )
    assert _norm(row["run"]) == header["run"], (
        f"{path.name}: run time {header['run']!r} in its header, {row['run']!r} in docs/teaching.md"
    )


def test_plan_total_is_the_sum_of_the_headers():
    plan = guide_plan()
    assert set(plan) - {"**total**"} == {p.name[:2] for p in NOTEBOOKS}, "one plan row per notebook"
    total = sum(header_times(p)["lecture"] for p in NOTEBOOKS)
    assert plan["**total**"]["lecture"] == f"**{total} min**"
    assert f"about {total} minutes of lecture" in GUIDE.read_text(), (
        "the guide's first paragraph states the total"
    )


def test_full_mode_table_matches_the_headers():
    headers = {p.name[:2]: header_times(p)["full"] for p in NOTEBOOKS}
    expected = {k: v for k, v in headers.items() if v is not None}
    assert set(expected) == {"05", "06", "07", "10"}, (
        f"notebooks whose header describes full mode: {sorted(expected)}"
    )
    assert guide_full_mode() == expected


def test_the_lecture_series_splits_the_plan_minutes():
    """Every lecture of the minute-by-minute plan adds up to its notebooks' header minutes."""
    text = GUIDE.read_text()
    lectures = re.findall(r"^### Lecture (\d): notebooks? ([\d, and]+) \((\d+) min\)", text, re.M)
    assert len(lectures) >= 4, (
        "the guide plans each lecture under '### Lecture N: notebooks AA and BB (M min)'"
    )
    minutes = {p.name[:2]: header_times(p)["lecture"] for p in NOTEBOOKS}
    covered = []
    for number, names, total in lectures:
        nbs = re.findall(r"\d\d", names)
        covered += nbs
        assert sum(minutes[n] for n in nbs) == int(total), f"lecture {number}: {nbs} add up to {total} min?"
        block = text.split(f"### Lecture {number}:", 1)[1].split("\n### ", 1)[0]
        spans = [(int(a), int(b)) for a, b in re.findall(r"^\| (\d+)–(\d+) \|", block, re.M)]
        assert spans and spans[0][0] == 0 and spans[-1][1] == int(total), (
            f"lecture {number}: minutes 0–{total}"
        )
        assert all(b0 == a1 for (_, b0), (a1, _) in zip(spans, spans[1:])), (
            f"lecture {number}: gaps or overlaps"
        )
    assert sorted(covered) == sorted(minutes), "every notebook is in exactly one lecture"


def test_notebook_00_maps_every_notebook():
    nb = json.loads(NOTEBOOKS[0].read_text())
    text = next("".join(c["source"]) for c in nb["cells"] if "## 6. The notebook map" in "".join(c["source"]))
    mapped = re.findall(r"^\| \*\*(\d\d) ", text, re.M)
    assert mapped == [p.name[:2] for p in NOTEBOOKS]
    assert "BEAT Table 4" in text and "make lab" in "".join("".join(c["source"]) for c in nb["cells"])


def test_real_beat_uses_the_fit_route():
    """Training on real BEAT writes to its own --out, never over the shipped checkpoints/."""
    text = GUIDE.read_text()
    assert "python -m beatlite.train fit camn_tiny --data" in text and "--out" in text
    assert not re.search(r"BEATLITE_DATA=\S+ make checkpoints", text)
    assert "CC BY-NC 4.0" in text


def test_quoted_progress_bar_is_what_fit_prints():
    """The bar quoted in the guide has the postfix ``beatlite.train`` writes (model name, unweighted term)."""
    from beatlite.train.training import _shown_losses

    text = GUIDE.read_text()
    bars = re.findall(r"`(\w+): 100%\|[^`]*?, (\w+=[\d.]+, val_\w+=[\d.]+)\]`", text)
    assert bars, "the guide quotes one progress bar line"
    for _name, postfix in bars:
        keys = dict(pair.split("=") for pair in postfix.split(", "))
        main = next(iter(keys))
        entry = {"train": {main: float(keys[main]), "total": 9.0}, "val": {main: float(keys[f"val_{main}"])}}
        shown = ", ".join(f"{k}={v}" for k, v in _shown_losses(entry).items())
        assert shown == postfix


def test_guide_calls_name_real_parameters():
    """Every backticked ``name(params)`` of the guide that resolves to one beatlite function names only its
    parameters (the check of ``docs/architecture.md``, with the notebooks' ``bl.`` prefix dropped)."""
    pytest.importorskip("torch")
    from tests.test_docs_signatures import _index, wrong_calls

    text = GUIDE.read_text().replace("`bl.", "`").replace(" bl.", " ")
    checked, wrong = wrong_calls(text, _index())
    assert checked >= 4, checked
    assert not wrong, "docs/teaching.md names parameters the code does not have:\n" + "\n".join(wrong)
