"""The multi-panel figures of the data and metrics notebooks (00-04): corpus, annotations, onsets, spreads.

Single curves over time and single waveforms have one home, :mod:`beatlite.viz.charts`
(:func:`~beatlite.viz.charts.plot_signals`, :func:`~beatlite.viz.charts.plot_waveform`); this module
holds the figures those cannot draw (several panels, several marker kinds per curve, bars by split).

Every function draws one figure in the beatlite style (:func:`beatlite.viz.style.figure_style`),
with units on every axis and legends outside the data, optionally saves it
(``out=`` path stem, :func:`beatlite.viz.style.save_figure`) and returns it.

===============================  ===========================================================
:func:`plot_corpus_overview`     minutes per speaker and split, minutes per emotion (00)
:func:`plot_transcript`          waveform, word and phone tiers of a TextGrid (01)
:func:`plot_annotations`         emotion segments, semantic scores and their 15-fps frames (01)
:func:`plot_onsets`              waveform and onset strength with detected onsets (03)
:func:`plot_beat_curves`         audio onsets, speed minima and HA2G angle-change beats (04)
:func:`plot_spread`              box plots of SRGR and L1 diversity per system (04, BEAT Fig. 6)
===============================  ===========================================================

Taught in notebooks/00_setup_and_tour.ipynb to notebooks/04_metrics.ipynb (their figures).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from beatlite.viz.style import figure_style, save_figure

#: Colours of audio onsets, word onsets and motion beats across the figures.
ONSET_COLOUR, WORD_COLOUR, BEAT_COLOUR = "#c44e52", "#4c72b0", "#55a868"
_OUTSIDE = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0}


def _finish(fig: Any, out: str | Path | None) -> Any:
    fig.tight_layout()
    if out is not None:
        save_figure(fig, out)
    return fig


def plot_corpus_overview(index: Any, *, out: str | Path | None = None):
    """Two panels: minutes per speaker stacked by split, and minutes per take-level emotion.

    Parameters
    ----------
    index : TakeIndex
        :func:`beatlite.data.index.index_folder`'s table; its usable takes are counted (durations in seconds,
        drawn in minutes).
    out : str or Path, optional
        Also save the figure there: a path stem, written as ``.png`` and ``.svg``
        (:func:`beatlite.viz.style.save_figure`).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Three takes made by hand (what :func:`~beatlite.data.index.index_folder` reads from a folder): speaker 2 has
    2 minutes of train and 1 of validation, speaker 4 half a minute of test, so the stacked bars read
    (train, val, test) = (2, 0) (0, 1) and (0, 0.5) minutes for (scott, lawrence):

    >>> import matplotlib.pyplot as plt
    >>> from beatlite.data.index import TakeIndex, TakeRecord
    >>> def take(stem, speaker_id, split, emotion, seconds):
    ...     files = {"motion": Path(stem + ".bvh"), "audio": Path(stem + ".wav")}
    ...     return TakeRecord(stem, speaker_id=speaker_id, speaker=stem.split("_")[1], split=split,
    ...                       emotion_name=emotion, files=files, durations={"motion": seconds, "audio": seconds})
    >>> index = TakeIndex([take("2_scott_0_1_1", 2, "train", "neutral", 120.0),
    ...                    take("2_scott_0_2_2", 2, "val", "neutral", 60.0),
    ...                    take("4_lawrence_0_65_65", 4, "test", "happiness", 30.0)])
    >>> fig = plot_corpus_overview(index)
    >>> by_split, by_emotion = fig.axes
    >>> [t.get_text() for t in by_split.get_xticklabels()], [float(b.get_height()) for b in by_split.patches]
    (['2_scott', '4_lawrence'], [2.0, 0.0, 1.0, 0.0, 0.0, 0.5])
    >>> [float(b.get_width()) for b in by_emotion.patches][:2]  # neutral, happiness
    [3.0, 0.5]
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    from beatlite.io import EMOTIONS

    usable = index.where(usable=True)
    speakers = sorted({(r.speaker_id, r.speaker) for r in usable}, key=lambda s: (s[0] is None, s[0] or 0))
    with figure_style():
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.2))
        bottom = np.zeros(len(speakers))
        for split in ("train", "val", "test"):
            values = np.array(
                [usable.where(speaker_id=s, split=split).total_duration / 60 for s, _ in speakers]
            )
            ax1.bar([f"{s}_{n}" for s, n in speakers], values, bottom=bottom, label=split)
            bottom += values
        ax1.set_ylabel("minutes")
        ax1.set_title("duration per speaker and split")
        ax1.legend(**_OUTSIDE)
        names = list(EMOTIONS)
        ax2.barh(names, [usable.where(emotion_name=e).total_duration / 60 for e in names], color="#8172b3")
        ax2.invert_yaxis()
        ax2.set_xlabel("minutes (take-level emotion)")
        ax2.set_title("duration per emotion")
        return _finish(fig, out)


def plot_transcript(
    audio: np.ndarray,
    sr: int,
    tiers: Mapping[str, Sequence[Any]],
    *,
    t_end: float = 4.0,
    out: str | Path | None = None,
):
    """The waveform above the ``words`` and ``phones`` tiers of a TextGrid (intervals with text shaded).

    Parameters
    ----------
    audio : (N,) float, [-1, 1]
        Mono waveform.
    sr : int
        Sample rate of ``audio``, Hz.
    tiers : mapping tier name -> intervals with ``start``, ``end`` (s) and ``text``
        :func:`beatlite.io.read_textgrid`'s result; ``words`` and ``phones`` are drawn.
    t_end : float
        Seconds shown, from 0.
    out : str or Path, optional
        Also save the figure there: a path stem, written as ``.png`` and ``.svg``
        (:func:`beatlite.viz.style.save_figure`).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Only the intervals with text are shaded and written (the pause between the words is not):

    >>> import matplotlib.pyplot as plt
    >>> from beatlite.io.textgrid import Interval
    >>> tiers = {"words": [Interval(0.0, 0.5, "hello"), Interval(0.5, 0.7, ""), Interval(0.7, 1.2, "world")],
    ...          "phones": [Interval(0.0, 0.2, "HH"), Interval(0.2, 0.5, "AH")]}
    >>> fig = plot_transcript(np.zeros(2 * 16000), 16000, tiers, t_end=2.0)
    >>> [[t.get_text() for t in ax.texts] for ax in fig.axes[1:]], [float(x) for x in fig.axes[2].get_xlim()]
    ([['hello', 'world'], ['HH', 'AH']], [0.0, 2.0])
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    y = np.asarray(audio, dtype=np.float64)[: int(t_end * sr)]
    with figure_style():
        fig, axes = plt.subplots(
            3, 1, figsize=(9, 3.4), sharex=True, gridspec_kw={"height_ratios": [2, 1, 1]}
        )
        axes[0].plot(np.arange(len(y)) / sr, y, lw=0.4, color="0.35")
        axes[0].set_ylabel("amplitude")
        for ax, tier, colour, size in ((axes[1], "words", WORD_COLOUR, 7), (axes[2], "phones", "#dd8452", 6)):
            for iv in tiers.get(tier, ()):
                if iv.start >= t_end:
                    break
                if iv.text.strip():
                    ax.axvspan(iv.start, iv.end, color=colour, alpha=0.25, ec="white")
                    ax.text((iv.start + iv.end) / 2, 0.5, iv.text, ha="center", va="center", fontsize=size)
            ax.set_yticks([])
            ax.grid(False)
            ax.set_ylabel(tier, rotation=0, ha="right", va="center")
        axes[2].set_xlim(0, t_end)
        axes[2].set_xlabel("time (s)")
        return _finish(fig, out)


def plot_annotations(
    emotions: Sequence[Any],
    semantic: Sequence[Any],
    semantic_frames: np.ndarray,
    fps: float,
    duration: float,
    *,
    out: str | Path | None = None,
):
    """Emotion segments, semantic segments (score, coloured by gesture type) and the per-frame score.

    A segment's bar is as high as its score, so a type whose segments all score 0 (``00_nogesture``) draws
    nothing: it is left out of the legend (its spans are the gaps between bars) unless no segment scores.
    Each drawn type has a colour of its own: tab10's hues for up to 10 types (BEAT's scoring ones), tab20's 20
    colours for more (``habit`` and ``need_cut`` besides them).

    Parameters
    ----------
    emotions : sequence of EmotionSegment
        ``start``, ``end`` (s), ``name``, ``emotion`` (id 0..7).
    semantic : sequence of SemanticSegment
        ``start``, ``end`` (s), ``score`` in [0, 1], ``type``.
    semantic_frames : (T,) float
        The per-frame scores at ``fps`` (:func:`beatlite.io.semantic_to_frames`).
    fps, duration : float
        Frame rate and take length (s).
    out : str or Path, optional
        Also save the figure there: a path stem, written as ``.png`` and ``.svg``
        (:func:`beatlite.viz.style.save_figure`).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    A beat gesture scoring 0.5 and a deictic one scoring 1 around a pause (``00_nogesture``, score 0: no bar, no
    legend entry); the bars are as high as the scores:

    >>> import matplotlib.pyplot as plt
    >>> from beatlite.io import EmotionSegment, SemanticSegment, semantic_to_frames
    >>> semantic = [SemanticSegment("01_beat_align", 0.2, 0.6, 0.4, 0.5),
    ...             SemanticSegment("00_nogesture", 0.6, 1.0, 0.4, 0.0),
    ...             SemanticSegment("02_deictic_l", 1.0, 1.6, 0.6, 1.0)]
    >>> frames = semantic_to_frames(semantic, 30, 15)  # 2 s at 15 fps
    >>> fig = plot_annotations([EmotionSegment("neutral", 0.0, 2.0, 2.0, 0)], semantic, frames, 15, 2.0)
    >>> scores = fig.axes[1]
    >>> [t.get_text() for t in scores.get_legend().get_texts()], [float(b.get_height()) for b in scores.patches]
    (['01_beat_align', '02_deictic_l'], [0.5, 1.0])
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    drawn = [seg for seg in semantic if seg.score > 0] or list(semantic)  # the segments that draw a bar
    types = sorted({seg.type for seg in drawn})
    # one hue each: tab10 for BEAT's 10 scoring types, tab20 when more are drawn (``habit``, ``need_cut``)
    cmap = plt.cm.tab10 if len(types) <= 10 else plt.cm.tab20
    type_colour = {name: cmap(i % cmap.N) for i, name in enumerate(types)}
    with figure_style():
        fig, axes = plt.subplots(
            3, 1, figsize=(10, 3.8), sharex=True, gridspec_kw={"height_ratios": [1, 2, 1.5]}
        )
        for seg in emotions:
            axes[0].axvspan(seg.start, seg.end, color=plt.cm.Set2(seg.emotion % 8))
            axes[0].text((seg.start + seg.end) / 2, 0.5, seg.name, ha="center", va="center", fontsize=8)
        axes[0].set_yticks([])
        axes[0].grid(False)
        axes[0].set_ylabel("emotion", rotation=0, ha="right", va="center")
        for seg in drawn:
            axes[1].bar(seg.start, seg.score, width=seg.end - seg.start, align="edge",
                        color=type_colour[seg.type], ec="white", lw=0.3)  # fmt: skip
        axes[1].set_ylabel("score\n(segments)")
        handles = [plt.Rectangle((0, 0), 1, 1, color=type_colour[name]) for name in types]
        axes[1].legend(handles, types, fontsize=7, title="gesture type", title_fontsize=8, **_OUTSIDE)
        axes[2].step(np.arange(len(semantic_frames)) / fps, semantic_frames, where="post", lw=1)
        axes[2].set_ylabel(f"score\n({fps:g} fps)")
        axes[2].set_xlabel("time (s)")
        axes[2].set_xlim(0, duration)
        return _finish(fig, out)


def plot_onsets(
    audio: np.ndarray,
    sr: int,
    onsets: np.ndarray,
    *,
    onsets_librosa: np.ndarray | None = None,
    word_starts: np.ndarray | None = None,
    hop_length: int = 512,
    t_end: float = 6.0,
    out: str | Path | None = None,
):
    """Two panels: the waveform with audio and word onsets, and librosa's onset strength with the picks.

    Parameters
    ----------
    audio : (N,) float, [-1, 1]
        Mono waveform.
    sr : int
        Sample rate of ``audio``, Hz.
    onsets : (A,) float, seconds
        beatlite's peak picking (:func:`beatlite.metrics.audio_beats`).
    onsets_librosa : (B,) float, optional
        librosa's default peak picking.
    word_starts : (W,) float, optional
        Word onsets of the TextGrid.
    hop_length : int
        Hop of the onset strength (512).
    t_end : float
        Seconds shown, from 0.
    out : str or Path, optional
        Also save the figure there: a path stem, written as ``.png`` and ``.svg``
        (:func:`beatlite.viz.style.save_figure`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import librosa
    import matplotlib.pyplot as plt

    y = np.asarray(audio, dtype=np.float32)
    strength = librosa.onset.onset_strength(y=y, sr=sr, hop_length=hop_length)
    t_strength = librosa.times_like(strength, sr=sr, hop_length=hop_length)
    n = int(t_end * sr)
    with figure_style():
        fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(10, 3.8), sharex=True)
        ax0.plot(np.arange(min(n, len(y))) / sr, y[:n], lw=0.3, color="0.45")
        ax0.vlines(onsets, -1, 1, color=ONSET_COLOUR, lw=1, label="audio onsets (beatlite)")
        if word_starts is not None:
            ax0.vlines(word_starts, -1, -0.6, color=WORD_COLOUR, lw=2, label="word onsets (TextGrid)")
        ax0.set_ylim(-1, 1)
        ax0.set_ylabel("amplitude")
        ax0.legend(**_OUTSIDE)
        ax1.plot(t_strength, strength, lw=0.8, color="0.2", label="onset strength")
        if onsets_librosa is not None:
            ax1.plot(onsets_librosa, np.interp(onsets_librosa, t_strength, strength), "x", ms=5,
                     color="#dd8452", label="onsets (librosa defaults)")  # fmt: skip
        ax1.plot(onsets, np.interp(onsets, t_strength, strength), "o", ms=5, mfc="none", color=ONSET_COLOUR,
                 label="onsets (beatlite)")  # fmt: skip
        ax1.set_ylabel("spectral flux\n(dB per frame)")
        ax1.set_xlim(0, t_end)
        ax1.set_xlabel("time (s)")
        ax1.legend(**_OUTSIDE)
        return _finish(fig, out)


def plot_beat_curves(
    audio: np.ndarray,
    sr: int,
    onsets: np.ndarray,
    curves: Mapping[str, tuple[np.ndarray, np.ndarray, str]],
    fps: float,
    *,
    t_range: tuple[float, float] = (0.0, 6.0),
    out: str | Path | None = None,
):
    """The waveform with its onsets above motion curves with their beats; onsets drawn across all panels.

    Parameters
    ----------
    audio : (N,) float, [-1, 1]
        Mono waveform.
    sr : int
        Sample rate of ``audio``, Hz.
    onsets : (A,) float, seconds
    curves : mapping label -> (curve (T,), beat times (K,) s, y label with units)
        One panel each, e.g. ``{"right wrist speed": (speed, minima, "cm/s")}``.
    fps : float
        Frame rate of the curves.
    t_range : (float, float)
        Seconds shown (start it at the speech to keep a swing before it from setting the scale).
    out : str or Path, optional
        Also save the figure there: a path stem, written as ``.png`` and ``.svg``
        (:func:`beatlite.viz.style.save_figure`).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    A wrist speed that falls to 0 every second (at 0.5 s, 1.5 s, ...) and peaks at 40 cm/s: the motion beats
    are drawn on the curve, the scale tops at ``1.1 * 40`` and the onset at 7 s, outside the 6 s shown, draws
    no line:

    >>> import matplotlib.pyplot as plt
    >>> t = np.arange(90) / 15
    >>> speed = np.abs(t % 1.0 - 0.5) * 80
    >>> curves = {"right wrist speed": (speed, [0.5, 1.5, 2.5, 3.5, 4.5, 5.5], "speed (cm/s)")}
    >>> fig = plot_beat_curves(np.zeros(6 * 16000), 16000, [1.0, 2.0, 7.0], curves, 15)
    >>> [ax.get_ylabel() for ax in fig.axes], round(float(fig.axes[1].get_ylim()[1]), 3)
    (['amplitude', 'speed (cm/s)'], 44.0)
    >>> sorted({float(line.get_xdata()[0]) for line in fig.axes[1].lines if len(line.get_xdata()) == 2})
    [1.0, 2.0]
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    t0, t_end = max(0.0, float(t_range[0])), float(t_range[1])
    y = np.asarray(audio)[: int(t_end * sr)]
    onsets = np.asarray(onsets, dtype=np.float64).reshape(-1)
    with figure_style():
        fig, axes = plt.subplots(1 + len(curves), 1, figsize=(10, 1.6 + 1.5 * len(curves)), sharex=True)
        axes[0].plot(np.arange(len(y)) / sr, y, lw=0.3, color="0.5")
        axes[0].set_ylabel("amplitude")
        axes[0].set_ylim(-1, 1)
        axes[0].plot([], [], color=ONSET_COLOUR, lw=1, label="audio onsets")
        axes[0].legend(**_OUTSIDE)
        for k, (ax, (label, (curve, beats, unit))) in enumerate(zip(axes[1:], curves.items())):
            c = np.asarray(curve)
            t = np.arange(len(c)) / fps
            ax.plot(t, c, lw=1, color=f"C{k + 1}", label=label)
            b = np.asarray(beats)
            ax.plot(b, np.interp(b, t, c), "v", ms=5, color=BEAT_COLOUR, label="motion beats")
            shown = c[(t >= t0) & (t <= t_end)]
            if shown.size:  # the scale of the shown window only
                ax.set_ylim(min(0.0, float(shown.min())), 1.1 * float(shown.max()) + 1e-9)
            ax.set_ylabel(unit)
            ax.legend(**_OUTSIDE)
        for ax in axes:
            for t in onsets[(onsets >= t0) & (onsets < t_end)]:
                ax.axvline(t, color=ONSET_COLOUR, lw=0.6, alpha=0.6)
        axes[-1].set_xlim(t0, t_end)
        axes[-1].set_xlabel("time (s)")
        return _finish(fig, out)


def plot_spread(
    spread: Mapping[str, tuple[np.ndarray, np.ndarray]],
    *,
    titles: tuple[str, str] = ("SRGR (paper, 10 cm)", "L1 diversity (degrees)"),
    out: str | Path | None = None,
):
    """Box plots of two metrics per system across evaluation subsets (BEAT Fig. 6 analog).

    Parameters
    ----------
    spread : mapping system -> (values of metric 1, values of metric 2)
        E.g. :func:`beatlite.metrics.perturb.subset_spread` per system.
    titles : (str, str)
        Panel titles, with units.
    out : str or Path, optional
        Also save the figure there: a path stem, written as ``.png`` and ``.svg``
        (:func:`beatlite.viz.style.save_figure`).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    One box per system and metric; a box's middle line is the median of the subsets' values:

    >>> import matplotlib.pyplot as plt
    >>> spread = {"Ground truth": ([0.20, 0.25, 0.30], [10.0, 11.0, 12.0]),
    ...           "CaMN": ([0.1, 0.2, 0.3], [8.0, 9.0, 10.0])}
    >>> fig = plot_spread(spread)
    >>> srgr = fig.axes[0]
    >>> [t.get_text() for t in srgr.get_xticklabels()], srgr.get_ylabel(), fig.axes[1].get_ylabel()
    (['Ground truth', 'CaMN'], 'SRGR per subset', 'L1 diversity per subset')
    >>> medians = fig.axes[1].lines[5::6]  # each box draws 6 lines: box, 2 whiskers, 2 caps, median
    >>> [float(line.get_ydata()[0]) for line in medians]
    [11.0, 9.0]
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    names = list(spread)
    with figure_style():
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.4))
        for i, (ax, title) in enumerate(zip(axes, titles)):
            ax.boxplot([spread[n][i] for n in names], showfliers=False)
            ax.set_xticks(range(1, len(names) + 1), names, rotation=30, ha="right")
            ax.set_title(title)
            ax.set_ylabel(title.split(" (")[0] + " per subset")
        return _finish(fig, out)
