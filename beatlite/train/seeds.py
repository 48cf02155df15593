"""The results table over several training seeds: mean ± standard deviation per model and metric.

Usage (skipped by the doctests: it trains models for minutes):

>>> from beatlite.train.seeds import train_seeds, evaluate_seeds    # doctest: +SKIP
>>> train_seeds(["camn_tiny", "s2g_tiny"], seeds=[2022, 2023], jobs=2)   # doctest: +SKIP
>>> table = evaluate_seeds(["camn_tiny", "s2g_tiny"], seeds=[2021, 2022, 2023])  # doctest: +SKIP
>>> print(table.to_markdown())                                       # doctest: +SKIP

One seed is one draw: on the 143 test windows of ``data_samples/`` the FGD of one model moves
by about ±1 between seeds, as much as the gap between some rows. A claim such as "CaMN beats
Trimodal on FGD" is therefore checked on the mean over seeds, against the spread.

Every seed ``s`` of a recipe is trained by :func:`beatlite.train.recipes.retrain` into
``build/seeds/<s>/<name>.pt`` (``python -m beatlite.train seeds``). The shipped checkpoint
``checkpoints/<name>.pt`` is a copy of the seed whose FGD is the median over the seeds
(:func:`median_seed`, :func:`ship_median_seeds`), not an arbitrary one; it stores its seed, and the recorded table names it
(``info["shipped"]``). Where ``build/seeds/<s>/`` lacks a checkpoint, the shipped one stands for its own
seed (a fresh clone has only those).

Taught in notebooks/07_benchmark.ipynb, section 2 (one run is one draw: the table over three seeds) and notebooks/05_camn.ipynb, section 7.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from beatlite import paths
from beatlite.io.atomic import atomic_write
from beatlite.io.errors import FormatError
from beatlite.metrics.scoring import METRICS, describe
from beatlite.models import build_model
from beatlite.report import markdown_table, write_markdown_and_json
from beatlite.train.evaluation import (
    COLUMNS,
    GROUND_TRUTH,
    GROUND_TRUTH_141,
    column_headers,
    evaluate_models,
    fmt_metric,
)
from beatlite.train.recipes import RECIPES, SEED, label_of, retrain_many
from beatlite.train.testset import load_test_set


def seeds_dir() -> Path:
    """``build/seeds`` (:func:`beatlite.paths.build_dir`, ``$BEATLITE_BUILD``): one folder per extra seed.

    Examples
    --------
    >>> seeds_dir().relative_to(paths.build_dir()).as_posix()
    'seeds'
    """

    return paths.build_dir() / "seeds"


def checkpoint_path(name: str, seed: int) -> Path:
    """Where the checkpoint of recipe ``name`` trained with ``seed`` lives.

    ``build/seeds/<seed>/<name>.pt``; when that file does not exist and the shipped
    ``checkpoints/<name>.pt`` was trained with ``seed``, the shipped one.

    Examples
    --------
    Seed 1 is not the shipped CaMN's (:func:`shipped_seed`), so its checkpoint is under ``build/seeds/1/``:

    >>> checkpoint_path("camn_tiny", 1).relative_to(paths.build_dir()).as_posix()
    'seeds/1/camn_tiny.pt'
    """

    path = seeds_dir() / str(seed) / f"{name}.pt"
    shipped = paths.checkpoints_dir() / f"{name}.pt"
    if not path.is_file() and shipped_seed(shipped) == seed:
        return shipped
    return path


def shipped_seed(path: str | Path) -> int | None:
    """The training seed stored in the checkpoint at ``path`` (None when there is no file or no seed).

    Examples
    --------
    The shipped CaMN is the copy of one seed of the recorded table, the one the record names:

    >>> seed = shipped_seed(paths.checkpoints_dir() / "camn_tiny.pt")
    >>> seed == recorded_shipped_seed("camn_tiny"), seed in recorded_seed_results().seeds
    (True, True)
    >>> print(shipped_seed(paths.checkpoints_dir() / "no_such_model.pt"))
    None
    """
    path = Path(path)
    if not path.is_file():
        return None
    stat = path.stat()
    return _stored_seed(str(path), stat.st_mtime_ns, stat.st_ino, stat.st_size)


@functools.lru_cache(maxsize=256)
def _stored_seed(path: str, mtime_ns: int, inode: int, size: int) -> int | None:  # the file's identity
    from beatlite.train.checkpoint import load_checkpoint

    seed = (load_checkpoint(path).get("train_config") or {}).get("seed")
    return None if seed is None else int(seed)


def median_seed(values: Sequence[float], seeds: Sequence[int]) -> int:
    """The seed of the median of the finite ``values``: the values ranked, equal ones in seed order, the
    middle one (the lower middle one of an even count).

    Examples
    --------
    >>> median_seed([3.1, 5.2, 4.0], [2021, 2022, 2023])
    2023
    >>> median_seed([3.0, float("nan"), 5.0, 4.5], [1, 2, 3, 4])
    4
    >>> median_seed([5.3, 4.1, float("nan")], [1, 2, 3])
    2
    """
    v = np.asarray(values, float)
    ok = np.flatnonzero(np.isfinite(v))
    if len(ok) == 0:
        raise ValueError(f"median_seed: no finite value among {list(values)}")
    ranked = ok[np.lexsort((ok, v[ok]))]  # by value, then by position: the lower median of an even count
    return int(seeds[int(ranked[(len(ranked) - 1) // 2])])


def ship_median_seeds(
    results: SeedResults, names: Sequence[str] | None = None, *, metric: str = "FGD"
) -> dict[str, int]:
    """Copy each recipe's median-seed checkpoint (:func:`median_seed` of ``metric``) to ``checkpoints/``.

    Every seed's checkpoint must be in ``build/seeds/<seed>/`` (or be the shipped one). The copies are
    written atomically; ``results.info["shipped"]`` (row label -> seed) records the choice.

    Returns
    -------
    dict recipe name -> shipped seed
    """

    names = [n for n in RECIPES if label_of(n) in results.values] if names is None else list(names)
    chosen = {}
    for name in names:
        seed = median_seed(results.values[label_of(name)][metric], results.seeds)
        src, dst = checkpoint_path(name, seed), paths.checkpoints_dir() / f"{name}.pt"
        if src.resolve() != dst.resolve():
            kept = shipped_seed(dst)  # the replaced checkpoint stays its seed's copy in build/seeds/
            if kept is not None and not (seeds_dir() / str(kept) / dst.name).is_file():
                _copy(dst, seeds_dir() / str(kept) / dst.name)
            _copy(src, dst)
        chosen[name] = seed
    results.info.setdefault("shipped", {}).update({label_of(n): seed for n, seed in chosen.items()})
    if "checkpoints" in results.info:  # the files each seed's values came from, after the copies
        results.info["checkpoints"].update({n: _seed_files(n, results.seeds) for n in chosen})
    return chosen


def _existing_checkpoint(name: str, seed: int) -> Path | None:
    """:func:`checkpoint_path` of ``(name, seed)`` when that file exists, else None."""
    path = checkpoint_path(name, seed)
    return path if path.is_file() else None


def _seed_files(name: str, seeds: Sequence[int]) -> list[str]:
    """The checkpoint files of recipe ``name`` for those of ``seeds`` that have one (:func:`checkpoint_path`), as
    :func:`beatlite.paths.shareable` writes them (``"build/seeds/2022/camn_tiny.pt"``, ``"checkpoints/camn_tiny.pt"``)."""
    return [paths.shareable(path) for s in seeds if (path := _existing_checkpoint(name, s)) is not None]


def _current(name: str, seed: int, verbose: bool) -> bool:
    """Whether the checkpoint of (name, seed) exists and was trained by today's recipe."""
    from beatlite.train.checkpoint import load_checkpoint

    path = checkpoint_path(name, seed)
    if not path.is_file():
        return False
    why = recipe_mismatch(name, load_checkpoint(path))
    if why is not None and verbose:
        print(f"{path}: {why}: retraining", flush=True)
    return why is None


def recipe_mismatch(name: str, checkpoint: Mapping[str, Any]) -> str | None:
    """Why ``checkpoint`` (a loaded checkpoint dict) was not trained by today's recipe ``name``, or None.

    Compares the harness settings stored in its ``"train_config"`` (epochs, batch size, learning
    rate and schedule; float32, deterministic: a checkpoint trained with ``amp`` or
    ``deterministic=False`` is not the recipe's) and its model config with what :data:`~beatlite.train.recipes.RECIPES`
    builds now (same vocabulary size and seed), so a seed table is never filled with checkpoints of
    an older recipe. Code changes that leave both unchanged are not seen here (the test
    ``test_the_first_training_steps_are_the_recorded_ones`` in ``tests/test_train_recipes.py`` sees them): retrain with
    ``force`` (``seeds --force``).

    Examples
    --------
    The shipped S2G-style checkpoint is today's recipe; the same file claiming 3 epochs is not:

    >>> from beatlite.train.checkpoint import load_checkpoint
    >>> checkpoint = load_checkpoint(paths.checkpoints_dir() / "s2g_tiny.pt")
    >>> print(recipe_mismatch("s2g_tiny", checkpoint))
    None
    >>> checkpoint["train_config"]["epochs"] = 3
    >>> recipe_mismatch("s2g_tiny", checkpoint)
    'trained with epochs=3; the recipe says epochs=40'
    """

    recipe = RECIPES[name]
    stored = checkpoint.get("train_config") or {}
    want = {
        "epochs": recipe.epochs,
        "batch_size": recipe.batch_size,
        "lr": recipe.lr,
        "lr_schedule": recipe.lr_schedule,
        "amp": False,
        "deterministic": True,
    }
    missing = {"lr_schedule": "constant", "amp": False, "deterministic": True}  # older checkpoints' defaults
    have = {key: stored.get(key, missing.get(key)) for key in want}
    if have != want:
        diff = {key: (have[key], want[key]) for key in want if have[key] != want[key]}
        return (
            f"trained with {', '.join(f'{k}={a!r}' for k, (a, _) in diff.items())}; the recipe says "
            + ", ".join(f"{k}={b!r}" for k, (_, b) in diff.items())
        )
    model = dict(checkpoint.get("model") or {})
    kw = dict(recipe.overrides)
    kw.update({key: model[key] for key in ("vocab_size", "seed") if key in model})
    built = build_model(recipe.model, preset="tiny", **kw)
    expected = built.to_config()
    try:  # the config the checkpoint loads as: fields it predates take their defaults, as load_model does
        model = type(built).from_config(model).to_config() if model else model
    except TypeError as error:  # a field that no longer exists
        return f"its model config does not load: {error}"
    if expected != model:
        fields = sorted(k for k in set(expected) | set(model) if expected.get(k) != model.get(k))
        return f"its model config differs from the recipe's in {fields}"
    return None


def _copy(src: Path, dst: Path) -> None:
    """Copy a file atomically (the folder of ``dst`` created)."""
    import shutil

    dst.parent.mkdir(parents=True, exist_ok=True)
    with open(src, "rb") as fin, atomic_write(dst, "wb") as fout:
        shutil.copyfileobj(fin, fout)


def train_seeds(
    names: Sequence[str] | None = None,
    seeds: Sequence[int] = (2022, 2023),
    *,
    jobs: int = 1,
    force: bool = False,
    verbose: bool = True,
) -> dict[tuple[str, int], float]:
    """Train every recipe of ``names`` with every seed of ``seeds`` that has no checkpoint yet.

    Parameters
    ----------
    names : sequence of str, optional
        Keys of :data:`beatlite.train.recipes.RECIPES` (default all).
    seeds : sequence of int
        Each is trained into ``build/seeds/<seed>/`` unless :func:`checkpoint_path` already has a
        current checkpoint (the shipped one counts for its own seed).
    jobs : int
        Training processes run at once, one torch thread each (2 on a 2-core machine that
        does nothing else; 1 otherwise: two busy processes on two cores slow each other).
    force : bool
        Retrain checkpoints that exist. Without it, an existing checkpoint is kept only when
        :func:`recipe_mismatch` finds nothing (one of an older recipe is retrained).
    verbose : bool
        Print one line per finished checkpoint.

    Returns
    -------
    dict (name, seed) -> seconds of training, for the checkpoints trained now.
    """
    names = list(RECIPES) if names is None else list(names)
    unknown = sorted(set(names) - set(RECIPES))
    if unknown:
        raise ValueError(f"unknown checkpoint name(s) {unknown}; known: {sorted(RECIPES)}")
    todo = [
        (name, int(seed), seeds_dir() / str(int(seed)))
        for seed in seeds
        for name in names
        if force or not _current(name, int(seed), verbose)
    ]

    def report(name: str, seed: int, seconds: float) -> None:
        if verbose:
            print(f"seed {seed} {name}: {seconds:.1f} s", flush=True)

    return retrain_many(todo, jobs=jobs, on_done=report)


@dataclasses.dataclass
class SeedResults:
    """Per-seed metric values of several models and their mean ± sd.

    Attributes
    ----------
    values : dict
        Row label -> metric -> list of values, one per seed of ``seeds`` in order, NaN where that
        seed's checkpoint was missing (ground-truth rows: one value, they do not depend on a seed).
    seeds : list of int
    info : dict
        Evaluation settings of :func:`beatlite.train.evaluate_models`, plus the checkpoint paths.

    Examples
    --------
    Three seeds of two rows: means 2 and 3, sample sd 1 each, so the difference 1 has the standard error
    ``sqrt(1/3 + 1/3) = 0.8165``:

    >>> table = SeedResults({"Full": {"FGD": [1.0, 2.0, 3.0]}, "A": {"FGD": [2.0, 3.0, 4.0]}}, [1, 2, 3], {})
    >>> table.mean("A", "FGD"), table.sd("A", "FGD"), table.count("A")
    (3.0, 1.0, 3)
    >>> delta, se = table.difference("A", "Full", "FGD")
    >>> delta, round(se, 4)
    (1.0, 0.8165)
    >>> print(table.to_markdown(columns=("FGD",)))
    | method | FGD ↓ | seeds | shipped |
    |---|---|---|---|
    | Full | 2.00 ± 1.00 | 3 |  |
    | A | 3.00 ± 1.00 | 3 |  |
    """

    values: dict[str, dict[str, list[float]]]
    seeds: list[int]
    info: dict[str, Any]

    def mean(self, row: str, metric: str) -> float:
        """Mean over seeds (NaN seeds ignored)."""
        v = np.asarray(self.values[row][metric], float)
        return float(np.nanmean(v)) if np.isfinite(v).any() else math.nan

    def count(self, row: str, metric: str = "FGD") -> int:
        """How many seeds have a (finite) value of ``metric`` in ``row``."""
        return int(np.isfinite(np.asarray(self.values[row][metric], float)).sum())

    def sd(self, row: str, metric: str) -> float:
        """Sample standard deviation over seeds (ddof 1; NaN with fewer than 2 finite values)."""
        v = np.asarray(self.values[row][metric], float)
        v = v[np.isfinite(v)]
        return float(np.std(v, ddof=1)) if len(v) > 1 else math.nan

    def difference(self, row: str, reference: str, metric: str) -> tuple[float, float]:
        """``mean(row) - mean(reference)`` and its standard error ``sqrt(sd_r²/n_r + sd_ref²/n_ref)`` (Welch).

        A difference larger than about two standard errors is unlikely to be seed noise; the
        standard error is NaN when either row has fewer than two seeds.
        """
        a = np.asarray(self.values[row][metric], float)
        b = np.asarray(self.values[reference][metric], float)
        a, b = a[np.isfinite(a)], b[np.isfinite(b)]
        delta = self.mean(row, metric) - self.mean(reference, metric)
        if len(a) < 2 or len(b) < 2:
            return delta, math.nan
        return delta, float(math.sqrt(np.var(a, ddof=1) / len(a) + np.var(b, ddof=1) / len(b)))

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SeedResults:
        """Inverse of :meth:`to_dict` (None read back as NaN)."""
        values = {
            row: {m: [math.nan if v is None else float(v) for v in d["values"]] for m, d in metrics.items()}
            for row, metrics in data["rows"].items()
        }
        return cls(values, [int(s) for s in data["seeds"]], dict(data.get("info", {})))

    def merged(self, other: SeedResults) -> SeedResults:
        """This table with ``other``'s rows added or replacing these (``make seeds ONLY=NAME`` records NAME's
        rows into the shipped table without dropping the others); ``info["checkpoints"]`` / ``["shipped"]``
        are merged, the rest of ``info`` is ``other``'s.

        Raises
        ------
        ValueError
            The two tables are over different seeds.
        """
        if list(other.seeds) != list(self.seeds):
            raise ValueError(f"cannot merge a table over seeds {other.seeds} into one over {self.seeds}")
        info = {**self.info, **other.info}
        for key in ("checkpoints", "shipped"):
            info[key] = {**(self.info.get(key) or {}), **(other.info.get(key) or {})}
        return SeedResults({**self.values, **other.values}, list(self.seeds), info)

    def to_markdown(self, columns: Sequence[str] | None = None, rows: Sequence[str] | None = None) -> str:
        """A Markdown table of ``mean ± sd`` over seeds, the seed count and the shipped seed.

        ``columns``: metric keys (default :data:`~beatlite.train.evaluation.COLUMNS`); ``rows``: row
        labels in table order (default every row, ground truth first, then in recipe order).
        """

        columns = COLUMNS if columns is None else tuple(columns)
        if rows is None:
            order = [GROUND_TRUTH, GROUND_TRUTH_141, *(r.label for r in RECIPES.values())]
            rows = sorted(self.values, key=lambda r: order.index(r) if r in order else len(order))
        shipped = self.info.get("shipped") or {}
        body = [
            [
                row,
                *[self.cell(row, key) if key in self.values[row] else "" for key in columns],
                self.count(row, "FGD" if "FGD" in self.values[row] else next(iter(self.values[row]))),
                "" if shipped.get(row) is None else shipped[row],
            ]
            for row in rows
        ]
        return markdown_table(["method", *column_headers(columns), "seeds", "shipped"], body)

    def cell(self, row: str, metric: str) -> str:
        """``"mean ± sd"`` of one row and metric as the tables print it (``"mean"`` with one seed)."""

        mean, sd = self.mean(row, metric), self.sd(row, metric)
        return fmt_metric(mean, metric) + (" ± " + fmt_metric(sd, metric) if math.isfinite(sd) else "")

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly dict (NaN written as None)."""

        def clean(v: float) -> float | None:
            return v if math.isfinite(v) else None

        rows = {
            row: {
                m: {
                    "values": [clean(x) for x in vals],
                    "mean": clean(self.mean(row, m)),
                    "sd": clean(self.sd(row, m)),
                }
                for m, vals in metrics.items()
            }
            for row, metrics in self.values.items()
        }
        return {"seeds": self.seeds, "rows": rows, "info": self.info}


@dataclasses.dataclass(frozen=True)
class Effect:
    """How one row differs from a reference row on one metric, over seeds (:func:`compare_rows`).

    Attributes
    ----------
    variant, metric : str
    delta : float
        ``mean(variant) - mean(full)`` in the metric's units.
    se : float
        Its standard error (:meth:`SeedResults.difference`).
    verdict : str
        ``"worse"`` or ``"better"`` than the full model when ``|delta| > 2 se``, else ``"noise"``
        (``"unknown"`` without a standard error).
    seeds_needed : int or None
        Seeds per row at which the standard error would be at most half of ``|delta|`` (so that
        ``|delta| > 2 se`` decides), if the two rows' spreads and the difference stay as measured:
        the least n > ``4 (sd_variant² + sd_full²) / delta²``. None without a standard error or a difference.
    """

    variant: str
    metric: str
    delta: float
    se: float
    verdict: str
    seeds_needed: int | None = None

    def cell(self, digits: int = 2) -> str:
        """``"+0.52 ± 0.31 worse"``: delta ± 2 standard errors and the verdict; an undecided one says
        how many seeds would decide it (``"+0.10 ± 0.31 noise (39 seeds)"``)."""
        text = f"{self.delta:+.{digits}f} ± {2 * self.se:.{digits}f} {self.verdict}"
        if self.verdict == "noise" and self.seeds_needed is not None:
            text += f" ({self.seeds_needed} seeds)"
        return text


def compare_rows(
    results: SeedResults, full: str, variants: Sequence[str], metrics: Sequence[str] = ("FGD", "SRGR")
) -> list[Effect]:
    """How each row of ``variants`` differs from row ``full``, metric by metric, against seed noise.

    For an ablation study ``full`` is the full model and ``variants`` its ablations; for a
    benchmark ``full`` can be a baseline and ``variants`` the models compared with it.
    A difference counts (``"worse"``/``"better"`` than ``full``) only when it exceeds two standard
    errors of the difference of the seed means (Welch); the direction is the metric's
    (``METRICS[key].higher_is_better``: FGD lower is better, most others higher). ``metrics``: keys of
    :data:`~beatlite.metrics.scoring.METRICS` that have a better direction.

    Returns
    -------
    list of Effect, variant-major.

    Examples
    --------
    Against a full model at FGD 1, 2, 3 (sd 1), a variant 1 worse is within two standard errors
    (``2 sqrt(2 / 3) = 1.63``): noise, which 9 seeds per row would decide (:func:`seeds_needed`); one 2 worse
    is worse (FGD: lower is better).

    >>> table = SeedResults({"Full": {"FGD": [1.0, 2.0, 3.0]}, "A": {"FGD": [2.0, 3.0, 4.0]},
    ...                      "B": {"FGD": [3.0, 4.0, 5.0]}}, [1, 2, 3], {})
    >>> for effect in compare_rows(table, "Full", ["A", "B"], metrics=("FGD",)):
    ...     print(effect.variant, effect.verdict, effect.seeds_needed, effect.cell())
    A noise 9 +1.00 ± 1.63 noise (9 seeds)
    B worse 3 +2.00 ± 1.63 worse
    """

    higher = {key: m.higher_is_better for key, m in METRICS.items() if m.higher_is_better is not None}
    effects = []
    for variant in variants:
        for metric in metrics:
            if metric not in higher:
                raise ValueError(f"metric must be a key of METRICS with a better direction, got {metric!r}")
            delta, se = results.difference(variant, full, metric)
            if not math.isfinite(se):
                verdict = "unknown"
            elif abs(delta) <= 2 * se:
                verdict = "noise"
            else:
                verdict = "better" if (delta > 0) == higher[metric] else "worse"
            effects.append(
                Effect(
                    variant, metric, delta, se, verdict, seeds_needed(results, variant, full, metric, delta)
                )
            )
    return effects


def seeds_needed(results: SeedResults, variant: str, full: str, metric: str, delta: float) -> int | None:
    """Seeds per row at which a difference ``delta`` between rows ``variant`` and ``full`` would exceed two
    standard errors, with the two rows' spreads as measured (:attr:`Effect.seeds_needed`; pass another
    ``delta``, e.g. a paper's effect, to ask what it would take to see that).

    Examples
    --------
    Both rows with sd 1: the least n with ``|delta| > 2 sqrt(2 / n)``, i.e. ``n > 8 / delta**2``:

    >>> table = SeedResults({"Full": {"FGD": [1.0, 2.0, 3.0]}, "A": {"FGD": [2.0, 3.0, 4.0]}}, [1, 2, 3], {})
    >>> seeds_needed(table, "A", "Full", "FGD", 1.0), seeds_needed(table, "A", "Full", "FGD", 0.5)
    (9, 33)
    """
    spread = results.sd(variant, metric) ** 2 + results.sd(full, metric) ** 2
    if not math.isfinite(spread) or not math.isfinite(delta) or delta == 0:
        return None
    return max(2, math.floor(4 * spread / delta**2) + 1)  # |delta| > 2 se, strictly, decides


def evaluate_seeds(
    names: Sequence[str] | None = None,
    seeds: Sequence[int] = (SEED, 2022, 2023),
    *,
    test: Any = None,
    extractor: Any = None,
    missing: str = "error",
    progress: bool = False,
    columns: Sequence[str] | None = None,
) -> SeedResults:
    """Score the checkpoints of every (name, seed) on the test split and collect them by row.

    Parameters
    ----------
    names : sequence of str, optional
        Keys of :data:`~beatlite.train.recipes.RECIPES`; default those whose checkpoints exist
        for every seed.
    seeds : sequence of int
        Checkpoints from :func:`checkpoint_path`.
    test, extractor
        As :func:`beatlite.train.evaluate_models` (loaded once for all seeds).
    missing : {"error", "skip"}
        A missing (name, seed) checkpoint raises, or is left out (that row then has fewer
        values; the table's ``seeds`` column gives the count).
    progress : bool
        Print one line per seed.
    columns : sequence of str, optional
        Metric keys (default :data:`~beatlite.train.evaluation.COLUMNS`; :data:`~beatlite.train.evaluation.RECORD_COLUMNS`
        adds the papers' variants).

    Returns
    -------
    SeedResults
        Rows in :data:`~beatlite.train.recipes.RECIPES` order; the two ground-truth rows first.
        ``info["shipped"]``: row label -> seed of the shipped checkpoint.

    Raises
    ------
    FileNotFoundError
        A requested checkpoint is missing (names the file and the command that trains it).
    """
    from beatlite.metrics.extractor import load_extractor

    seeds = [int(s) for s in seeds]
    if not seeds:
        raise ValueError("seeds must not be empty")
    if missing not in ("error", "skip"):
        raise ValueError(f"missing must be 'error' or 'skip', got {missing!r}")
    names = _seed_names(names, seeds, missing)
    test = load_test_set() if test is None else test
    extractor = load_extractor("dirvec") if extractor is None else extractor
    columns = tuple(columns or COLUMNS)
    euler_extractor = load_extractor("pose") if "FGD (BEAT AE)" in columns else None  # once for all seeds
    values: dict[str, dict[str, list[float]]] = {}
    info: dict[str, Any] = {}
    for i, seed in enumerate(seeds):
        present = {n: path for n in names if (path := _existing_checkpoint(n, seed)) is not None}
        res = evaluate_models(
            [str(path) for path in present.values()],
            test=test,
            extractor=extractor,
            ground_truth=i == 0,
            columns=columns,
            euler_extractor=euler_extractor,
        )
        info = dict(res.info)
        for row in res.rows:
            slot = values.setdefault(row.label, {})
            for metric, v in row.metrics.items():
                slot.setdefault(metric, []).append(float(v))
        for name in set(names) - set(present):  # a skipped checkpoint is a NaN: value k is always seed k
            for vals in values[label_of(name)].values():
                vals.append(math.nan)
        if progress:
            print(f"seed {seed}: {len(names)} checkpoints scored in {res.info['seconds']:.1f} s", flush=True)
    info["checkpoints"] = {n: _seed_files(n, seeds) for n in names}
    info["shipped"] = {label_of(n): shipped_seed(paths.checkpoints_dir() / f"{n}.pt") for n in names}
    return SeedResults(values, seeds, info)


def _seed_names(names: Sequence[str] | None, seeds: list[int], missing: str) -> list[str]:
    """The checkpoints to score: ``names`` checked to exist (all seeds, or the first with ``"skip"``),
    or by default every recipe whose checkpoints exist."""
    if names is None:
        return [
            n
            for n in RECIPES
            if checkpoint_path(n, seeds[0]).is_file()
            and (missing == "skip" or all(checkpoint_path(n, s).is_file() for s in seeds))
        ]
    for name in names:
        for seed in seeds:
            path = checkpoint_path(name, seed)
            if not path.is_file() and (missing == "error" or seed == seeds[0]):
                raise FileNotFoundError(
                    f"{path}: no checkpoint of {name!r} for seed {seed}; train it with "
                    f"`python -m beatlite.train seeds --seeds {seed} --only {name}`"
                )
    return list(names)


def recorded_seed_results(path: str | Path | None = None) -> SeedResults:
    """The seed table recorded beside the shipped checkpoints (``checkpoints/results_seeds.json``).

    Written by ``make seeds`` (``python -m beatlite.train seeds --ship --out checkpoints/results_seeds``)
    when the checkpoints were trained; ``info["shipped"]`` names each row's shipped seed.

    Raises
    ------
    FileNotFoundError
        No recorded table (names the file and the command that writes it).

    Examples
    --------
    Every recorded CaMN seed has an FGD; the ground-truth rows have one value (they do not depend on a seed):

    >>> record = recorded_seed_results()
    >>> record.count("CaMN") == len(record.seeds), len(record.values[GROUND_TRUTH]["FGD"])
    (True, 1)
    """

    path = Path(path) if path is not None else paths.checkpoints_dir() / "results_seeds.json"
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no recorded seed table; write it with `make seeds`")
    try:
        return SeedResults.from_dict(json.loads(path.read_text()))
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise FormatError(path, f"not a seed table written by write_seed_results ({exc})") from exc


def recorded_shipped_seed(name: str, path: str | Path | None = None) -> int:
    """The seed of recipe ``name``'s shipped checkpoint in the recorded seed table (``info["shipped"]``),
    :data:`~beatlite.train.recipes.SEED` when there is no record or it does not name the row.

    Examples
    --------
    >>> recorded_shipped_seed("camn_tiny") == shipped_seed(paths.checkpoints_dir() / "camn_tiny.pt")
    True
    >>> recorded_shipped_seed("camn_tiny", path="no_such_record.json") == SEED  # no record: the default seed
    True
    """

    path = Path(path) if path is not None else paths.checkpoints_dir() / "results_seeds.json"
    if not path.is_file():
        return SEED
    seed = (recorded_seed_results(path).info.get("shipped") or {}).get(label_of(name))
    return SEED if seed is None else int(seed)


#: Tolerances of :func:`check_against_record`. Generation runs float32 torch kernels whose rounding
#: differs between CPUs (oneDNN picks kernels per instruction set), and the autoregressive units
#: carry it forward: scores agree to ~1e-5 relative, so 1e-3 is safe. Values that are zero by
#: definition (the ground truth's FGD against itself) are pure float64 round-off of size ~1e-14
#: that differs between machines: hence an absolute 1e-9, far below any printed digit.
RECORD_RTOL, RECORD_ATOL = 1e-3, 1e-9


def record_command(name: str | None = None) -> str:
    """The command that records recipe ``name``'s rows (every row when None) in the shipped seed table.

    Examples
    --------
    >>> record_command("camn_tiny"), record_command()
    ('make seeds ONLY=camn_tiny', 'make seeds')
    """
    return "make seeds" + (f" ONLY={name}" if name else "")


@dataclasses.dataclass(frozen=True)
class NotRecorded:
    """A row, or one metric of a row, of a live table that the seed record does not have yet.

    A model or metric registered after the record was written (``make seeds``, about 2 hours) is reported
    so, not failed: its ``str`` is ``"<row>[ <metric>]: not recorded: run `make seeds ONLY=<recipe>`"``.

    Attributes
    ----------
    row : str
        Row label.
    metric : str or None
        The metric key the recorded row lacks; None when the whole row is missing.
    recipe : str or None
        The recipe to record (:func:`record_command`); None for the ground-truth rows (every row).

    Examples
    --------
    >>> print(NotRecorded("CaMN", "Speed", "camn_tiny"))
    CaMN Speed: not recorded: run `make seeds ONLY=camn_tiny`
    >>> print(NotRecorded("Ground truth", None, None))
    Ground truth: not recorded: run `make seeds`
    """

    row: str
    metric: str | None
    recipe: str | None

    def __str__(self) -> str:
        what = self.row if self.metric is None else f"{self.row} {self.metric}"
        return f"{what}: not recorded: run `{record_command(self.recipe)}`"


def check_against_record(
    results: Any, record: SeedResults, *, metrics: Sequence[str] | None = None
) -> list[NotRecorded]:
    """Assert that a live :func:`~beatlite.train.evaluation.evaluate_models` table equals the record.

    Each row's value must equal the record's value for the seed of the shipped checkpoint
    (``record.info["shipped"]``, :data:`~beatlite.train.recipes.SEED` for a row it does not name;
    ground-truth rows: the recorded one) within :data:`RECORD_RTOL` / :data:`RECORD_ATOL`. Rows and
    metrics the record does not have yet are not compared: they are returned.

    Returns
    -------
    list of NotRecorded
        The rows (and metrics of recorded rows) left unchecked, each saying which ``make seeds`` records it.

    Raises
    ------
    AssertionError
        Naming the row and metric and ``make seeds``: the record or the checkpoint is stale.

    Examples
    --------
    >>> from beatlite.train.evaluation import ModelResults, ResultRow
    >>> record = SeedResults({"CaMN": {"FGD": [3.0]}}, [SEED], {})
    >>> live = ModelResults([ResultRow("CaMN", "camn_tiny", "euler141", {"FGD": 3.0, "Speed": 1.0}),
    ...                      ResultRow("Mine", "/tmp/mine_tiny.pt", "euler141", {"FGD": 2.0})], {})
    >>> for gap in check_against_record(live, record):
    ...     print(gap)
    CaMN Speed: not recorded: run `make seeds ONLY=camn_tiny`
    Mine: not recorded: run `make seeds ONLY=mine_tiny`
    """
    shipped = record.info.get("shipped") or {}
    gaps = []
    for row in results.rows:
        recipe = None if row.representation == "ground_truth" else Path(row.source).stem
        if row.label not in record.values:
            gaps.append(NotRecorded(row.label, None, recipe))
            continue
        seed = SEED if shipped.get(row.label) is None else int(shipped[row.label])
        assert seed in record.seeds, f"{row.label}: shipped seed {seed} is not in the record: make seeds"
        k = 0 if row.representation == "ground_truth" else record.seeds.index(seed)
        for metric, value in row.metrics.items():
            if metrics is not None and metric not in metrics:
                continue
            if metric not in record.values[row.label]:
                gaps.append(NotRecorded(row.label, metric, recipe))
                continue
            recorded = record.values[row.label][metric][k]
            np.testing.assert_allclose(
                recorded,
                value,
                rtol=RECORD_RTOL,
                atol=RECORD_ATOL,
                err_msg=f"{row.label} {metric}: make seeds",
            )
    return gaps


def write_seed_results(results: SeedResults, stem: str | Path | None = None) -> tuple[Path, Path]:
    """Write ``<stem>.md`` and ``<stem>.json`` atomically (default ``build/results_seeds``).

    Returns
    -------
    (Path, Path)
        The ``.md`` and ``.json`` files; the JSON reads back with :meth:`SeedResults.from_dict` (or
        :func:`recorded_seed_results`).

    Examples
    --------
    A round trip, NaN (a missing seed) included:

    >>> import tempfile
    >>> table = SeedResults({"CaMN": {"FGD": [3.0, math.nan, 4.0]}}, [1, 2, 3], {"windows": 143})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     md, js = write_seed_results(table, Path(tmp) / "seeds")
    ...     back = recorded_seed_results(js)
    >>> md.name, back.seeds, back.values["CaMN"]["FGD"], back.mean("CaMN", "FGD")
    ('seeds.md', [1, 2, 3], [3.0, nan, 4.0], 3.5)
    """

    stem = Path(stem) if stem is not None else paths.build_dir() / "results_seeds"
    info = results.info
    text = (
        f"# Gesture models on the `{info.get('split', 'test')}` split, seeds {results.seeds}\n\n"
        f"Mean ± sample standard deviation over the training seeds of each row (column `seeds`: how many; "
        f"{info.get('windows', '?')} FGD windows; ground-truth rows do not depend on a seed). "
        "The shipped checkpoint of each row is its seed nearest the median FGD (column `shipped`); every "
        "seed's checkpoint is in `build/seeds/<seed>/`.\n\n"
        + results.to_markdown()
        + "\n\n"
        + describe(COLUMNS)
        + (f"\n\nNote: {info['notes']}" if info.get("notes") else "")
        + "\n"
    )
    return write_markdown_and_json(stem, text, results.to_dict())


def ablation_table(
    record: SeedResults,
    full: str,
    rows: Mapping[str, str | None],
    paper: Mapping[str, Mapping[str, float]],
    *,
    metrics: Sequence[str] = ("FGD", "SRGR"),
    deltas: Sequence[str] = ("FGD", "SRGR", "BeatAlign"),
    absent: Mapping[str, str] | None = None,
) -> str:
    """An ablation study as a Markdown table: the paper's row beside ours (mean ± sd) and each change ± 2 SE.

    Parameters
    ----------
    record : SeedResults
        Per-seed values (:func:`recorded_seed_results`).
    full : str
        The full model's row label (its change columns stay empty).
    rows : mapping our row label -> the paper's row name (None: no paper row)
        In table order.
    paper : mapping paper row -> metric -> value
        E.g. :data:`beatlite.train.evaluation.PAPER_BEAT_TABLE5`.
    metrics : sequence of str
        Columns shown as values, for us and for the paper: the paper's value of a variant key
        (``"BC (ha2g)"``) is the one it reports under the key or the metric's name (``"BC"``), its column
        headed by what the paper has (``"paper BC"``); the caption must say which variant the paper used.
    deltas : sequence of str
        Columns shown as changes vs ``full`` (:func:`compare_rows`: ``"+0.52 ± 0.31 worse"``; an undecided
        change says how many seeds would decide it).
    absent : mapping paper row -> reason, optional
        Paper rows we have no model for, listed last with the paper's values and the reason.

    Returns
    -------
    str

    Examples
    --------
    >>> rec = SeedResults({"Full": {"FGD": [1.0, 2.0, 3.0]}, "A": {"FGD": [2.0, 3.0, 4.0]}}, [1, 2, 3], {})
    >>> print(ablation_table(rec, "Full", {"Full": "full", "A": None}, {"full": {"FGD": 5.0}},
    ...                      metrics=("FGD",), deltas=("FGD",)))
    | variant | paper row | paper FGD ↓ | ours FGD ↓ | Δ FGD ± 2 SE | seeds |
    |---|---|---|---|---|---|
    | Full | full | 5.00 | 2.00 ± 1.00 |  | 3 |
    | A | — | — | 3.00 ± 1.00 | +1.00 ± 1.63 noise (9 seeds) | 3 |

    A paper row with no model of ours:

    >>> print(ablation_table(rec, "Full", {"Full": "full"}, {"full": {"FGD": 5.0}, "B": {"FGD": 6.0}},
    ...                      metrics=("FGD",), deltas=("FGD",), absent={"B": "needs X"}).splitlines()[-1])
    | — | B | 6.00 | not trained: needs X |  | 0 |
    """

    variants = [label for label in rows if label != full]
    by = {(e.variant, e.metric): e for e in compare_rows(record, full, variants, metrics=deltas)}
    heads = column_headers(metrics)
    # a paper reports one variant per metric name: its value of "BC (ha2g)" is its "BC"
    name = {m: METRICS[m].name if m in METRICS else m for m in (*metrics, *deltas)}

    def paper_cells(published: Mapping[str, float]) -> list[str]:
        return [fmt_metric(published.get(m, published.get(name[m], math.nan)), m) for m in metrics]

    header = [
        "variant",
        "paper row",
        *[f"paper {h}" for h in column_headers([name[m] for m in metrics])],
        *[f"ours {h}" for h in heads],
    ]
    header += [f"Δ {m} ± 2 SE" for m in deltas] + ["seeds"]
    body = []
    for label, paper_row in rows.items():
        published = paper.get(paper_row, {}) if paper_row else {}
        cells = [label, paper_row or "—", *paper_cells(published)]
        cells += [record.cell(label, m) for m in metrics]
        cells += [
            "" if label == full else by[label, m].cell(3 if name[m] in ("SRGR", "BeatAlign", "BC") else 2)
            for m in deltas
        ]
        body.append([*cells, record.count(label, metrics[0])])
    for paper_row, reason in (absent or {}).items():
        published = paper.get(paper_row, {})
        cells = ["—", paper_row, *paper_cells(published)]
        body.append([*cells, f"not trained: {reason}", *[""] * (len(metrics) - 1 + len(deltas)), 0])
    return markdown_table(header, body)
