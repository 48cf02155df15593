"""The paper's correlation claims as numbers with significance tests.

BEAT (Sec. 3.3) states that gestures correlate with audio, facial expression,
emotion and speaker identity. Here *gesture energy* is the mean speed of the
arm/spine joints (:data:`beatlite.stats.corpus.ENERGY_JOINTS`, cm/s), averaged
over non-overlapping windows (2 s by default) to tame autocorrelation.

- continuous modalities (audio RMS, facial activity): Spearman's rho over windows,
  scipy's p-value (assumes independent windows, optimistic) **and** a permutation
  p-value from circularly shifting the other signal within each take, which keeps
  each signal's autocorrelation and each take's level (the honest baseline: it asks
  whether the moment-to-moment coupling is real, beyond takes that are louder *and*
  livelier overall; its null rho can therefore be well above 0);
- categorical factors (emotion, speaker): one-way ANOVA of the take-mean energy
  across groups (one value per take, so takes are the independent units), its
  effect size eta^2, and a permutation p-value from shuffling the take labels.

Taught in notebooks/02_dataset_statistics.ipynb, section 5 (the correlation claims of §3.3).

:func:`window_means`, :func:`speed_by_emotion` and :func:`gesture_correlations` read their takes once,
in order, keeping a few numbers per window and per take: pass
:func:`beatlite.stats.corpus.iter_corpus` instead of a loaded list to stream over a large corpus
(:func:`plot_correlations` reads its takes twice: give it a list).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from beatlite.stats.corpus import CorpusTake
from beatlite.stats.distributions import EMOTION_NAMES


@dataclass
class CorrelationResult:
    """Spearman correlation with parametric and permutation p-values.

    Attributes
    ----------
    rho : float
    p_value : float
        scipy.stats.spearmanr (independence assumed).
    p_permutation : float
        ``(1 + #{|rho_null| >= |rho|}) / (1 + n_permutations)``, or the exact share of all shift
        combinations when there are no more than ``n_permutations`` (see :func:`correlation_test`).
    null_mean, null_std : float
        Mean and spread of rho under the permutation null.
    n : int
        Number of windows.
    """

    rho: float
    p_value: float
    p_permutation: float
    null_mean: float
    null_std: float
    n: int


@dataclass
class GroupEffectResult:
    """Effect of a categorical factor on per-take values.

    Attributes
    ----------
    f_stat, p_value : float
        One-way ANOVA (scipy.stats.f_oneway) across groups of take means.
    eta2 : float
        Between-group sum of squares / total sum of squares (0..1).
    p_permutation : float
        Permutation p-value of eta^2 under shuffled take labels.
    group_means : dict
        Label -> mean of the take values.
    n_takes : int
    """

    f_stat: float
    p_value: float
    eta2: float
    p_permutation: float
    group_means: dict
    n_takes: int


def _rank(x: np.ndarray) -> np.ndarray:
    from scipy.stats import rankdata

    return rankdata(x).astype(np.float64)


def _pearson(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pearson r of ``a`` (N,) with every row of ``b`` (..., N)."""
    a = a - a.mean()
    b = b - b.mean(axis=-1, keepdims=True)
    den = np.sqrt((a * a).sum() * (b * b).sum(axis=-1))
    return np.divide((b * a).sum(axis=-1), den, out=np.zeros(den.shape), where=den > 0)


def _group_shifts(size: np.ndarray, n_permutations: int, rng: np.random.Generator) -> tuple[np.ndarray, bool]:
    """Circular shifts (K, G) of G groups of ``size`` values, and whether they are every combination.

    When the groups allow at most ``n_permutations`` combinations of shifts, all of them, the identity
    included (the exact null: each counted once); else ``n_permutations`` random non-zero shifts per group.
    """
    if np.prod(size.astype(np.float64)) <= n_permutations:
        grids = np.meshgrid(*[np.arange(m) for m in size], indexing="ij")
        return np.stack([g.ravel() for g in grids], axis=1).astype(np.int64), True
    shifts = np.zeros((n_permutations, len(size)), dtype=np.int64)
    for k, m in enumerate(size):  # group by group, as the draws have always been made
        if m > 1:
            shifts[:, k] = rng.integers(1, m, size=n_permutations)
    return shifts, False


def correlation_test(
    x: np.ndarray,
    y: np.ndarray,
    *,
    groups: np.ndarray | None = None,
    n_permutations: int = 1000,
    seed: int = 0,
) -> CorrelationResult:
    """Spearman correlation of ``x`` and ``y`` with a within-group circular-shift permutation test.

    Parameters
    ----------
    x, y : (N,) float
        Paired values (e.g. window means), in time order within each group; all finite
        (``ValueError`` otherwise). When ``x`` or ``y`` is constant, rho is undefined: ``rho``,
        ``p_value`` and ``p_permutation`` are NaN.
    groups : (N,) int, optional
        Group (take) of each value; ``y`` is rolled by a random offset inside each group.
        Default: one group.
    n_permutations : int
        Number of shifted copies, made in blocks of about 2^20 values (memory does not grow as
        ``N * n_permutations``: 999 copies of BEAT's 76 h in 2-s windows would be 1 GB per array).
        When the groups allow no more combinations of shifts than this (a few short takes), every
        combination is used once, the identity included, and the p-value is exact.
    seed : int

    Returns
    -------
    CorrelationResult
        ``p_permutation`` is ``(1 + #{|rho_null| >= |rho|}) / (1 + n_permutations)`` over random shifts, or

        ``#{|rho_null| >= |rho|} / K`` over all K combinations of shifts (at least ``1 / K``).

    Examples
    --------
    Ranks 1 2 3 4 against 1 3 2 4: rho = 1 - 6 sum d^2 / (n (n^2 - 1)) = 1 - 6 * 2 / 60 = 0.8. Of the
    4 circular shifts of ``y`` (rho 0.8, -0.4, 0, -0.4) only the unshifted one reaches 0.8: p = 1/4.

    >>> r = correlation_test(np.array([1.0, 2, 3, 4]), np.array([1.0, 3, 2, 4]))
    >>> round(r.rho, 4), r.p_permutation, r.n
    (0.8, 0.25, 4)
    """
    from scipy.stats import spearmanr

    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if x.ndim != 1 or x.shape != y.shape or len(x) < 3:
        raise ValueError(
            f"correlation_test: x and y must be equal (N,) with N >= 3, got {x.shape} and {y.shape}"
        )
    for name, v in (("x", x), ("y", y)):
        if not np.isfinite(v).all():
            raise ValueError(f"correlation_test: {name} has {int(np.sum(~np.isfinite(v)))} non-finite values")
    g = np.zeros(len(x), np.int64) if groups is None else np.asarray(groups)
    if g.shape != x.shape:
        raise ValueError(f"correlation_test: groups must be {x.shape}, got {g.shape}")
    if np.ptp(x) == 0 or np.ptp(y) == 0:  # no rho, so no test (scipy would warn and give NaN)
        nan = float("nan")
        return CorrelationResult(
            rho=nan, p_value=nan, p_permutation=nan, null_mean=nan, null_std=nan, n=len(x)
        )
    res = spearmanr(x, y)
    rho = float(res.statistic)
    rx, ry = _rank(x), _rank(y)
    rng = np.random.default_rng(seed)
    order = np.argsort(g, kind="stable")  # positions group by group, in time order within each
    _, first, member, size = np.unique(g[order], return_index=True, return_inverse=True, return_counts=True)
    shifts, exact = _group_shifts(size, n_permutations, rng)
    start, m, r = first[member], size[member], np.arange(len(x)) - first[member]
    block = max(1, (1 << 20) // len(x))  # shifted copies at once: about 8 MB per (block, N) array
    null = np.empty(len(shifts))
    for b in range(0, len(shifts), block):
        perm = np.empty((min(block, len(shifts) - b), len(x)), dtype=np.int64)
        perm[:, order] = order[start + (r + shifts[b : b + block, member]) % m]
        null[b : b + len(perm)] = _pearson(rx, ry[perm])
    extreme = int(np.sum(np.abs(null) >= abs(rho) - 1e-12))
    p_perm = extreme / len(null) if exact else (1 + extreme) / (1 + n_permutations)
    return CorrelationResult(
        rho=rho,
        p_value=float(res.pvalue),
        p_permutation=float(p_perm),
        null_mean=float(null.mean()),
        null_std=float(null.std()),
        n=len(x),
    )


def _eta2(values: np.ndarray, labels: np.ndarray) -> float:
    total = ((values - values.mean()) ** 2).sum()
    if total == 0:
        return 0.0
    between = sum(
        (labels == c).sum() * (values[labels == c].mean() - values.mean()) ** 2 for c in np.unique(labels)
    )
    return float(between / total)


def group_effect_test(
    values: np.ndarray, labels: np.ndarray, *, n_permutations: int = 1000, seed: int = 0
) -> GroupEffectResult:
    """One-way ANOVA + eta^2 + label-permutation p-value of per-take ``values`` (N,) by ``labels`` (N,).

    Parameters
    ----------
    values : (N,) float
        One value per take (e.g. mean gesture speed, cm/s), all finite.
    labels : (N,)
        Group of each take (emotion id, speaker id, ...): at least 2 groups, one with 2 or more takes.
    n_permutations : int
        Label shuffles for ``p_permutation``.
    seed : int

    Returns
    -------
    GroupEffectResult

    Examples
    --------
    Two groups of three takes around 2 and 12: the squares about the grand mean 7 sum to 154, of which
    3 x 5^2 x 2 = 150 lie between the groups (eta^2 = 150/154), and F = (150 / 1) / (4 / 4) = 150.

    >>> r = group_effect_test(np.array([1.0, 2, 3, 11, 12, 13]), np.array(["a", "a", "a", "b", "b", "b"]))
    >>> round(r.eta2, 4), round(150 / 154, 4), round(r.f_stat, 6), r.group_means, r.n_takes
    (0.974, 0.974, 150.0, {'a': 2.0, 'b': 12.0}, 6)
    """
    from scipy.stats import f_oneway

    v = np.asarray(values, dtype=np.float64)
    lab = np.asarray(labels)
    if v.ndim != 1 or lab.shape != v.shape:
        raise ValueError(
            f"group_effect_test: values and labels must be equal (N,), got {v.shape} and {lab.shape}"
        )
    if not np.isfinite(v).all():
        raise ValueError(f"group_effect_test: values has {int(np.sum(~np.isfinite(v)))} non-finite values")
    classes = np.unique(lab)
    if len(classes) < 2 or len(classes) == len(v):
        raise ValueError(f"group_effect_test: need >= 2 groups and a group with >= 2 takes ({len(v)} takes)")
    res = f_oneway(*[v[lab == c] for c in classes])
    eta = _eta2(v, lab)
    rng = np.random.default_rng(seed)
    null = np.array([_eta2(v, rng.permutation(lab)) for _ in range(n_permutations)])
    p_perm = (1 + int(np.sum(null >= eta - 1e-12))) / (1 + n_permutations)
    return GroupEffectResult(
        f_stat=float(res.statistic),
        p_value=float(res.pvalue),
        eta2=eta,
        p_permutation=float(p_perm),
        group_means={c.item(): float(v[lab == c].mean()) for c in classes},
        n_takes=len(v),
    )


def window_means(takes: Iterable[CorpusTake], *, seconds: float = 2.0) -> dict[str, np.ndarray]:
    """Means of gesture speed, audio RMS and face activity over non-overlapping windows.

    Parameters
    ----------
    takes : iterable of CorpusTake
        Read once, in order.
    seconds : float
        Window length, seconds (``round(seconds * fps)`` frames); a take's last partial window is dropped.

    Returns
    -------
    dict with (N,) arrays ``speed`` (cm/s), ``audio`` (RMS), ``face`` (1/s, NaN without JSON),
    ``take`` (index into ``takes``), ``emotion``, ``speaker``.

    Examples
    --------
    A 5-frame take at 1 fps in 2-s windows: frames (0, 1) and (2, 3); frame 4 is a partial window.

    >>> from types import SimpleNamespace
    >>> take = SimpleNamespace(fps=1.0, n_frames=5, speed=np.array([0.0, 1, 2, 3, 4]), audio_rms=np.ones(5),
    ...                        face_activity=None, emotion=2, speaker_id=4)
    >>> wm = window_means([take], seconds=2.0)
    >>> wm["speed"].tolist(), wm["face"].tolist(), wm["take"].tolist(), wm["emotion"].tolist()
    ([0.5, 2.5], [nan, nan], [0, 0], [2, 2])
    """
    out: dict[str, list] = {k: [] for k in ("speed", "audio", "face", "take", "emotion", "speaker")}
    for i, t in enumerate(takes):
        length = max(1, int(round(seconds * t.fps)))
        n = t.n_frames // length
        if n == 0:
            continue
        cut = n * length
        out["speed"].append(t.speed[:cut].reshape(n, length).mean(axis=1))
        out["audio"].append(t.audio_rms[:cut].reshape(n, length).mean(axis=1))
        face = (
            np.full(n, np.nan)
            if t.face_activity is None
            else t.face_activity[:cut].reshape(n, length).mean(axis=1)
        )
        out["face"].append(face)
        out["take"].append(np.full(n, i))
        out["emotion"].append(np.full(n, t.emotion))
        out["speaker"].append(np.full(n, t.speaker_id))
    if not out["take"]:
        raise ValueError(f"window_means: no take is at least {seconds} s long")
    return {k: np.concatenate(v) for k, v in out.items()}


def speed_by_emotion(takes: Iterable[CorpusTake]) -> dict[str, float]:
    """Mean gesture speed (cm/s) of the frames of each emotion present in the takes.

    Each frame counts under its own emotion (``emotion_frames``: a speech take's from its name, a conversation's
    turn by turn).

    Returns
    -------
    dict
        Emotion name -> mean speed (cm/s), in emotion id order, emotions with frames only.

    Examples
    --------
    A conversation that turns angry halfway: (1 + 3) / 2 cm/s neutral, (10 + 20) / 2 angry.

    >>> from types import SimpleNamespace
    >>> take = SimpleNamespace(emotion_frames=np.array([0, 0, 2, 2]), speed=np.array([1.0, 3, 10, 20]))
    >>> speed_by_emotion([take])
    {'neutral': 2.0, 'anger': 15.0}
    """
    sums = np.zeros(len(EMOTION_NAMES))
    counts = np.zeros(len(EMOTION_NAMES), np.int64)
    for t in takes:
        frames = np.asarray(t.emotion_frames, np.int64)[: len(t.speed)]
        sums += np.bincount(
            frames, weights=np.asarray(t.speed[: len(frames)], np.float64), minlength=len(sums)
        )
        counts += np.bincount(frames, minlength=len(counts))
    return {EMOTION_NAMES[e]: float(sums[e] / counts[e]) for e in range(len(sums)) if counts[e] > 0}


def gesture_correlations(
    takes: Iterable[CorpusTake], *, seconds: float = 2.0, n_permutations: int = 1000, seed: int = 0
) -> dict[str, CorrelationResult | GroupEffectResult]:
    """Gesture energy vs audio energy, facial activity, emotion and speaker.

    Returns
    -------
    dict
        ``"audio"``, ``"face"``: :class:`CorrelationResult` over windows (face only when every
        take has a JSON); ``"emotion"``, ``"speaker"``: :class:`GroupEffectResult` over takes
        (speaker only with >= 2 speakers; emotion over self-talk takes only, with >= 2 emotions:
        a conversation take is neutral by its name but changes emotion turn by turn).

    Examples
    --------
    Two neutral 14.8-s takes of one speaker: 7 windows of 2 s each (14 in all), no emotion or speaker
    contrast to test. Each take has 7 circular shifts, so the exact null has 7 x 7 = 49 combinations
    and no p-value is below 1/49.

    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.stats.corpus import load_corpus
    >>> tmp = example_corpus()
    >>> takes = load_corpus(index_folder(tmp.name, cache=False))
    >>> res = gesture_correlations(takes)
    >>> list(res), res["audio"].n, bool(res["audio"].p_permutation >= 1 / 49)
    (['audio', 'face'], 14, True)
    >>> tmp.cleanup()
    """
    per_take: list[tuple[float, int, int | None, bool]] = []  # speed, emotion, speaker, conversation
    wm = window_means(_noting_takes(takes, per_take), seconds=seconds)
    out: dict[str, CorrelationResult | GroupEffectResult] = {
        "audio": correlation_test(
            wm["speed"], wm["audio"], groups=wm["take"], n_permutations=n_permutations, seed=seed
        )
    }
    if not np.any(np.isnan(wm["face"])):
        out["face"] = correlation_test(
            wm["speed"], wm["face"], groups=wm["take"], n_permutations=n_permutations, seed=seed
        )
    take_speed = np.array([speed for speed, _, _, _ in per_take])
    emotions = np.array([emotion for _, emotion, _, _ in per_take])
    speakers = np.array([speaker for _, _, speaker, _ in per_take])
    speech = ~np.array([conversation for _, _, _, conversation in per_take], dtype=bool)
    if len(np.unique(emotions[speech])) >= 2:
        out["emotion"] = group_effect_test(
            take_speed[speech], emotions[speech], n_permutations=n_permutations, seed=seed
        )
    if len(np.unique(speakers)) >= 2:
        out["speaker"] = group_effect_test(take_speed, speakers, n_permutations=n_permutations, seed=seed)
    return out


def _noting_takes(takes: Iterable[CorpusTake], notes: list) -> Iterator[CorpusTake]:
    """``takes`` unchanged, appending (mean speed, emotion, speaker id, conversation) of each to ``notes``."""
    for t in takes:
        notes.append((float(np.mean(t.speed)), t.emotion, t.speaker_id, t.conversation))
        yield t


def correlations_markdown(results: dict[str, CorrelationResult | GroupEffectResult]) -> str:
    """A Markdown table of :func:`gesture_correlations` results: a header, a rule, one row per result.

    Examples
    --------
    >>> r = CorrelationResult(rho=0.8, p_value=0.2, p_permutation=0.25, null_mean=0.0, null_std=0.49, n=4)
    >>> print(correlations_markdown({"audio": r}))
    | gesture energy vs | statistic | p (parametric) | p (permutation) | null |
    |---|---|---|---|---|
    | audio | Spearman rho = 0.800 (n=4 windows) | 0.2 | 0.25 | rho +0.000 +- 0.490 |
    """
    lines = [
        "| gesture energy vs | statistic | p (parametric) | p (permutation) | null |",
        "|---|---|---|---|---|",
    ]
    for name, r in results.items():
        if isinstance(r, CorrelationResult):
            lines.append(
                f"| {name} | Spearman rho = {r.rho:.3f} (n={r.n} windows) | {r.p_value:.2g} | "
                f"{r.p_permutation:.3g} | rho {r.null_mean:+.3f} +- {r.null_std:.3f} |"
            )
        else:
            lines.append(
                f"| {name} | eta^2 = {r.eta2:.3f}, F = {r.f_stat:.2f} (n={r.n_takes} takes) | {r.p_value:.2g} | "
                f"{r.p_permutation:.3g} | shuffled take labels |"
            )
    return "\n".join(lines)


def plot_correlations(
    takes: Sequence[CorpusTake],
    *,
    seconds: float = 2.0,
    out: str | Path | None = None,
    formats: tuple[str, ...] = ("png", "svg"),
):
    """Three panels: gesture energy vs audio energy, vs facial activity (windows), and per emotion (takes).

    Takes without facial data get no facial-activity panel (two panels, none empty).

    Parameters
    ----------
    takes : sequence of CorpusTake
        Read twice (give a list).
    seconds : float
        Window length of the scatter panels, seconds.
    out : str or Path, optional
        Path stem to save the figure to with :func:`beatlite.viz.style.save_figure`.
    formats : tuple of str
        Formats to save.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Two takes with facial data: three panels, 2 x 7 two-second windows in each scatter.

    >>> import matplotlib.pyplot as plt
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.stats.corpus import load_corpus
    >>> tmp = example_corpus()
    >>> takes = load_corpus(index_folder(tmp.name, cache=False))
    >>> fig = plot_correlations(takes)
    >>> len(fig.axes), len(fig.axes[0].collections[0].get_offsets())
    (3, 14)
    >>> plt.close(fig)
    >>> tmp.cleanup()
    """
    import matplotlib.pyplot as plt

    from beatlite.viz.style import SYSTEM_COLOURS, figure_style, save_figure

    wm = window_means(takes, seconds=seconds)
    speeds = speed_by_emotion(takes)
    has_face = not np.any(np.isnan(wm["face"]))
    with figure_style():
        n = 3 if has_face else 2  # no facial data (no .json): no empty panel for it
        fig, axes = plt.subplots(1, n, figsize=(13 * n / 3, 4.2), layout="constrained")
        axes[0].scatter(wm["audio"], wm["speed"], s=6, alpha=0.5, color=SYSTEM_COLOURS[0])
        axes[0].set_xlabel(f"audio RMS (full scale, {seconds:g}-s window mean)")
        axes[0].set_ylabel("gesture speed (cm/s)")
        axes[0].set_title("gesture vs audio energy")
        if has_face:
            axes[1].scatter(wm["face"], wm["speed"], s=6, alpha=0.5, color=SYSTEM_COLOURS[0])
            axes[1].set_xlabel(f"facial activity (1/s, {seconds:g}-s window mean)")
            axes[1].set_ylabel("gesture speed (cm/s)")
            axes[1].set_title("gesture vs facial activity")
        axes[-1].bar(list(speeds), list(speeds.values()), color=SYSTEM_COLOURS[0])
        axes[-1].set_xlabel("emotion")
        axes[-1].set_ylabel("mean gesture speed (cm/s)")
        axes[-1].set_title("gesture energy per emotion")
        axes[-1].tick_params(axis="x", rotation=45)
        if out is not None:
            save_figure(fig, out, formats)
    return fig
