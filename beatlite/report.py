"""Tables and figures that the notebooks hand to the main job's ``build/results.md``.

A notebook calls :func:`save_table` for every table it reproduces; ``make run``
collects ``build/tables/*.md`` into ``build/results.md`` in notebook order.

Taught in notebooks/00_setup_and_tour.ipynb, section 5 (the two commands: what ``make run`` writes).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np

from beatlite.paths import build_dir


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[object]], *, digits: int = 3) -> str:
    """A Markdown table: the one way beatlite writes tables (never hand-built ``|---|`` strings).

    Parameters
    ----------
    header : sequence of str
        Column titles.
    rows : iterable of sequences
        Cells; floats are printed with ``digits`` decimals, NaN as ``—``, everything else with ``str``.
    digits : int
        Decimals of float cells.

    Examples
    --------
    >>> print(markdown_table(["model", "FGD"], [["CaMN", 3.1234], ["Mean pose", float("nan")]], digits=2))
    | model | FGD |
    |---|---|
    | CaMN | 3.12 |
    | Mean pose | — |
    """
    header = [str(h) for h in header]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for i, row in enumerate(rows):
        cells = [_cell(c, digits) for c in row]
        if len(cells) != len(header):
            raise ValueError(f"markdown_table: row {i + 1} has {len(cells)} cells for {len(header)} columns")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _cell(value: object, digits: int) -> str:
    if isinstance(value, float | np.floating):
        return "—" if not np.isfinite(value) else f"{value:.{digits}f}"
    return str(value)


def tables_dir() -> Path:
    """Folder of the reproduced tables: ``<build>/tables``."""
    return build_dir() / "tables"


def figures_dir() -> Path:
    """Folder of the saved figures: ``<build>/figures``."""
    return build_dir() / "figures"


def save_table(name: str, markdown: str, *, title: str | None = None) -> Path:
    """Write a Markdown table to ``<build>/tables/<name>.md`` atomically.

    Parameters
    ----------
    name : str
        File stem, e.g. ``"02_table1"``; letters, digits, ``_`` and ``-`` only.
        The numeric prefix orders the tables in ``results.md``.
    markdown : str
        The table (any Markdown).
    title : str, optional
        A heading written above the table.

    Returns
    -------
    Path
        The file written.
    """
    if not name or not all(c.isalnum() or c in "_-" for c in name):
        raise ValueError(f"save_table: name must be letters, digits, '_' or '-', got {name!r}")
    out = tables_dir() / f"{name}.md"
    out.parent.mkdir(parents=True, exist_ok=True)
    text = (f"### {title}\n\n" if title else "") + markdown.rstrip() + "\n"
    fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=f".{name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.chmod(tmp, 0o644)  # mkstemp creates 0600; a table is an ordinary readable file
        os.replace(tmp, out)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return out


def write_markdown_and_json(stem: str | Path, markdown: str, data: object) -> tuple[Path, Path]:
    """Write ``<stem>.md`` (the text) and ``<stem>.json`` (``data``, indented, sorted keys) atomically.

    Returns
    -------
    (Path, Path)
        The two files written (parent folders are created).
    """
    import json

    from beatlite.io.atomic import atomic_write

    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    md, js = stem.with_suffix(".md"), stem.with_suffix(".json")
    with atomic_write(md, "w") as fh:
        fh.write(markdown)
    with atomic_write(js, "w") as fh:
        json.dump(data, fh, indent=2, sort_keys=True)
    return md, js
