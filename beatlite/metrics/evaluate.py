"""One call that computes every metric beatlite knows, with its variant and parameters.

Usage (skipped by the doctests: ``gen_positions``, ``audio``, ... stand for your own arrays):

>>> report = evaluate(gen_positions, gt_positions, audio=audio, semantic=sem)  # doctest: +SKIP
>>> print(report.to_markdown())  # doctest: +SKIP

Each metric is computed only when its inputs are given (FGD and Diversity need windows and an
extractor, SRGR needs semantic scores, BeatAlign and BC need audio, ...); ``skipped`` lists
the others with the reason.

Not used by the notebooks: notebooks/04_metrics.ipynb, section 5 calls each metric itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from beatlite.metrics._checks import as_array, as_list
from beatlite.metrics.beat_align import beat_align
from beatlite.metrics.beat_consistency import beat_consistency, default_angle_pairs, prepare_directions
from beatlite.metrics.beats import mean_angle_change
from beatlite.metrics.diversity import diversity, l1_diversity
from beatlite.metrics.extras import jerk_stats, mpjpe, pck, velocity_stats
from beatlite.metrics.fgd import Extractor, fgd
from beatlite.metrics.srgr import srgr


@dataclass(frozen=True)
class MetricResult:
    """One metric value.

    Attributes
    ----------
    name : str
        E.g. ``"FGD"``, ``"SRGR"``, ``"BeatAlign"``.
    value : float
    variant : str
        Which definition, e.g. ``"paper"``, ``"reference"``, ``"HA2G"``.
    params : dict
        The parameters that change the value (sigma, delta, window, ...).
    higher_is_better : bool or None
        ``None`` for descriptive statistics.
    """

    name: str
    value: float
    variant: str
    params: dict[str, Any] = field(default_factory=dict)
    higher_is_better: bool | None = None


@dataclass
class Evaluation:
    """The results of :func:`evaluate`: ``results`` plus ``skipped`` ``{metric: reason}``."""

    results: list[MetricResult]
    skipped: dict[str, str] = field(default_factory=dict)

    def get(self, name: str, variant: str | None = None) -> MetricResult:
        """The first result called ``name`` (and ``variant`` if given); ``KeyError`` otherwise."""
        for r in self.results:
            if r.name == name and (variant is None or r.variant == variant):
                return r
        have = sorted({f"{r.name}/{r.variant}" for r in self.results})
        raise KeyError(f"no metric {name!r}{'' if variant is None else '/' + variant}; have {have}")

    def as_dict(self) -> dict[str, float]:
        """``{"name/variant": value}``."""
        return {f"{r.name}/{r.variant}": r.value for r in self.results}

    def to_markdown(self) -> str:
        """A Markdown table: metric, variant, value, better direction, parameters."""
        lines = ["| metric | variant | value | better | parameters |", "|---|---|---|---|---|"]
        for r in self.results:
            better = {True: "higher", False: "lower", None: ""}[r.higher_is_better]
            params = ", ".join(f"{k}={_fmt(v)}" for k, v in r.params.items())
            lines.append(f"| {r.name} | {r.variant} | {_fmt(r.value)} | {better} | {params} |")
        for name, why in self.skipped.items():
            lines.append(f"| {name} | — | skipped | | {why} |")
        return "\n".join(lines)


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, tuple):
        return "(" + ", ".join(_fmt(x) for x in v) + ")"
    return str(v)


def evaluate(
    generated: np.ndarray | list[np.ndarray],
    ground_truth: np.ndarray | list[np.ndarray],
    *,
    fps: float = 15.0,
    audio: np.ndarray | list[np.ndarray] | None = None,
    sr: int = 16000,
    semantic: np.ndarray | list[np.ndarray] | None = None,
    extractor: Extractor | None = None,
    generated_windows: np.ndarray | None = None,
    real_windows: np.ndarray | None = None,
    generated_euler: np.ndarray | list[np.ndarray] | None = None,
    ground_truth_euler: np.ndarray | list[np.ndarray] | None = None,
    generated_directions: np.ndarray | list[np.ndarray] | None = None,
    ground_truth_directions: np.ndarray | list[np.ndarray] | None = None,
    beat_joints: list[int] | np.ndarray | None = None,
    srgr_delta: float = 10.0,
    pck_delta: float = 10.0,
    seed: int = 0,
) -> Evaluation:
    """Every metric for generated vs ground-truth motion.

    Parameters
    ----------
    generated, ground_truth : (T, J, 3) float or list of such, centimetres
        Joint positions of each take (same shapes pairwise). With J = 43 (TED-43) or 75
        (BEAT, converted by ``beatlite.skeleton.ted.beat_to_ted43``), BC directions are
        derived from them unless given.
    fps : float
        Motion frame rate.
    audio : (N,) float or list, optional
        Speech at ``sr``, aligned with the motion -> BeatAlign, BC.
    semantic : (T,) float or list, optional
        Ground-truth semantic scores in [0, 1] -> SRGR (paper; reference too with Euler).
    extractor : callable, optional
        Windows (N, 34, D) -> features (N, F), e.g. ``load_extractor()``.
    generated_windows, real_windows : (N, 34, D), (M, 34, D) float, optional
        Windows in the extractor's space -> FGD and HA2G Diversity.
    generated_euler, ground_truth_euler : (T, C) float or list, degrees, optional
        Euler channels (141-d) -> reference SRGR, reference BeatAlign, L1div (reference, windowed).
    generated_directions, ground_truth_directions : (T, 42, 3) or list, optional
        TED bone directions -> BC (MAAC from the ground truth).
    beat_joints : (K,) int, optional
        Joints used by the positions BeatAlign (default all).
    srgr_delta, pck_delta : float
        Thresholds in cm.
    seed : int
        Seed of the Diversity pairing.

    Returns
    -------
    Evaluation
    """
    gens, many = as_list(generated, "generated")
    gts, many_t = as_list(ground_truth, "ground_truth")
    if many != many_t or len(gens) != len(gts):
        raise ValueError(f"generated and ground_truth must pair up, got {len(gens)} and {len(gts)} takes")
    gens = [as_array(g, f"generated[{i}]", ndim=3, last=3) for i, g in enumerate(gens)]
    gts = [as_array(g, f"ground_truth[{i}]", ndim=3, last=3) for i, g in enumerate(gts)]
    for i, (g, t) in enumerate(zip(gens, gts)):
        if g.shape != t.shape:
            raise ValueError(f"take {i}: generated {g.shape} and ground_truth {t.shape} differ")
    audios = None if audio is None else _listed(audio, len(gens), "audio")
    sems = None if semantic is None else _listed(semantic, len(gens), "semantic")
    res: list[MetricResult] = []
    skipped: dict[str, str] = {}

    # FGD / Diversity ---------------------------------------------------------------
    if extractor is not None and generated_windows is not None and real_windows is not None:
        fg = np.asarray(extractor(as_array(generated_windows, "generated_windows", ndim=3)), dtype=np.float64)
        fr = np.asarray(extractor(as_array(real_windows, "real_windows", ndim=3)), dtype=np.float64)
        feat = {"windows": (len(fg), len(fr)), "features": fg.shape[1]}
        res.append(MetricResult("FGD", fgd(fg, fr), "stable", feat, False))
        res.append(MetricResult("FGD", fgd(fg, fr, reference=True), "reference (sqrtm)", feat, False))
        res.append(MetricResult("Diversity", diversity(fg, n_pairs=500, seed=seed), "HA2G (clip pairs)",
                                {"n_pairs": 500, "seed": seed}, True))  # fmt: skip
    else:
        skipped["FGD"] = skipped["Diversity"] = "needs extractor, generated_windows and real_windows"

    # SRGR / PCK -----------------------------------------------------------------------
    if sems is not None:
        res.append(MetricResult("SRGR", srgr(gens, gts, sems, variant="paper", delta=srgr_delta), "paper",
                                {"delta_cm": srgr_delta}, True))  # fmt: skip
        if generated_euler is not None and ground_truth_euler is not None:
            ge = _listed(generated_euler, len(gens), "generated_euler")
            te = _listed(ground_truth_euler, len(gens), "ground_truth_euler")
            res.append(MetricResult("SRGR", srgr(ge, te, sems, variant="reference"), "reference",
                                    {"threshold_deg": 4.0, "normaliser": 0.165}, True))  # fmt: skip
    else:
        skipped["SRGR"] = "needs semantic"
    res.append(
        MetricResult("PCK", _mean_over(pck, gens, gts, pck_delta), "positions", {"delta_cm": pck_delta}, True)
    )
    res.append(MetricResult("MPJPE", _mean_over(mpjpe, gens, gts), "positions", {"unit": "cm"}, False))

    # BeatAlign / BC ---------------------------------------------------------------------
    if audios is not None:
        ba = beat_align(audios, sr, gens, fps, sigma=0.3, joints=beat_joints)
        ba_gt = beat_align(audios, sr, gts, fps, sigma=0.3, joints=beat_joints)
        params = {"sigma_s": 0.3, "order": 2, "direction": "audio_to_motion"}
        res.append(MetricResult("BeatAlign", ba, "positions", params, True))
        res.append(MetricResult("BeatAlign", ba_gt, "positions, ground truth", params, True))
        if generated_euler is not None:
            ge = _listed(generated_euler, len(gens), "generated_euler")
            res.append(MetricResult("BeatAlign", beat_align(audios, sr, ge, fps, legacy=True), "reference",
                                    {"sigma_s": 0.3, "columns": "36:39", "window_s": (10.0, 500.0),
                                     "legacy_sr": True}, True))  # fmt: skip
        gdirs, tdirs, why = _directions(gens, gts, generated_directions, ground_truth_directions)
        if gdirs is not None:
            pairs = default_angle_pairs()
            ca = mean_angle_change([prepare_directions(d) for d in tdirs], pairs)
            bc = beat_consistency(audios, sr, gdirs, fps, sigma=0.1, pairs=pairs, change_angle=ca)
            res.append(MetricResult("BC", bc, "HA2G (whole takes)",
                                    {"sigma_s": 0.1, "threshold": 0.03, "maac": "ground truth"}, True))  # fmt: skip
        else:
            skipped["BC"] = why
    else:
        skipped["BeatAlign"] = skipped["BC"] = "needs audio"

    # Diversity of the motion itself, extras ----------------------------------------------
    res.append(MetricResult("L1div", l1_diversity(gens), "positions", {"unit": "cm summed over 3J"}, True))
    if generated_euler is not None:
        ge = _listed(generated_euler, len(gens), "generated_euler")
        res.append(MetricResult("L1div", l1_diversity(ge, windowed=True), "reference (windowed)",
                                {"unit": "degrees summed over C", "length": 34, "stride": 10}, True))  # fmt: skip
    vel = [velocity_stats(g, fps)["mean"] for g in gens]
    jerk = [jerk_stats(g, fps)["mean"] for g in gens if g.shape[0] >= 4]
    res.append(MetricResult("speed", float(np.mean(vel)), "mean", {"unit": "cm/s"}, None))
    if jerk:
        res.append(MetricResult("jerk", float(np.mean(jerk)), "mean", {"unit": "cm/s^3"}, None))
    return Evaluation(res, skipped)


def _listed(x, n: int, name: str) -> list:
    items, _ = as_list(x, name)
    if len(items) != n:
        raise ValueError(f"{name} has {len(items)} takes but generated has {n}")
    return items


def _mean_over(fn, gens, gts, *args) -> float:
    frames = np.array([g.shape[0] for g in gens], dtype=np.float64)
    vals = np.array([fn(g, t, *args) for g, t in zip(gens, gts)])
    return float((vals * frames).sum() / frames.sum())


def _directions(gens, gts, gdirs, tdirs):
    if gdirs is not None and tdirs is not None:
        return (
            _listed(gdirs, len(gens), "generated_directions"),
            _listed(tdirs, len(gens), "ground_truth_directions"),
            "",
        )
    j = gens[0].shape[1]
    if j not in (43, 75):
        return None, None, f"needs TED directions (positions have {j} joints, not 43 or 75)"
    try:
        from beatlite.skeleton.directions import positions_to_directions
        from beatlite.skeleton.ted import TED_BONES, beat_to_ted43
    except ImportError as exc:  # pragma: no cover - module written in parallel
        return None, None, f"beatlite.skeleton.ted unavailable ({exc})"

    def conv(p: np.ndarray) -> np.ndarray:
        q = beat_to_ted43(p) if p.shape[1] == 75 else p
        return positions_to_directions(q, np.asarray(TED_BONES))

    return [conv(g) for g in gens], [conv(t) for t in gts], ""
