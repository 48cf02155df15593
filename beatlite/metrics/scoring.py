"""The one evaluation path: every metric, by name and variant, on one system's takes vs the ground truth.

Every table of beatlite (the results tables of BEAT Tables 4/5 and HA2G Tables 1/3/4, the seed
tables, the notebooks) scores a system by calling :func:`evaluate` with

- a :class:`Takes`: the system's motion on every evaluated take, in the forms the metrics read
  (positions, TED directions, Euler degrees, extractor features of its windows), and
- a :class:`GroundTruth`: the same for the dataset, plus what is computed once for all systems
  (semantic scores, audio onsets, the training MAAC of beat consistency).

Metrics are looked up by name in :data:`METRICS`; each names its variant and parameters, so a
table can say which definition produced each column (:func:`describe`). A metric whose input
is missing (e.g. Euler angles for a direction model) is skipped with the reason.

Adding a metric: write one function (its own module in ``beatlite.metrics``) whose parameters are named
after the inputs it reads (:data:`INPUTS`: ``positions``, ``truth_positions``, ``semantic``, ``fps``, ...),
then one :class:`Metric` entry (:func:`register_metric`, or a line in :data:`METRICS`): the adapter from
:class:`Takes` / :class:`GroundTruth` is generated from those names (:func:`bind_inputs`).

>>> import numpy as np
>>> pos = [np.zeros((40, 2, 3))]
>>> truth = GroundTruth(Takes(positions=pos), semantic=[np.full(40, 0.5)])
>>> evaluate(Takes(positions=pos), truth, metrics=("SRGR", "PCK")).get("SRGR").value  # perfect: mean score
0.5

Taught in ``notebooks/04_metrics.ipynb`` (the metrics) and ``notebooks/07_benchmark.ipynb`` (the tables).
"""

from __future__ import annotations

import dataclasses
import inspect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from beatlite.constants import FPS, SR, WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.notebook import defined_again


@dataclass(eq=False)
class Takes:
    """One system's motion on every evaluated take (lists in take order).

    Attributes
    ----------
    positions : list of (T_k, J, 3) float, cm
        Joint positions (SRGR, PCK, BeatAlign, L1div).
    directions : list of (T_k, 42, 3) float, optional
        Unit TED bone directions (beat consistency).
    euler : list of (T_k, 141) float, degrees, optional
        ``spine_neck_141`` Euler channels (the reference SRGR / BeatAlign / L1div of BEAT's code).
    features : (N, F) float, optional
        Extractor features of the system's 34-frame windows (FGD, Diversity).
    euler_features : (N, F) float, optional
        Features of the same windows of the Euler channels by an autoencoder trained on them
        (BEAT's FGD space: ``"FGD (BEAT AE)"``).
    rot6d_features : (N, F) float, optional
        Features of the same windows as 6D rotations of the 47 joints (EMAGE's kind of FGD space: ``"FGD (rot6d)"``).

    Examples
    --------
    >>> takes = Takes(positions=[np.zeros((4, 2, 3)), np.zeros((6, 2, 3))])
    >>> len(takes.positions), takes.directions is None
    (2, True)
    """

    positions: list[np.ndarray]
    directions: list[np.ndarray] | None = None
    euler: list[np.ndarray] | None = None
    features: np.ndarray | None = None
    euler_features: np.ndarray | None = None
    rot6d_features: np.ndarray | None = None


@dataclass(eq=False)
class GroundTruth:
    """The dataset's takes and what every system is scored against, computed once.

    Attributes
    ----------
    takes : Takes
        The ground truth's own motion (its ``features`` are FGD's real distribution).
    semantic : list of (T_k,) float in [0, 1], optional
        Per-frame semantic scores (SRGR).
    audio : list of (N_k,) float32, optional
        The takes' audio at ``sr`` (metrics whose variant detects its own onsets).
    audio_beats : list of (A_k,) float, optional
        Onset times (s) of each take's audio with beatlite's detector
        (:func:`beatlite.metrics.beats.audio_beats` defaults), shared by BeatAlign and BC;
        computed from ``audio`` on first use when not given.
    change_angle : (P,) float, optional
        MAAC of the training directions per angle pair (beat consistency).
    fps, sr : float, int
    mean_direction : (126,) or (42, 3) float, optional
        The train split's mean bone direction (HA2G's ``mean_dir_vec``; ``"BC (ha2g published)"``).
    mean_speed : (J,) float, cm/s, optional
        The train split's mean speed of each joint of ``takes.positions`` (EMAGE's ``avg_vel``; ``"BC (emage)"``).
    onsets : dict of str -> list
        Per-take onsets of the variants that detect their own (``"BeatAlign (reference)"``: one array per
        take; ``"BC (ha2g)"``: per take one array per 34-frame clip), filled on first use.

    Examples
    --------
    >>> truth = GroundTruth(Takes(positions=[np.zeros((4, 2, 3))]), semantic=[np.full(4, 0.5)])
    >>> truth.fps, truth.sr, truth.beats() is None  # no audio, no beats
    (15, 16000, True)
    """

    takes: Takes
    semantic: list[np.ndarray] | None = None
    audio: list[np.ndarray] | None = None
    audio_beats: list[np.ndarray] | None = None
    change_angle: np.ndarray | None = None
    fps: float = FPS
    sr: int = SR
    mean_direction: np.ndarray | None = None
    mean_speed: np.ndarray | None = None
    onsets: dict[str, list[Any]] = field(default_factory=dict)

    def variant_onsets(self, key: str, detect: Callable[[], list[Any]]) -> list[Any]:
        """Per-take audio onsets of one metric variant (``detect()``), computed on first use and kept in
        :attr:`onsets` ``[key]`` (bootstrap resamples pick the takes' entries instead of detecting again)."""
        if key not in self.onsets:
            self.onsets[key] = detect()
        return self.onsets[key]

    def beats(self) -> list[np.ndarray] | None:
        """:attr:`audio_beats`, detected from :attr:`audio` now if needed (None without audio)."""
        if self.audio_beats is None and self.audio is not None:
            from beatlite.metrics.beats import audio_beats

            self.audio_beats = [audio_beats(y, self.sr) for y in self.audio]
        return self.audio_beats


@dataclass(frozen=True)
class Metric:
    """One column a table can show.

    Attributes
    ----------
    name : str
        The metric as the papers name it (``"FGD"``, ``"SRGR"``, ...).
    variant : str
        Which definition (``"beatlite"``, ``"paper"``, ``"reference"``, ``"ha2g"``, ...).
    higher_is_better : bool or None
        None for descriptive statistics.
    needs : tuple of str or None
        Inputs it reads: ``"positions"``, ``"directions"``, ``"euler"``, ``"features"``,
        ``"semantic"``, ``"audio"``, ``"beats"``, ``"change_angle"``, ``"mean_direction"``, ``"mean_speed"``;
        None: :func:`needs_of` ``(compute)`` (a function that names its inputs).
    compute : callable
        The metric function: its parameters are named after :data:`INPUTS` (bound by :func:`bind_inputs`:
        ``positions`` is the system's, ``truth_positions`` the ground truth's, ``fps`` the ground truth's
        rate, ...), or it is ``compute(generated: Takes, truth: GroundTruth, seed: int) -> float`` when a
        required parameter is not an input name (the built-in metrics, which combine several inputs).
    describe : str
        One line for a table caption: the variant and its parameters.
    source : str
        Where the variant comes from (paper, code, section) and what it differs in.
    bounds : (float, float)
        The values the metric can take (``(0, 1)`` for a fraction; default unbounded).
    perfect : float or None
        Its value when the system is the ground truth itself, where that is a constant (FGD 0, PCK 1);
        None where it depends on the data (SRGR, BeatAlign, BC: the ground truth's own value).

    Examples
    --------
    >>> def mean_height(positions, fps):
    ...     return float(np.mean([p[..., 1].mean() for p in positions]))
    >>> metric = Metric("Height", "demo", None, None, mean_height, "mean joint height, cm")
    >>> metric.needs  # from the parameter names (needs_of)
    ('positions',)
    """

    name: str
    variant: str
    higher_is_better: bool | None
    needs: tuple[str, ...] | None
    compute: Callable[[Takes, GroundTruth, int], float]
    describe: str
    source: str = ""
    bounds: tuple[float, float] = (-math.inf, math.inf)
    perfect: float | None = None

    def __post_init__(self) -> None:
        if self.needs is None:
            object.__setattr__(self, "needs", needs_of(self.compute))


ARROWS: dict[bool | None, str] = {True: " ↑", False: " ↓", None: ""}
"""A column header's suffix for a metric's ``higher_is_better``: none for a descriptive metric."""


@dataclass(frozen=True)
class MetricResult:
    """One metric value with the definition that produced it (a :class:`Metric`'s fields).

    Examples
    --------
    >>> result = MetricResult("MPJPE", "MPJPE", 1.5, "positions", higher_is_better=False)
    >>> result.key, result.value
    ('MPJPE', 1.5)
    """

    key: str
    name: str
    value: float
    variant: str
    higher_is_better: bool | None = None
    describe: str = ""


@dataclass
class Evaluation:
    """The results of :func:`evaluate`: ``results`` plus ``skipped`` ``{metric key: reason}``.

    Examples
    --------
    >>> truth = GroundTruth(Takes(positions=[np.zeros((4, 2, 3))]))
    >>> ev = evaluate(Takes(positions=[np.ones((4, 2, 3))]), truth, metrics=("MPJPE", "SRGR"))
    >>> round(ev.get("MPJPE").value, 6), list(ev.skipped)  # sqrt(3) cm; no semantic scores for SRGR
    (1.732051, ['SRGR'])
    """

    results: list[MetricResult]
    skipped: dict[str, str] = field(default_factory=dict)

    def get(self, key: str) -> MetricResult:
        """The result of metric ``key`` (a key of :data:`METRICS`); ``KeyError`` otherwise."""
        for r in self.results:
            if r.key == key:
                return r
        raise KeyError(
            f"no metric {key!r}; have {[r.key for r in self.results]}, skipped {sorted(self.skipped)}"
        )

    def values(self) -> dict[str, float]:
        """``{metric key: value}``, NaN for the skipped ones."""
        return {**{k: float("nan") for k in self.skipped}, **{r.key: r.value for r in self.results}}

    def to_markdown(self) -> str:
        """A Markdown table: metric, variant, value, better direction, definition."""
        from beatlite.report import markdown_table

        better = {True: "higher", False: "lower", None: ""}
        rows = [
            [r.name, r.variant, f"{r.value:.4g}", better[r.higher_is_better], r.describe]
            for r in self.results
        ]
        rows += [[key, "—", "skipped", "", why] for key, why in self.skipped.items()]
        return markdown_table(["metric", "variant", "value", "better", "definition"], rows)


def evaluate(
    generated: Takes, truth: GroundTruth, *, metrics: Sequence[str] | None = None, seed: int = 0
) -> Evaluation:
    """Score one system: every metric of ``metrics`` whose inputs are there.

    Parameters
    ----------
    generated : Takes
        The system's takes (same takes, in the same order and lengths, as ``truth.takes``).
    truth : GroundTruth
    metrics : sequence of str, optional
        Keys of :data:`METRICS` (default: all of them).
    seed : int
        Seed of the Diversity pairing.

    Returns
    -------
    Evaluation

    Examples
    --------
    >>> truth = GroundTruth(Takes(positions=[np.zeros((4, 2, 3))]))
    >>> generated = Takes(positions=[np.zeros((4, 2, 3))])
    >>> evaluate(generated, truth, metrics=("MPJPE", "PCK")).values()  # a perfect prediction
    {'MPJPE': 0.0, 'PCK': 1.0}
    """
    _check_pairing(generated, truth)
    results, skipped = [], {}
    for key in METRICS if metrics is None else metrics:
        if key not in METRICS:
            raise ValueError(f"unknown metric {key!r}; known: {sorted(METRICS)}")
        m = METRICS[key]
        missing = [n for n in m.needs if not _has(n, generated, truth)]
        if missing:
            skipped[key] = f"needs {', '.join(missing)}"
            continue
        try:
            value = _one_number(key, bind_inputs(m.compute)(generated, truth, seed))
        except TooFewWindows as e:  # a defined metric that this test set is too small for: skipped, said why
            skipped[key] = str(e)
            continue
        if not math.isfinite(value):  # e.g. BeatAlign without audio onsets, BC of a system that never moves
            skipped[key] = f"undefined on these takes ({UNDEFINED.get(m.name, f'the metric gave {value}')})"
            continue
        results.append(MetricResult(key, m.name, value, m.variant, m.higher_is_better, m.describe))
    return Evaluation(results, skipped)


def describe(keys: Sequence[str], *, sources: bool = False) -> str:
    """Caption lines ``- <key>: <variant and parameters>`` for the columns of a table (``sources``: each
    followed by where the variant comes from).

    Examples
    --------
    >>> print(describe(["MPJPE"]))
    - **MPJPE**: mean per-joint position error, cm, frame-weighted over takes
    """
    return "\n".join(
        f"- **{key}**: {METRICS[key].describe}" + (f" [{METRICS[key].source}]" if sources else "")
        for key in keys
    )


#: Generated per take (a list in take order, or an (N, F) array of window features): the system's under
#: these names, the ground truth's as ``truth_<name>``.
TAKE_INPUTS: tuple[str, ...] = (
    "positions",
    "directions",
    "euler",
    "features",
    "euler_features",
    "rot6d_features",
)
#: Every parameter name :func:`bind_inputs` fills: :data:`TAKE_INPUTS`, their ``truth_`` twins, the
#: :class:`GroundTruth` fields (``beats``: :meth:`GroundTruth.beats`) and ``seed``.
INPUTS: tuple[str, ...] = (
    *TAKE_INPUTS,
    *(f"truth_{name}" for name in TAKE_INPUTS),
    "semantic",
    "audio",
    "beats",
    "change_angle",
    "mean_direction",
    "mean_speed",
    "fps",
    "sr",
    "seed",
)


def _input(name: str, gen: Takes, truth: GroundTruth, seed: int) -> Any:
    if name in TAKE_INPUTS:
        return getattr(gen, name)
    if name.startswith("truth_"):
        return getattr(truth.takes, name[len("truth_") :])
    if name == "beats":
        return truth.beats()
    return seed if name == "seed" else getattr(truth, name)


def bind_inputs(fn: Callable[..., float]) -> Callable[[Takes, GroundTruth, int], float]:
    """``compute(generated, truth, seed)`` for a metric function whose parameters name its inputs.

    Parameters
    ----------
    fn : callable
        A function whose required parameters all are names of :data:`INPUTS` (``positions`` the system's,
        ``truth_positions`` the ground truth's, ``semantic``, ``fps``, ``seed``, ...; parameters with a
        default that are not inputs keep it). A function with another required parameter is taken to be
        ``compute(generated, truth, seed)`` already and returned as is.

    Returns
    -------
    callable
        ``(generated: Takes, truth: GroundTruth, seed: int) -> float``.

    Examples
    --------
    >>> import numpy as np
    >>> def mean_height(positions, fps):
    ...     return float(np.mean([p[..., 1].mean() for p in positions]))
    >>> takes = Takes(positions=[np.ones((4, 2, 3))])
    >>> bind_inputs(mean_height)(takes, GroundTruth(takes), 0)
    1.0
    >>> needs_of(mean_height)
    ('positions',)
    """
    params = inspect.signature(fn).parameters.values()
    required = [p.name for p in params if p.default is inspect.Parameter.empty]
    if any(name not in INPUTS for name in required):
        return fn
    names = [p.name for p in params if p.name in INPUTS]

    def compute(generated: Takes, truth: GroundTruth, seed: int) -> float:
        return fn(**{name: _input(name, generated, truth, seed) for name in names})

    return compute


def needs_of(fn: Callable[..., float]) -> tuple[str, ...]:
    """The :class:`Metric` ``needs`` of a function :func:`bind_inputs` binds by name: its parameters that
    name an input which may be missing (``truth_positions`` reads as ``positions``; ``fps``, ``sr`` and
    ``seed`` are always there).

    Examples
    --------
    >>> def recall(positions, truth_positions, semantic, fps):
    ...     return 0.0
    >>> needs_of(recall)  # fps is always there; truth_positions reads as positions
    ('positions', 'semantic')
    """
    if bind_inputs(fn) is fn:
        required = [
            p.name for p in inspect.signature(fn).parameters.values() if p.default is inspect.Parameter.empty
        ]
        unknown = [name for name in required if name not in INPUTS]
        raise ValueError(
            f"{getattr(fn, '__name__', fn)!r} does not name its inputs ({', '.join(unknown)} not in INPUTS: "
            f"{', '.join(INPUTS)}); rename them, or give needs explicitly"
        )
    names = [p for p in inspect.signature(fn).parameters if p in INPUTS and p not in ("fps", "sr", "seed")]
    return tuple(dict.fromkeys(n.removeprefix("truth_") for n in names))


def register_metric(key: str, metric: Metric) -> None:
    """Add a metric to :data:`METRICS` under ``key`` (``"<name>"`` or ``"<name> (<variant>)"``).

    Raises
    ------
    ValueError
        ``key`` is already another metric (the same one again, or its function defined again in a notebook cell
        run twice, replaces it), or ``metric.compute`` reads an input its ``needs`` does not list.

    Examples
    --------
    >>> def mean_height(positions):
    ...     return float(np.mean([p[..., 1].mean() for p in positions]))
    >>> register_metric("Height (demo)", Metric("Height", "demo", None, None, mean_height, "mean joint height"))
    >>> truth = GroundTruth(Takes(positions=[np.zeros((4, 2, 3))]))
    >>> evaluate(Takes(positions=[np.ones((4, 2, 3))]), truth, metrics=["Height (demo)"]).values()
    {'Height (demo)': 1.0}
    >>> del METRICS["Height (demo)"]  # keep the registry as shipped
    """
    if key in METRICS and not _same_metric(METRICS[key], metric):
        raise ValueError(f"{key!r} is already a metric ({METRICS[key].describe})")
    if bind_inputs(metric.compute) is not metric.compute:
        unlisted = sorted(set(needs_of(metric.compute)) - set(metric.needs))
        if unlisted:
            raise ValueError(f"{key!r}: compute reads {unlisted}, which needs={metric.needs} does not list")
    METRICS[key] = metric


def _same_metric(old: Metric, new: Metric) -> bool:
    """``new`` equals ``old`` up to its ``compute`` being the same function defined again
    (:func:`beatlite.notebook.defined_again`)."""
    a, b = old.compute, new.compute
    return (a is b or defined_again(a, b)) and dataclasses.replace(old, compute=b) == new


def _one_number(key: str, value: Any) -> float:
    """``float(value)`` of a metric's result, or a ``TypeError`` naming the metric when it is not one real number
    (``None`` from a missing ``return``, a per-take array, a complex value, a string).

    Examples
    --------
    >>> _one_number("Speed", np.float32(2.5))
    2.5
    >>> _one_number("Speed", np.array([1.0, 2.0]))
    Traceback (most recent call last):
    ...
    TypeError: metric 'Speed': compute returned an array of shape (2,), not one real number
    """
    shape = getattr(value, "shape", ())
    if tuple(shape) != ():
        raise TypeError(
            f"metric {key!r}: compute returned an array of shape {tuple(shape)}, not one real number"
        )
    if (
        value is None
        or isinstance(value, (str, bytes, complex, np.complexfloating))
        or "complex" in str(getattr(value, "dtype", ""))
    ):
        raise TypeError(f"metric {key!r}: compute returned {value!r}, not one real number")
    try:
        return float(value)
    except (TypeError, ValueError) as error:
        raise TypeError(
            f"metric {key!r}: compute returned {type(value).__name__}, not one real number"
        ) from error


def _has(need: str, gen: Takes, truth: GroundTruth) -> bool:
    if need in TAKE_INPUTS:
        return getattr(gen, need) is not None and getattr(truth.takes, need) is not None
    if need == "beats":
        return truth.beats() is not None
    return getattr(truth, need) is not None


def _check_pairing(gen: Takes, truth: GroundTruth) -> None:
    n, m = len(gen.positions), len(truth.takes.positions)
    if n != m:
        raise ValueError(f"generated has {n} takes, the ground truth {m}")
    for i, (g, t) in enumerate(zip(gen.positions, truth.takes.positions, strict=True)):
        if np.shape(g)[:1] != np.shape(t)[:1]:
            raise ValueError(
                f"take {i}: generated has {np.shape(g)[0]} frames, the ground truth {np.shape(t)[0]}"
            )


# --------------------------------------------------------------------------- the metrics
def _windows(features: np.ndarray, need: int = 2) -> np.ndarray:
    """``features`` of the windows, or :class:`TooFewWindows` when there are fewer than ``need`` (a covariance or a
    pair needs two)."""
    if len(features) < need:
        raise TooFewWindows(f"needs at least {need} windows, got {len(features)}")
    return features


def _fgd(reference: bool) -> Callable[[Takes, GroundTruth, int], float]:
    from beatlite.metrics.frechet import fgd

    return lambda g, t, seed: fgd(_windows(g.features), _windows(t.takes.features), reference=reference)


def _fgd_euler(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.frechet import fgd

    return fgd(_windows(g.euler_features), _windows(t.takes.euler_features))


def _fgd_rot6d(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.frechet import fgd

    return fgd(_windows(g.rot6d_features), _windows(t.takes.rot6d_features))


def _srgr_paper(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.recall import srgr

    return srgr(g.positions, t.takes.positions, t.semantic, variant="paper", delta=10.0)


def _srgr_reference(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.recall import srgr

    return srgr(g.euler, t.takes.euler, t.semantic, variant="reference")


def _beat_align(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.alignment import beat_align

    return beat_align(None, t.sr, g.positions, t.fps, audio_beats=t.beats())


def _beat_align_reference(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.alignment import VARIANTS, beat_align

    detect = VARIANTS["reference"].audio_beats
    beats = t.variant_onsets("BeatAlign (reference)", lambda: [detect(y, t.sr) for y in t.audio])
    return beat_align(None, t.sr, g.euler, t.fps, variant="reference", audio_beats=beats)


def _bc(variant: str) -> Callable[[Takes, GroundTruth, int], float]:
    from beatlite.metrics.consistency import beat_consistency, clip_audio_beats

    def compute(g: Takes, t: GroundTruth, seed: int) -> float:
        if variant == "beatlite":
            return beat_consistency(
                None, t.sr, g.directions, t.fps, change_angle=t.change_angle, audio_beats=t.beats()
            )
        beats = t.variant_onsets(
            f"BC ({variant})",
            lambda: [
                clip_audio_beats(y, t.sr, len(d), t.fps, variant=variant)
                for y, d in zip(t.audio, t.takes.positions, strict=True)
            ],
        )
        return beat_consistency(
            None, t.sr, g.directions, t.fps, change_angle=t.change_angle, variant=variant, audio_beats=beats
        )

    return compute


def _bc_published(g: Takes, t: GroundTruth, seed: int) -> float:
    """HA2G's clip BC as the paper's values were computed (the authors' README note of January 2023; the code they
    released adds the mean back): the train mean direction is not added back, so angles are measured between the
    mean-subtracted vectors (renormalised) the model outputs."""
    mean = np.asarray(t.mean_direction, np.float64).reshape(-1, 3)
    residuals = dataclasses.replace(
        g, directions=[np.asarray(d).reshape(len(d), -1, 3) - mean for d in g.directions]
    )
    return _bc("ha2g")(residuals, t, seed)


#: TED-43 joints EMAGE's "BC" scores: the counterparts of its SMPL-X upper body (neck, shoulders, elbows, wrists,
#: the nose for the head; SMPL-X's spine joints have no moving counterpart, the spine root is fixed here).
EMAGE_JOINTS = (1, 2, 3, 4, 5, 6, 7, 38)


def _bc_emage(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.alignment import emage_audio_beats, emage_beat_align

    beats = t.variant_onsets(
        "BC (emage)",
        lambda: [
            emage_audio_beats(y, t.sr, len(p), t.fps) for y, p in zip(t.audio, t.takes.positions, strict=True)
        ],
    )
    joints = list(EMAGE_JOINTS)
    speed = np.asarray(t.mean_speed, np.float64)[joints]
    return emage_beat_align(beats, [p[:, joints] for p in g.positions], t.fps, speed)


def _kinematic(stat: Callable[..., dict[str, float]]) -> Callable[[Takes, GroundTruth, int], float]:
    """GENEA's average acceleration / jerk: per take the mean over frames and moving joints (the fixed root
    of the common space left out, as GENEA leaves out the fixed hips), then the mean over takes."""
    return lambda g, t, seed: float(np.mean([stat(p[:, 1:], t.fps)["mean"] for p in g.positions]))


def _speed_hellinger(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.extras import hellinger_distance, speed_histogram

    def hist(takes: Takes) -> np.ndarray:
        return speed_histogram([p[:, 1:] for p in takes.positions], t.fps)

    return hellinger_distance(hist(g), hist(t.takes))


def _diversity(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.variation import diversity

    return diversity(_windows(g.features), n_pairs=500, seed=seed)


#: Windows per batch of ``Diversity (ha2g)``: HA2G's loader holds 96 clips, but data_samples' 143 test windows would
#: make one batch (every batch then meets itself: 0); 16 gives 8 batches there. On a large test set the two agree up
#: to the share of rows paired with their own batch, 1 / number of batches (docs/reference_code.md#ha2g-diversity).
DIVERSITY_BATCH = 16


class TooFewWindows(ValueError):
    """A metric needs more windows than the takes give; :func:`evaluate` lists it as skipped, with this message.

    Examples
    --------
    17 windows make one batch of 16 for ``Diversity (ha2g)``, which needs two:

    >>> takes = Takes(positions=[np.zeros((50, 2, 3))], features=np.zeros((17, 4)))
    >>> evaluate(takes, GroundTruth(takes), metrics=("Diversity (ha2g)",)).skipped
    {'Diversity (ha2g)': 'needs at least 2 batches of 16 windows, got 17 windows'}
    """


def _diversity_ha2g(g: Takes, t: GroundTruth, seed: int) -> float:
    from beatlite.metrics.variation import diversity

    n = len(g.features) // DIVERSITY_BATCH
    if n < 2:
        raise TooFewWindows(
            f"needs at least 2 batches of {DIVERSITY_BATCH} windows, got {len(g.features)} windows"
        )
    batches = [g.features[i * DIVERSITY_BATCH : (i + 1) * DIVERSITY_BATCH] for i in range(n)]  # test order
    return diversity(batches, n_pairs=500, seed=seed, batch_pairing=True)


def _l1div(windowed: bool) -> Callable[[Takes, GroundTruth, int], float]:
    from beatlite.metrics.variation import l1_diversity

    if windowed:
        return lambda g, t, seed: l1_diversity(g.euler, windowed=True)
    return lambda g, t, seed: l1_diversity(g.positions)


def _frame_weighted(fn: Callable[..., float]) -> Callable[[Takes, GroundTruth, int], float]:
    def compute(g: Takes, t: GroundTruth, seed: int) -> float:
        frames = np.array([len(p) for p in g.positions], dtype=np.float64)
        values = np.array([fn(a, b) for a, b in zip(g.positions, t.takes.positions, strict=True)])
        return float((values * frames).sum() / frames.sum())

    return compute


def _metrics() -> dict[str, Metric]:
    from beatlite.metrics.extras import acceleration_stats, jerk_stats, mpjpe, pck

    win = f"{WINDOW_LENGTH}-frame windows, stride {WINDOW_STRIDE}"
    return {
        "FGD": Metric("FGD", "beatlite", False, ("features",), _fgd(False),
                      f"Fréchet distance of extractor features of {win} (stable square root)",
                    source="Yoon et al. 2020 (Trimodal, ACM TOG) define FGD; BEAT (Liu et al., ECCV 2022) §6.3 and HA2G (Liu et al., CVPR 2022) §4.3 report it; beatlite's own autoencoder on TED-43 directions (docs/reference_code.md#fgd)"),
        "FGD (reference)": Metric("FGD", "reference", False, ("features",), _fgd(True),
                                  "the same with scipy's sqrtm, 1e10 on a complex result (BEAT's code)",
                    source="BEAT's and HA2G's code: pytorch-fid's scipy sqrtm, 1e10 on a complex result; differs from FGD only in the square root (docs/reference_code.md#fgd)"),
        "FGD (BEAT AE)": Metric("FGD", "beat_ae", False, ("euler_features",), _fgd_euler,
                                f"the same on {win} of the 141 z-scored Euler channels, features of an "
                                "autoencoder trained on them (BEAT's space; Euler models only)",
                    source="BEAT's code: features of an autoencoder on the 141 Euler channels (docs/reference_code.md#fgd-autoencoder); here beatlite's own such autoencoder, not BEAT's weights"),
        "FGD (rot6d)": Metric("FGD", "rot6d", False, ("rot6d_features",), _fgd_rot6d,
                              f"the same on {win} of the 6D rotations of the 47 spine_neck_141 joints (282-d), "
                              "features of an autoencoder trained on them",
                    source="EMAGE (Liu et al., CVPR 2024) and BEAT2 compute FGD on 6D rotations (Zhou et al., CVPR 2019) with an autoencoder of their own; here beatlite's autoencoder on the 47 upper-body BEAT joints (checkpoints/fgd_rot6d.pt), not EMAGE's weights or joint set"),
        "SRGR": Metric("SRGR", "paper", True, ("positions", "semantic"), _srgr_paper,
                       "BEAT eq. 11 on joint positions, δ = 10 cm, ground-truth semantic scores",
                    source='BEAT (Liu et al., ECCV 2022) eq. 11: PCK weighted by semantic scores, here on TED-43 positions with δ = 10 cm'),
        "SRGR (reference)": Metric("SRGR", "reference", True, ("euler", "semantic"), _srgr_reference,
                                   "BEAT's code: Euler degrees, summed |diff| < 4°, weight score / 0.165",
                    source="BEAT's code (docs/reference_code.md#srgr-reference): Euler degrees, summed |diff| < 4°, score / 0.165; can exceed 1"),
        "BeatAlign": Metric("BeatAlign", "beatlite", True, ("positions", "beats"), _beat_align,
                            "audio onsets vs joint-speed minima (positions), σ = 0.3 s, mean over audio beats",
                    source="BEAT (Liu et al., ECCV 2022) §6.3 / supplement §D; beatlite's clean reading on joint positions (docs/reference_code.md#beatalign-reference)"),
        "BeatAlign (reference)": Metric("BeatAlign", "reference", True, ("euler", "audio"), _beat_align_reference,
                                        "BEAT's code: Euler speed of columns 36:39, 10-500 s, RMS backtrack, "
                                        "times at 22050 Hz; onsets by the installed librosa (BEAT pins 0.8.0)",
                    source="BEAT's code utils/metric.py (docs/reference_code.md#beatalign-reference): one Euler triplet (a finger joint), 10-500 s, RMS backtracking, times at 22050 Hz"),
        "BC (emage)": Metric("BC", "emage", True, ("positions", "audio", "mean_speed"), _bc_emage,
                             "EMAGE/BEAT2's 'BC': BEAT's BeatAlign on positions (neck, shoulders, elbows, wrists, "
                             "nose), speeds / train mean, minima of order 7 at 30 fps above 0.3, σ = 0.3 s, 2 s "
                             "left out at both ends, joints without beats 0, takes frame-weighted",
                    source="EMAGE (Liu et al., CVPR 2024) and BEAT2 report BeatAlign as 'BC': PantoMatrix scripts/EMAGE_2024/utils/metric.py class alignment and its trainers (align_mask 60 frames at 30 fps); joints mapped from SMPL-X to TED-43"),
        "BC": Metric("BC", "beatlite", True, ("directions", "beats", "change_angle"), _bc("beatlite"),
                     "HA2G beat consistency on whole takes, σ = 0.1 s, MAAC of the train windows, rigid angle pairs left out",
                    source="HA2G (Liu et al., CVPR 2022) §4.3 eq. 10-11 on whole takes (docs/reference_code.md#beat-consistency); differs from HA2G's code in scoring whole takes and dropping rigid angle pairs"),
        "BC (ha2g)": Metric("BC", "ha2g", True, ("directions", "audio", "change_angle"), _bc("ha2g"),
                            "HA2G's code: 34-frame clips (stride 10) with their own onsets, σ = 0.1 s",
                    source="HA2G's code scripts/train_expressive.py (docs/reference_code.md#beat-consistency): 34-frame clips with their own onsets, weighted by audio beats, mean direction added back (as the released code does)"),
        "BC (ha2g published)": Metric("BC", "ha2g_published", True, ("directions", "audio", "change_angle", "mean_direction"),
                                      _bc_published,
                                      "HA2G's BC as its paper's values were computed (the authors' 2023 README note): "
                                      "BC (ha2g) on the mean-subtracted directions, the train mean direction not added back",
                    source="HA2G's paper values, per the authors' README note of January 2023 (docs/reference_code.md#beat-consistency): HA2G's code's clip protocol on mean-subtracted vectors (the released code adds the mean back)"),
        "Diversity": Metric("Diversity", "ha2g", True, ("features",), _diversity,
                            "mean L1 distance of extractor features of 500 random window pairs",
                    source="HA2G (Liu et al., CVPR 2022) §4.3 / Trimodal's evaluator: mean L1 distance of features of random clip pairs (docs/reference_code.md#ha2g-diversity); beatlite's extractor"),
        "Diversity (ha2g)": Metric("Diversity", "ha2g_batches", True, ("features",), _diversity_ha2g,
                                   f"HA2G's code: windows in test order in batches of {DIVERSITY_BATCH} (HA2G: 96), "
                                   "each batch paired row by row with a random batch, itself included (its rows "
                                   "then add 0), 500 batches at most",
                    source="HA2G's code scripts/model/embedding_space_evaluator.py (docs/reference_code.md#ha2g-diversity): a list of batches paired with a random permutation of itself; beatlite's extractor, batches of 16 windows"),
        "L1div": Metric("L1div", "beatlite", True, ("positions",), _l1div(False),
                        "BEAT L1div on positions (cm summed over joints x 3 per frame)",
                    source="BEAT (Liu et al., ECCV 2022) §5-6 'L1 diversity', on TED-43 positions (docs/reference_code.md#l1-diversity)"),
        "L1div (reference)": Metric("L1div", "reference", True, ("euler",), _l1div(True),
                                    f"BEAT's code: Euler degrees of the concatenated {win}",
                    source="BEAT's code utils/metric.py L1div (docs/reference_code.md#l1-diversity): Euler degrees of the concatenated 34-frame windows"),
        "PCK": Metric("PCK", "positions", True, ("positions",), _frame_weighted(lambda a, b: pck(a, b, 10.0)),
                      "fraction of joints within 10 cm, frame-weighted over takes",
                    source='Percentage of Correct Keypoints (e.g. Ginosar et al., CVPR 2019, Speech2Gesture), 10 cm, positions'),
        "MPJPE": Metric("MPJPE", "positions", False, ("positions",), _frame_weighted(mpjpe),
                        "mean per-joint position error, cm, frame-weighted over takes",
                    source='Mean per-joint position error (Ionescu et al., Human3.6M, TPAMI 2014), positions'),
        "Acceleration (GENEA)": Metric("Acceleration", "genea", None, ("positions",), _kinematic(acceleration_stats),
                                       "GENEA's average acceleration: |Δ²p|·fps² (cm/s²), mean over frames and "
                                       "moving joints per take, then over takes (compare with the ground truth's)",
                    source='GENEA Challenge 2020 numerical evaluation (Kucherenko et al., IUI 2021; genea_numerical_evaluations calk_jerk_or_acceleration.py): average acceleration, fixed root left out'),
        "Jerk (GENEA)": Metric("Jerk", "genea", None, ("positions",), _kinematic(jerk_stats),
                               "GENEA's average jerk: |Δ³p|·fps³ (cm/s³), averaged as Acceleration (GENEA)",
                    source='GENEA Challenge 2020 numerical evaluation (Kucherenko et al., IUI 2021; genea_numerical_evaluations calk_jerk_or_acceleration.py): average jerk, fixed root left out'),
        "Speed Hellinger (GENEA)": Metric("Speed Hellinger", "genea", False, ("positions",), _speed_hellinger,
                                          "GENEA's Hellinger distance of joint-speed histograms (1 cm/s bins, "
                                          "0-49 cm/s, moving joints of all takes pooled) vs the ground truth's",
                    source='GENEA Challenge numerical evaluation (Kucherenko et al., IUI 2021; genea_numerical_evaluations calc_histogram.py + hellinger_distance.py): histogram of moving distance, Hellinger distance'),
    }  # fmt: skip


#: The values each built-in metric can take, by name (``SRGR (reference)``, weighted by score / 0.165, can exceed 1).
BOUNDS: dict[str, tuple[float, float]] = {
    "FGD": (0.0, math.inf), "SRGR": (0.0, 1.0), "BeatAlign": (0.0, 1.0), "BC": (0.0, 1.0),
    "Diversity": (0.0, math.inf), "L1div": (0.0, math.inf), "PCK": (0.0, 1.0), "MPJPE": (0.0, math.inf),
    "Acceleration": (0.0, math.inf), "Jerk": (0.0, math.inf), "Speed Hellinger": (0.0, 1.0),
}  # fmt: skip
#: Why a built-in metric may be undefined (NaN) on some takes, by name: :func:`evaluate` lists it as skipped with this.
UNDEFINED: dict[str, str] = {
    "BeatAlign": "no audio onset in any take",
    "BC": "no motion beat in any take, as for a system that never moves, or no audio beat",
}
#: Built-in metrics whose value for the ground truth itself is a constant, by name.
PERFECT: dict[str, float] = {"FGD": 0.0, "PCK": 1.0, "MPJPE": 0.0, "Speed Hellinger": 0.0}


def _with_bounds(metrics: dict[str, Metric]) -> dict[str, Metric]:
    """The built-in metrics with their :data:`BOUNDS` and :data:`PERFECT` values."""
    out = {}
    for key, m in metrics.items():
        bounds = (0.0, math.inf) if key == "SRGR (reference)" else BOUNDS.get(m.name, m.bounds)
        out[key] = dataclasses.replace(m, bounds=bounds, perfect=PERFECT.get(m.name))
    return out


METRICS: dict[str, Metric] = _with_bounds(_metrics())
"""Every metric a table can show, by key (``"<name>"`` or ``"<name> (<variant>)"``)."""
