"""Tables and figures that the notebooks hand to the main job's ``build/results.md``.

A notebook calls :func:`save_table` for every table it reproduces; ``make run``
collects ``build/tables/*.md`` into ``build/results.md`` in notebook order.

Sentences that compare recorded numbers are rendered from the seed record by :func:`claim` (and
:func:`claim_close`), so that a retraining cannot leave them stale.

Taught in notebooks/00_setup_and_tour.ipynb, section 5 (the two commands: what ``make run`` writes).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

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
    """Folder of the reproduced tables: ``<build>/tables`` (:func:`beatlite.paths.build_dir`).

    Examples
    --------
    >>> tables_dir() == build_dir() / "tables"
    True
    """
    return build_dir() / "tables"


def figures_dir() -> Path:
    """Folder of the saved figures: ``<build>/figures`` (:func:`beatlite.paths.build_dir`).

    Examples
    --------
    >>> figures_dir() == build_dir() / "figures"
    True
    """
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

    Raises
    ------
    ValueError
        ``name`` is empty or has another character (a ``/`` or ``..`` could write outside the folder).

    Examples
    --------
    A table written under a temporary build folder (``$BEATLITE_BUILD``) and read back:

    >>> import os, tempfile
    >>> from unittest import mock
    >>> with tempfile.TemporaryDirectory() as tmp, mock.patch.dict(os.environ, {"BEATLITE_BUILD": tmp}):
    ...     path = save_table("02_table1", markdown_table(["speaker", "minutes"], [["scott", 1.5]]), title="Table 1")
    ...     print(path.relative_to(tmp).as_posix())
    ...     print(path.read_text(), end="")
    tables/02_table1.md
    ### Table 1
    <BLANKLINE>
    | speaker | minutes |
    |---|---|
    | scott | 1.500 |
    """
    if not name or not all(c.isalnum() or c in "_-" for c in name):
        raise ValueError(f"save_table: name must be letters, digits, '_' or '-', got {name!r}")
    from beatlite.io.atomic import atomic_write

    out = tables_dir() / f"{name}.md"
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(out) as fh:  # (the project's one atomic writer: the umask's mode, stale temps removed)
        fh.write((f"### {title}\n\n" if title else "") + markdown.rstrip() + "\n")
    return out


def write_markdown_and_json(stem: str | Path, markdown: str, data: object) -> tuple[Path, Path]:
    """Write ``<stem>.md`` (the text) and ``<stem>.json`` (``data``, indented, sorted keys) atomically.

    Parameters
    ----------
    stem : str or Path
        The files' path without suffix; the suffixes are appended, so a dot in it stays
        (``"build/seeds_v1.2"`` gives ``seeds_v1.2.md``, as ``python -m beatlite.train seeds --out`` reads it back).
    markdown : str
        The text, written as given.
    data : JSON-serialisable object

    Returns
    -------
    (Path, Path)
        The two files written (parent folders are created).

    Examples
    --------
    The JSON file reads back as ``data``:

    >>> import json, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     md, js = write_markdown_and_json(Path(tmp) / "runs" / "seeds_v1.2", "# Seeds", {"seeds": [1, 2]})
    ...     md.name, js.name, json.loads(js.read_text()) == {"seeds": [1, 2]}
    ('seeds_v1.2.md', 'seeds_v1.2.json', True)
    """
    import json

    from beatlite.io.atomic import atomic_write

    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    md, js = stem.with_name(stem.name + ".md"), stem.with_name(stem.name + ".json")
    with atomic_write(md, "w") as fh:
        fh.write(markdown)
    with atomic_write(js, "w") as fh:
        json.dump(data, fh, indent=2, sort_keys=True)
    return md, js


VERDICTS: tuple[str, ...] = ("better", "worse", "indistinguishable", "unknown")
"""What :func:`claim` can conclude about one row against another."""


@dataclasses.dataclass(frozen=True)
class Claim:
    """One comparison of two rows of a seed record, as :func:`claim` reads it (``str`` is the sentence).

    Attributes
    ----------
    row, reference : str
        Row labels of the record (``row`` is compared with ``reference``).
    metric : str
        A key of :data:`beatlite.metrics.scoring.METRICS`.
    higher_is_better : bool
        The metric's direction.
    mean, reference_mean : float
        Means over the seeds, in the metric's units.
    delta : float
        ``mean - reference_mean`` in the metric's units.
    se : float
        Standard error of ``delta`` (Welch; a ground-truth row, recorded once, adds none); NaN without one.
    verdict : str
        One of :data:`VERDICTS`: ``"better"``/``"worse"`` when ``|delta| > 2 se``, in the metric's direction;
        ``"indistinguishable"`` when ``delta ± 2 se`` covers 0; ``"unknown"`` when ``se`` is NaN.
    seeds : (int, int)
        Finite values of each row (1 for a ground-truth row).
    against_data : bool
        ``reference`` is a row recorded once (the ground truth) and the metric has no perfect value (SRGR,
        BeatAlign, BC: the data's own value is the target, more is not closer to it): the sentence then says
        "above"/"below" rather than "better"/"worse" (the verdict keeps the metric's direction).
    """

    row: str
    reference: str
    metric: str
    higher_is_better: bool
    mean: float
    reference_mean: float
    delta: float
    se: float
    verdict: str
    seeds: tuple[int, int]
    against_data: bool = False

    @property
    def holds(self) -> bool:
        """Whether the difference exceeds two standard errors (``"better"`` or ``"worse"``)."""
        return self.verdict in ("better", "worse")

    def sentence(self) -> str:
        """The claim in words, with the numbers that support it (``str(claim)``)."""
        direction = "higher" if self.higher_is_better else "lower"
        decimals = _decimals(2 * self.se, self.metric)
        d, e = f"{abs(self.delta):.{decimals}f}", f"{2 * self.se:.{decimals}f}"
        a, b = _fmt(self.mean, self.metric), _fmt(self.reference_mean, self.metric)
        n, m = self.seeds
        if n == m:
            means = f"means {a} vs {b} over {n} seeds"
        else:  # a row recorded once is a ground-truth row: not a draw
            means = f"mean {a} over {n} seeds vs " + (f"{b} (one value)" if m == 1 else f"{b} over {m} seeds")
        if self.verdict in ("better", "worse") and self.against_data:
            side = "above" if self.delta > 0 else "below"
            return f"{self.row} is {side} {self.reference} on {self.metric} by {d} ± {e} (2 SE; {means})."
        if self.verdict in ("better", "worse"):
            return (
                f"{self.row} is {self.verdict} than {self.reference} on {self.metric} ({direction} is better) "
                f"by {d} ± {e} (2 SE; {abs(self.delta) / self.se:.1f} SE from 0; {means})."
            )
        if self.verdict == "indistinguishable":
            return (
                f"{self.row} and {self.reference} are indistinguishable on {self.metric}: "
                f"Δ {self.delta:+.{decimals}f} ± {e} covers 0 (2 SE; {means})."
            )
        return f"{self.row} vs {self.reference} on {self.metric}: {means}; no standard error (one seed)."

    __str__ = sentence


def claim(record: Any, row: str, reference: str, metric: str) -> Claim:
    """Compare two rows of a seed record on one metric against seed noise, as a sentence that cannot go stale.

    A notebook prints ``claim(...)`` instead of writing "X beats Y on FGD" by hand: the sentence is
    rendered from the record, so a retraining that changes the order changes the sentence. Prose that
    explains a claim sits beside a ``check`` cell asserting its :attr:`Claim.verdict`.

    Parameters
    ----------
    record : SeedResults
        :func:`beatlite.train.seeds.recorded_seed_results` (or any object with its ``values``: row label ->
        metric key -> list of per-seed values, NaN for a missing seed; a ground-truth row holds one value:
        it is not a draw, so it adds no variance).
    row, reference : str
        Row labels; ``row`` is the one said to be better or worse.
    metric : str
        A key of :data:`beatlite.metrics.scoring.METRICS` with a direction (``higher_is_better`` not None):
        ``"FGD"`` (lower is better), ``"SRGR"``, ``"BeatAlign"``, ``"BC"``, ``"BC (ha2g)"``, ...

    Returns
    -------
    Claim
        ``delta = mean(row) - mean(reference)`` in the metric's units, its standard error
        ``sqrt(sd_row² / n_row + sd_ref² / n_ref)`` (ddof 1, as :meth:`SeedResults.difference`; NaN where a
        row recorded per seed has fewer than 2 finite values), and the verdict: better/worse beyond
        2 standard errors, else indistinguishable. ``str`` of it is the sentence.

    Raises
    ------
    KeyError
        The record has no such row or metric.
    ValueError
        The metric is descriptive (no better direction).

    Examples
    --------
    >>> from beatlite.train.seeds import SeedResults
    >>> record = SeedResults({"Ground truth": {"FGD": [0.0]}, "A": {"FGD": [3.0, 3.4, 3.2]},
    ...                       "B": {"FGD": [4.0, 4.6, 4.3]}, "C": {"FGD": [3.1, 4.1, 2.9]}}, [1, 2, 3], {})
    >>> print(claim(record, "A", "B", "FGD"))
    A is better than B on FGD (lower is better) by 1.10 ± 0.42 (2 SE; 5.3 SE from 0; means 3.20 vs 4.30 over 3 seeds).
    >>> print(claim(record, "C", "A", "FGD"))
    C and A are indistinguishable on FGD: Δ +0.17 ± 0.78 covers 0 (2 SE; means 3.37 vs 3.20 over 3 seeds).
    >>> c = claim(record, "B", "Ground truth", "FGD")  # the ground truth is recorded once: B's spread only
    >>> c.verdict, round(c.delta, 2), round(2 * c.se, 2)
    ('worse', 4.3, 0.35)
    >>> print(c)
    B is worse than Ground truth on FGD (lower is better) by 4.30 ± 0.35 (2 SE; 24.8 SE from 0; mean 4.30 over 3 seeds vs 0.00 (one value)).

    Against the ground truth on a metric whose target is the data's own value (BeatAlign, BC, SRGR), a
    difference is "above"/"below", not "better"/"worse":

    >>> record.values["Ground truth"]["BC"], record.values["A"]["BC"] = [0.66], [0.77, 0.78, 0.76]
    >>> print(claim(record, "A", "Ground truth", "BC"))
    A is above Ground truth on BC by 0.110 ± 0.012 (2 SE; mean 0.770 over 3 seeds vs 0.660 (one value)).
    """
    from beatlite.metrics.scoring import METRICS

    if metric not in METRICS:
        raise ValueError(f"claim: metric must be one of {list(METRICS)}, got {metric!r}")
    higher = METRICS[metric].higher_is_better
    if higher is None:
        raise ValueError(f"claim: {metric!r} is descriptive: neither higher nor lower is better")
    a, var_a = _draws(record, row, metric)
    b, var_b = _draws(record, reference, metric)
    delta = float(np.mean(a) - np.mean(b)) if len(a) and len(b) else math.nan
    se = math.sqrt(var_a + var_b)
    if not (math.isfinite(se) and math.isfinite(delta)):
        verdict = "unknown"
    elif abs(delta) <= 2 * se:
        verdict = "indistinguishable"
    else:
        verdict = "better" if (delta > 0) == higher else "worse"
    mean_a = float(np.mean(a)) if len(a) else math.nan
    mean_b = float(np.mean(b)) if len(b) else math.nan
    against_data = len(record.values[reference][metric]) == 1 and METRICS[metric].perfect is None
    return Claim(
        row, reference, metric, higher, mean_a, mean_b, delta, se, verdict, (len(a), len(b)), against_data
    )


def claims(record: Any, pairs: Iterable[tuple[str, str]], metric: str) -> list[Claim]:
    """:func:`claim` of every ``(row, reference)`` pair on ``metric``, skipping rows the record lacks.

    Examples
    --------
    >>> from beatlite.train.seeds import SeedResults
    >>> record = SeedResults({"A": {"SRGR": [0.2, 0.21]}, "B": {"SRGR": [0.1, 0.11]}}, [1, 2], {})
    >>> [c.verdict for c in claims(record, [("A", "B"), ("B", "A"), ("A", "Z")], "SRGR")]
    ['better', 'worse']
    """
    return [claim(record, a, b, metric) for a, b in pairs if a in record.values and b in record.values]


@dataclasses.dataclass(frozen=True)
class Closeness:
    """Which rows of a seed record lie within a tolerance of a reference row (:func:`claim_close`).

    Attributes
    ----------
    reference, metric : str
    reference_mean : float
    within : float
        The tolerance, in the metric's units.
    near, far : dict str -> float
        Row label -> mean over seeds, for the rows with ``|mean - reference_mean| <= within`` and the others.
    """

    reference: str
    metric: str
    reference_mean: float
    within: float
    near: dict[str, float]
    far: dict[str, float]

    def sentence(self) -> str:
        """The grouping in words (``str(closeness)``)."""

        def listed(rows: dict[str, float]) -> str:
            return ", ".join(f"{k} ({_fmt(v, self.metric)})" for k, v in rows.items()) or "none"

        head = f"{self.metric} (mean over seeds) against {self.reference}'s {_fmt(self.reference_mean, self.metric)}"
        return f"{head}: within {self.within:g}: {listed(self.near)}; further: {listed(self.far)}."

    __str__ = sentence


def claim_close(record: Any, rows: Sequence[str], reference: str, metric: str, *, within: float) -> Closeness:
    """Split ``rows`` into those whose seed mean is within ``within`` of ``reference``'s and the others.

    For a sentence such as "every moving model's BeatAlign is close to the ground truth's": print this and
    assert in a ``check`` cell that :attr:`Closeness.far` holds exactly the rows the prose names.

    Parameters
    ----------
    record : SeedResults
        As :func:`claim`.
    rows : sequence of str
        Row labels, in the order listed (rows the record lacks are left out).
    reference : str
        The row they are compared with.
    metric : str
        A metric key of the record.
    within : float
        Tolerance in the metric's units (inclusive).

    Examples
    --------
    >>> from beatlite.train.seeds import SeedResults
    >>> record = SeedResults({"GT": {"BeatAlign": [0.92]}, "A": {"BeatAlign": [0.9, 0.92]},
    ...                       "B": {"BeatAlign": [0.6, 0.7]}}, [1, 2], {})
    >>> print(claim_close(record, ["A", "B"], "GT", "BeatAlign", within=0.05))
    BeatAlign (mean over seeds) against GT's 0.920: within 0.05: A (0.910); further: B (0.650).
    """
    ref, _ = _draws(record, reference, metric)
    ref_mean = float(np.mean(ref)) if len(ref) else math.nan
    means = {
        r: float(np.mean(v)) for r in rows if r in record.values and len(v := _draws(record, r, metric)[0])
    }
    near = {r: m for r, m in means.items() if abs(m - ref_mean) <= within}
    far = {r: m for r, m in means.items() if r not in near}
    return Closeness(reference, metric, ref_mean, float(within), near, far)


def _draws(record: Any, row: str, metric: str) -> tuple[np.ndarray, float]:
    """The finite per-seed values of ``row`` and the variance of their mean (0 for a row recorded once:
    a ground-truth row is not a draw; NaN for a per-seed row with fewer than 2 finite values)."""
    recorded = np.asarray(record.values[row][metric], float)
    v = recorded[np.isfinite(recorded)]
    if len(recorded) == 1:
        return v, 0.0
    return v, float(np.var(v, ddof=1) / len(v)) if len(v) > 1 else math.nan


def _fmt(value: float, metric: str) -> str:
    """A mean as the tables print it (:func:`beatlite.train.evaluation.fmt_metric`)."""
    from beatlite.train.evaluation import fmt_metric

    return fmt_metric(value, metric)


def _decimals(two_se: float, metric: str) -> int:
    """Decimals that show two significant digits of ``two_se`` (the tables' digits without one)."""
    if not math.isfinite(two_se) or two_se <= 0:
        return 2 if _fmt(1.0, metric) == "1.00" else 3
    return max(0, 1 - math.floor(math.log10(two_se)))
