"""Evaluate gesture models on whole test takes: the results table of BEAT Tables 4/5 and HA2G Tables 1/3/4.

Usage (skipped by the doctests: it loads every shipped checkpoint and runs for minutes):

>>> from beatlite.train.evaluation import evaluate_models      # doctest: +SKIP
>>> res = evaluate_models(["mean_pose", "camn_tiny", "s2g_tiny"])  # doctest: +SKIP
>>> print(res.to_markdown())                                     # doctest: +SKIP

Every model generates each test take whole (:func:`beatlite.train.generate`, seeded by
the first 4 ground-truth frames). All rows are then scored in one **common space**, the
TED-43 skeleton of HA2G (:mod:`beatlite.skeleton.ted`), so that Euler models (CaMN, the
baselines) and direction models (HA2G) are comparable:

- Euler rows: denormalised ``spine_neck_141`` degrees -> 228-channel BEAT motion (other
  joints at rest, root at the origin) -> forward kinematics -> ``beat_to_ted43`` -> 42 unit
  bone directions (exactly how :mod:`beatlite.data.windows` makes ``"dirvec"``).
- Direction rows: mean added back and renormalised.
- Positions for SRGR / BeatAlign / L1div: the directions chained with fixed bone lengths
  (those of the BEAT rest skeleton in TED-43, cm), root at the origin, for every row
  (ground truth included).

Metrics (``COLUMNS``):

=============  ====================================================================================
``FGD``        Fréchet distance of ``load_extractor("dirvec")`` features of 34-frame windows
               (stride 10, mean-subtracted directions) of all test takes vs the ground truth's
``SRGR``       paper variant on TED-43 positions, delta 10 cm, ground-truth semantic scores
``BeatAlign``  audio onsets vs joint-speed minima (positions, sigma 0.3 s), mean over takes
``BC``         HA2G Beat Consistency on the whole takes (sigma 0.1 s, MAAC of the train windows)
``Diversity``  HA2G Diversity: mean L1 distance of extractor features of 500 random window pairs
``L1div``      BEAT L1div on TED-43 positions (cm summed over 43 x 3 per frame)
=============  ====================================================================================

Two ground-truth rows: ``Ground truth`` (the dataset's TED-43 directions, the FGD reference,
FGD 0 by definition) and ``Ground truth (141 Euler channels)`` (only the channels the Euler
models predict, the rest at rest pose: the floor an Euler model can reach).
Nothing is cached outside ``build/`` (the window stores of :mod:`beatlite.data.store`).
The test takes, the generation of one model's row and its scoring are :mod:`beatlite.train.testset`; the
conversions to the common space are :mod:`beatlite.skeleton.ted`'s.

Taught in notebooks/05_camn.ipynb, section 6 (evaluation on the test split) and notebooks/07_benchmark.ipynb, section 1 (one evaluation, one common space).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from beatlite import paths
from beatlite.constants import FPS
from beatlite.data.normalize import Normalizers
from beatlite.metrics.scoring import ARROWS, METRICS, GroundTruth, describe
from beatlite.report import markdown_table, write_markdown_and_json
from beatlite.train import recipes
from beatlite.train.recipes import GROUND_TRUTH, GROUND_TRUTH_141  # the ground truth's rows
from beatlite.train.testset import (
    EvaluationSet,
    generate_takes,
    load_checkpoint_for,
    load_test_set,
    score_directions,
)

# torch stays lazy (imported by evaluate_models): the tables, COLUMNS and the papers' rows import without it.

COLUMNS: tuple[str, ...] = ("FGD", "SRGR", "BeatAlign", "BC", "Diversity", "L1div")
"""The results table's columns, in order: keys of :data:`beatlite.metrics.scoring.METRICS`
(each names its variant and parameters; the table caption lists them)."""

RECORD_COLUMNS: tuple[str, ...] = (
    *COLUMNS,
    "FGD (BEAT AE)",
    "FGD (reference)",
    "SRGR (reference)",
    "BeatAlign (reference)",
    "BC (ha2g)",
)
"""The metrics of the recorded seed table (``checkpoints/results_seeds.json``): :data:`COLUMNS`, then
the variants the papers' code computes (FGD in BEAT's Euler space and with scipy's square root, BEAT's
SRGR and BeatAlign on Euler angles, HA2G's BC on 34-frame clips) for the side-by-side tables of
notebooks 06-07."""


@dataclasses.dataclass
class ResultRow:
    """One row of the results table.

    Attributes
    ----------
    label : str
        Display name (e.g. ``"CaMN w/o audio"``).
    source : str
        Checkpoint name, ``"ground_truth"`` or ``"<given>"`` for a model passed in.
    representation : str
        ``"euler141"``, ``"dirvec126"`` or ``"ground_truth"``.
    metrics : dict of str -> float
        Values of :data:`COLUMNS` (NaN where undefined).
    seconds : float
        Wall time to generate all test takes (0 for ground-truth rows).
    fingerprint : str
        Data fingerprint stored in the checkpoint ("" when unknown).
    stale : bool
        The checkpoint was trained on other data than the evaluated corpus' train split
        (marked with a dagger in the table).
    """

    label: str
    source: str
    representation: str
    metrics: dict[str, float]
    seconds: float = 0.0
    fingerprint: str = ""
    stale: bool = False


@dataclasses.dataclass
class ModelResults:
    """Rows of :func:`evaluate_models` with the evaluation settings.

    Attributes
    ----------
    rows : list of ResultRow
    info : dict
        Split, takes, frames, window counts, extractor path (as :func:`beatlite.paths.shareable` writes it:
        relative to the repository, else the file's name), total seconds.

    Examples
    --------
    Two rows built by hand (:func:`evaluate_models` makes them from the test takes); a row is found by its
    label or its checkpoint name:

    >>> rows = [ResultRow("Ground truth", "ground_truth", "ground_truth", {"FGD": 0.0, "SRGR": 0.25}),
    ...         ResultRow("CaMN", "camn_tiny", "euler141", {"FGD": 12.5, "SRGR": math.nan}, seconds=1.5)]
    >>> results = ModelResults(rows, {"columns": ("FGD", "SRGR")})
    >>> results.get("camn_tiny").label, results.value("CaMN", "FGD"), results.columns
    ('CaMN', 12.5, ('FGD', 'SRGR'))
    >>> print(results.to_markdown(caption=False))
    | method | FGD ↓ | SRGR ↑ | gen. s |
    |---|---|---|---|
    | Ground truth | 0.00 | 0.250 |  |
    | CaMN | 12.50 | — | 1.50 |
    """

    rows: list[ResultRow]
    info: dict[str, Any]

    def get(self, label_or_source: str) -> ResultRow:
        """The row with this label or checkpoint name (``KeyError`` if none)."""
        for row in self.rows:
            if label_or_source in (row.label, row.source):
                return row
        raise KeyError(f"no row {label_or_source!r}; have {[r.label for r in self.rows]}")

    def value(self, row: str, metric: str) -> float:
        """``get(row).metrics[metric]``."""
        return self.get(row).metrics[metric]

    def to_markdown(self, columns: Sequence[str] | None = None, *, caption: bool = True) -> str:
        """A Markdown table: one row per model, its metrics, generation seconds.

        Parameters
        ----------
        columns : sequence of str, optional
            Metric keys to show, in order (default :attr:`columns`, all that were scored); the
            header names the variant (``"SRGR (reference) ↑"``). A key a row was not scored with
            shows as ``—``.
        caption : bool
            Append the variant and parameters of every column.

        Returns
        -------
        str

        Examples
        --------
        >>> res = ModelResults([ResultRow("A", "a", "ground_truth", {"SRGR": 0.25, "BC": math.nan})], {})
        >>> print(res.to_markdown(["SRGR", "BC"], caption=False))
        | method | SRGR ↑ | BC ↑ | gen. s |
        |---|---|---|---|
        | A | 0.250 | — |  |
        """
        columns = self.columns if columns is None else tuple(columns)
        unknown = [key for key in columns if key not in METRICS]
        if unknown:
            raise ValueError(f"unknown metric keys {unknown}; known: {sorted(METRICS)}")
        rows = []
        for row in self.rows:
            cells = [row.label + (" †" if row.stale else "")]
            cells += [fmt_metric(row.metrics.get(key, math.nan), key) for key in columns]
            cells.append(f"{row.seconds:.2f}" if row.representation != "ground_truth" else "")
            rows.append(cells)
        text = markdown_table(["method", *column_headers(columns), "gen. s"], rows)
        if any(row.stale for row in self.rows):
            text += "\n\n† trained on another version of the data than the one evaluated: retrain it."
        return text + ("\n\n" + describe(columns) if caption else "")

    @property
    def columns(self) -> tuple[str, ...]:
        """The metric keys of the table, in order (:data:`COLUMNS` unless chosen otherwise)."""
        return tuple(self.info.get("columns", COLUMNS))

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly dict: ``{"columns", "rows": [...], "info"}`` (NaN written as None; a row's ``source``
        path as :func:`beatlite.paths.shareable` writes it)."""
        return {
            "columns": [
                {"name": key, "higher_is_better": METRICS[key].higher_is_better} for key in self.columns
            ],
            "rows": [
                {
                    **dataclasses.asdict(r),
                    "source": paths.shareable(r.source),
                    "metrics": {k: (None if not math.isfinite(v) else v) for k, v in r.metrics.items()},
                }
                for r in self.rows
            ],
            "info": self.info,
        }


def column_headers(keys: Sequence[str]) -> list[str]:
    """``"FGD ↓"``, ``"SRGR ↑"``, ``"Jerk (GENEA)"``: each metric key with the arrow of its better direction
    (none for a descriptive metric, ``higher_is_better=None``).

    Examples
    --------
    >>> column_headers(["FGD", "SRGR", "Jerk (GENEA)"])
    ['FGD ↓', 'SRGR ↑', 'Jerk (GENEA)']
    """
    return [key + ARROWS[METRICS[key].higher_is_better] for key in keys]


def fmt_metric(v: float, key: str) -> str:
    """``v`` as printed in the results tables: 2 decimals for FGD/Diversity/L1div (1 from 100 on), 3 for the
    rest; ``—`` for NaN or infinity.

    Examples
    --------
    >>> fmt_metric(12.3456, "FGD"), fmt_metric(123.456, "FGD"), fmt_metric(0.23456, "SRGR"), fmt_metric(math.nan, "BC")
    ('12.35', '123.5', '0.235', '—')
    """
    if not math.isfinite(v):
        return "—"
    if METRICS[key].name in ("FGD", "Diversity", "L1div"):
        return f"{v:.2f}" if abs(v) < 100 else f"{v:.1f}"
    return f"{v:.3f}"


def _as_entries(models: Sequence[Any] | None) -> list[tuple[str, str, Any, Normalizers | None]]:
    """Normalise ``models`` to (label, source, model or None, normalizers) entries."""
    if models is None:
        models = [name for name in recipes.RECIPES if (paths.checkpoints_dir() / f"{name}.pt").is_file()]
    entries = []
    for item in models:
        if isinstance(item, str | Path):
            name = Path(item).stem if str(item).endswith(".pt") else str(item)
            entries.append((recipes.label_of(name), str(item), None, None))
        elif isinstance(item, tuple) and len(item) in (2, 3):
            norms = item[2] if len(item) == 3 else None
            if norms is not None and not isinstance(norms, Normalizers):
                raise TypeError(
                    f"the third entry of {item[0]!r} must be Normalizers, got {type(norms).__name__}"
                )
            entries.append((str(item[0]), "<given>", item[1], norms))
        else:
            raise TypeError(
                "models entries must be checkpoint names/paths or (label, model[, normalizers]) tuples, "
                f"got {type(item).__name__}"
            )
    return entries


def evaluate_models(
    models: Sequence[Any] | None = None,
    *,
    test: EvaluationSet | None = None,
    extractor: Any = None,
    ground_truth: bool = True,
    seed: int = 0,
    progress: bool = False,
    columns: Sequence[str] = COLUMNS,
    euler_extractor: Any = None,
) -> ModelResults:
    """Generate every test take with each model and score all of them in the TED-43 space.

    Parameters
    ----------
    models : sequence, optional
        Checkpoint names (``"camn_tiny"``, looked up in ``checkpoints/``) or paths, and/or
        ``(label, model)`` / ``(label, model, normalizers)`` tuples for models trained in a notebook
        (``normalizers``: the :class:`~beatlite.data.normalize.Normalizers` they were trained with;
        default the test set's). Default: every checkpoint of :data:`~beatlite.train.recipes.RECIPES`
        found in ``checkpoints/``, in that order.
    test : EvaluationSet, optional
        Default :func:`~beatlite.train.testset.load_test_set` (``data_samples/`` test split).
    extractor : callable, optional
        (N, 34, 126) -> (N, F) features; default ``load_extractor("dirvec")``.
    ground_truth : bool
        Add the two ground-truth rows first.
    seed : int
        Seed of the Diversity pairing.
    progress : bool
        Print one line per row.
    columns : sequence of str
        Metric keys of :data:`beatlite.metrics.scoring.METRICS` to score (default :data:`COLUMNS`; e.g.
        the reference variants ``"SRGR (reference)"``, ``"BC (ha2g)"`` for a like-for-like table).
    euler_extractor : callable, optional
        (N, 34, 141) -> (N, F) features of z-scored Euler windows for ``"FGD (BEAT AE)"``; default
        ``load_extractor("pose")``, loaded only when that column is asked for (as ``load_extractor("rot6d")`` for
        ``"FGD (rot6d)"``).

    Returns
    -------
    ModelResults
    """
    import torch

    from beatlite.metrics.extractor import load_extractor

    unknown = [key for key in columns if key not in METRICS]
    if unknown:
        raise ValueError(f"unknown metric keys {unknown}; known: {sorted(METRICS)}")
    start = time.perf_counter()
    torch.set_num_threads(paths.n_threads())
    entries = _as_entries(models)
    test = load_test_set() if test is None else test
    extractor = load_extractor("dirvec") if extractor is None else extractor
    euler_ae = None
    if "FGD (BEAT AE)" in columns:
        euler_ae = load_extractor("pose") if euler_extractor is None else euler_extractor
    rot6d_ae = load_extractor("rot6d") if "FGD (rot6d)" in columns else None
    truth = test.ground_truth(extractor, euler_ae, rot6d_ae)
    scoring = {"columns": columns, "seed": seed, "euler_extractor": euler_ae, "rot6d_extractor": rot6d_ae}
    rows: list[ResultRow] = []
    if ground_truth:
        for label, dirs in ((GROUND_TRUTH, test.gt_directions), (GROUND_TRUTH_141, test.gt_directions_141)):
            metrics = score_directions(dirs, test, extractor, truth, euler=test.gt_euler, **scoring)
            rows.append(ResultRow(label, "ground_truth", "ground_truth", metrics))
    for label, source, model, norms in entries:
        rows.append(_model_row(label, source, model, norms, test, extractor, truth, scoring))
        if progress:
            values = ", ".join(f"{k} {v:.4g}" for k, v in rows[-1].metrics.items())
            print(f"{label}: {values} ({rows[-1].seconds:.1f} s)", flush=True)
    info = {
        "split": test.split,
        "takes": list(test.takes),
        "frames": test.n_frames,
        "windows": int(len(truth.takes.features)),
        "fps": FPS,
        "extractor": paths.shareable(getattr(extractor, "meta", {}).get("path", type(extractor).__name__)),
        "common_space": "TED-43 unit bone directions; positions from BEAT rest-pose bone lengths, root at origin",
        "columns": {key: METRICS[key].describe for key in columns},
        "data_fingerprint": test.fingerprint,
        "seconds": round(time.perf_counter() - start, 2),
    }
    return ModelResults(rows, info)


def _model_row(
    label: str,
    source: str,
    model: Any,
    norms: Normalizers | None,
    test: EvaluationSet,
    extractor: Any,
    truth: GroundTruth,
    scoring: dict[str, Any],
) -> ResultRow:
    """Load (when ``model`` is None), generate and score one model's row (``scoring``: keywords of
    :func:`score_directions`)."""
    import torch

    fingerprint, stale = "", False
    if model is None:
        model, norms, fingerprint, stale = load_checkpoint_for(source, test)
    t0 = time.perf_counter()
    with torch.no_grad():
        dirs, euler = generate_takes(model, test, norms)
    seconds = time.perf_counter() - t0
    metrics = score_directions(dirs, test, extractor, truth, euler=euler, **scoring)
    return ResultRow(label, source, model.representation, metrics, seconds, fingerprint, stale)


def write_results(results: ModelResults, stem: str | Path | None = None) -> tuple[Path, Path]:
    """Write ``<stem>.md`` and ``<stem>.json`` atomically (default ``build/results_models``).

    The Markdown page states the evaluation from ``results.info`` (``split``, ``takes``, ``frames``, ``fps``,
    ``windows``, ``common_space``, ``extractor``, ``seconds``: what :func:`evaluate_models` records) above
    :meth:`ModelResults.to_markdown`; the JSON is :meth:`ModelResults.to_dict` (NaN as null).

    Returns
    -------
    (Path, Path)
        The ``.md`` and ``.json`` files.

    Examples
    --------
    >>> import json, tempfile
    >>> info = {"split": "test", "takes": ["a", "b"], "frames": 300, "fps": 15, "windows": 24,
    ...         "common_space": "TED-43", "extractor": "fgd_dirvec.pt", "seconds": 3.0, "columns": ("FGD", "SRGR")}
    >>> results = ModelResults([ResultRow("CaMN", "camn_tiny", "euler141", {"FGD": 12.5, "SRGR": math.nan})], info)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     md, js = write_results(results, Path(tmp) / "results")
    ...     print(md.name, js.name, json.loads(js.read_text())["rows"][0]["metrics"])
    ...     print(md.read_text().splitlines()[2])
    results.md results.json {'FGD': 12.5, 'SRGR': None}
    2 takes, 300 frames at 15 fps, 24 FGD windows (34 frames, stride 10). Common space: TED-43. FGD extractor: `fgd_dirvec.pt`.
    """
    stem = Path(stem) if stem is not None else paths.build_dir() / "results_models"
    info = results.info
    text = (
        f"# Gesture models on the `{info['split']}` split\n\n"
        f"{len(info['takes'])} takes, {info['frames']} frames at {info['fps']} fps, {info['windows']} FGD windows "
        f"(34 frames, stride 10). Common space: {info['common_space']}. FGD extractor: `{info['extractor']}`.\n\n"
        + results.to_markdown()
        + f"\n\nEvaluation time: {info['seconds']:.1f} s.\n"
    )
    return write_markdown_and_json(stem, text, results.to_dict())


# ------------------------------------------------------------------------------------ the papers' rows
#: BEAT (ECCV 2022) Table 4, on BEAT's 4-speaker English data: method -> metric -> value. Computed
#: with BEAT's code: FGD of its own autoencoder on 141 Euler channels, SRGR and BeatAlign on Euler
#: angles (our keys ``"SRGR (reference)"`` and ``"BeatAlign (reference)"``).
PAPER_BEAT_TABLE4: dict[str, dict[str, float]] = {
    "Seq2Seq": {"FGD": 261.3, "SRGR": 0.173, "BeatAlign": 0.729},
    "S2G": {"FGD": 256.7, "SRGR": 0.092, "BeatAlign": 0.751},
    "A2G": {"FGD": 223.8, "SRGR": 0.097, "BeatAlign": 0.766},
    "MultiContext": {"FGD": 176.2, "SRGR": 0.196, "BeatAlign": 0.776},
    "CaMN": {"FGD": 123.7, "SRGR": 0.239, "BeatAlign": 0.783},
}

#: BEAT Table 5 (ablations of CaMN), same metrics: row of the paper -> metric -> value.
PAPER_BEAT_TABLE5: dict[str, dict[str, float]] = {
    "full cascaded": {"FGD": 123.7, "SRGR": 0.239, "BeatAlign": 0.783},
    "w/o cascaded": {"FGD": 137.2, "SRGR": 0.207, "BeatAlign": 0.776},
    "w/o text": {"FGD": 149.4, "SRGR": 0.171, "BeatAlign": 0.781},
    "w/o audio": {"FGD": 155.7, "SRGR": 0.225, "BeatAlign": 0.733},
    "w/o speaker ID": {"FGD": 159.1, "SRGR": 0.207, "BeatAlign": 0.774},
    "w/o face": {"FGD": 163.3, "SRGR": 0.217, "BeatAlign": 0.767},
    "w/o emotion": {"FGD": 151.7, "SRGR": 0.231, "BeatAlign": 0.775},
    "w/o semantic": {"FGD": 151.8, "SRGR": 0.194, "BeatAlign": 0.786},
}

#: HA2G (CVPR 2022) Table 1, TED-Expressive columns: FGD and Diversity of HA2G's own extractor, BC
#: with HA2G's code on 34-frame clips (our key ``"BC (ha2g)"``).
PAPER_HA2G_TABLE1: dict[str, dict[str, float]] = {
    "Ground Truth": {"FGD": 0.0, "BC": 0.723, "Diversity": 175.231},
    "Attention Seq2Seq": {"FGD": 54.920, "BC": 0.155, "Diversity": 122.693},
    "Speech2Gesture": {"FGD": 54.650, "BC": 0.714, "Diversity": 142.489},
    "Joint Embedding": {"FGD": 64.555, "BC": 0.131, "Diversity": 120.627},
    "Trimodal": {"FGD": 12.613, "BC": 0.592, "Diversity": 154.088},
    "HA2G": {"FGD": 5.306, "BC": 0.715, "Diversity": 173.899},
}

#: HA2G Tables 3 (audio learner) and 4 (pose inferer), TED-Expressive, same metrics as Table 1.
PAPER_HA2G_ABLATIONS: dict[str, dict[str, float]] = {
    "f_a^low only (T3)": {"FGD": 6.588, "BC": 0.704, "Diversity": 171.482},
    "f_a^mid only (T3)": {"FGD": 7.212, "BC": 0.682, "Diversity": 168.223},
    "f_a^high only (T3)": {"FGD": 7.421, "BC": 0.661, "Diversity": 165.741},
    "w/o high-level negatives (T3)": {"FGD": 7.982, "BC": 0.652, "Diversity": 163.649},
    "w/o low/mid-level negatives (T3)": {"FGD": 6.998, "BC": 0.701, "Diversity": 169.021},
    "w/o text (T3)": {"FGD": 9.228, "BC": 0.619, "Diversity": 158.236},
    "HA2G-ASR (T3)": {"FGD": 5.319, "BC": 0.716, "Diversity": 173.058},
    "Holistic (T4)": {"FGD": 11.989, "BC": 0.594, "Diversity": 156.079},
    "w/o hand hierarchy (T4)": {"FGD": 10.832, "BC": 0.606, "Diversity": 158.823},
    "w/o body hierarchy (T4)": {"FGD": 5.882, "BC": 0.709, "Diversity": 173.066},
    "Same audio f_a^h (T4)": {"FGD": 6.801, "BC": 0.701, "Diversity": 170.085},
    "w/o L_phy (T4)": {"FGD": 5.907, "BC": 0.708, "Diversity": 172.651},
    "HA2G Full": {"FGD": 5.306, "BC": 0.715, "Diversity": 173.899},
}


PAPER_TABLES: dict[tuple[str, str], dict[str, dict[str, float]]] = {
    ("BEAT", "Table 4"): PAPER_BEAT_TABLE4,
    ("BEAT", "Table 5"): PAPER_BEAT_TABLE5,
    ("HA2G", "Table 1"): PAPER_HA2G_TABLE1,
    ("HA2G", "Table 3"): PAPER_HA2G_ABLATIONS,
    ("HA2G", "Table 4"): PAPER_HA2G_ABLATIONS,
}
"""(paper, table) of a :class:`~beatlite.train.recipes.PaperRow` -> the published rows above."""


def paper_table(rows: Mapping[str, Mapping[str, float]], *, digits: int = 3) -> str:
    """A Markdown table of a paper's published rows (one of the ``PAPER_*`` dicts above).

    Examples
    --------
    >>> print(paper_table({"CaMN": {"FGD": 123.7, "SRGR": 0.239}}, digits=1))
    | method | FGD | SRGR |
    |---|---|---|
    | CaMN | 123.7 | 0.2 |
    """
    keys = list(dict.fromkeys(k for values in rows.values() for k in values))
    return markdown_table(
        ["method", *keys],
        [[m, *(float(v.get(k, math.nan)) for k in keys)] for m, v in rows.items()],
        digits=digits,
    )
