"""Figure 2 analogs: emotion proportions, language share, per-speaker duration (from the index only).

Shares are fractions of the summed take durations (seconds of motion), not of take counts.

Taught in notebooks/02_dataset_statistics.ipynb, section 2 (Figure 2: emotions, languages and speakers).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from beatlite.data.index import TakeIndex, TakeRecord

EMOTION_NAMES = ("neutral", "happiness", "anger", "sadness", "contempt", "surprise", "fear", "disgust")

#: BEAT paper Sec. 3.1 / Fig. 2c: of the 120 self-talk questions 64 are neutral and each of the
#: other seven emotions has 8, i.e. the designed emotion shares of the self-talk session.
PAPER_EMOTION_SHARES: dict[str, float] = {
    name: (64 / 120 if name == "neutral" else 8 / 120) for name in EMOTION_NAMES
}
#: BEAT paper Sec. 3.1 / Fig. 2d: hours per language. The text prints "60h (81%)", but 60 of these
#: 76 hours is 78.9 %; beatlite shows the share computed from the hours (:func:`paper_language_shares`).
PAPER_LANGUAGE_HOURS: dict[str, float] = {"english": 60.0, "chinese": 12.0, "spanish": 2.0, "japanese": 2.0}


def paper_language_shares() -> dict[str, float]:
    """Fig. 2d of the paper as fractions: each language's hours / the 76 h total (English 0.789).

    The one computation of the paper's language shares (tables and plots use it).

    >>> round(paper_language_shares()["english"], 3)
    0.789
    """
    total = sum(PAPER_LANGUAGE_HOURS.values())
    return {k: v / total for k, v in PAPER_LANGUAGE_HOURS.items()}


def speaker_split_table(index: TakeIndex, *, splits: tuple[str, ...] | None = None) -> str:
    """Markdown table: takes and minutes per speaker and split, with a total row.

    Parameters
    ----------
    index : TakeIndex
        Usable takes count (durations from the headers).
    splits : tuple of str, optional
        Columns, in order (default: the splits present, in :data:`beatlite.io.names.SPLITS` order; BEAT's
        1-hour speakers add ``"test+val"`` and ``"none"`` to train, val and test).

    Returns
    -------
    str
        Columns ``speaker``, ``<split> takes`` ..., ``<split> min`` ... (minutes with 1 decimal).

    Examples
    --------
    BEAT's names give the split (sequence 1 of a speech session is a test take, a conversation's is
    train): speaker 2 has a 60-s train take and two 30-s test takes, speaker 10 one 30-s test take.

    >>> from beatlite.data.examples import example_index  # the files are listed, never read
    >>> index = example_index({"2_scott_1_2_2": 60.0, "2_scott_0_1_1": 30.0, "2_scott_0_73_73": 30.0,
    ...                        "10_kieks_0_1_1": 30.0})
    >>> print(speaker_split_table(index))
    | speaker | train takes | test takes | train min | test min |
    |---|---|---|---|---|
    | 2_scott | 1 | 2 | 1.0 | 1.0 |
    | 10_kieks | 0 | 1 | 0.0 | 0.5 |
    | **all** | 1 | 3 | 1.0 | 1.5 |
    """
    from beatlite.io.names import SPLITS
    from beatlite.report import markdown_table

    usable = index.where(usable=True)
    if splits is None:
        splits = tuple(s for s in SPLITS if len(usable.where(split=s)))
    speakers = sorted({(r.speaker_id, r.speaker) for r in usable}, key=lambda s: (s[0] is None, s[0] or 0))
    rows = []
    for label, sub in [(f"{sid}_{name}", usable.where(speaker_id=sid)) for sid, name in speakers] + [
        ("**all**", usable)
    ]:
        counts = [len(sub.where(split=s)) for s in splits]
        rows.append([label, *counts, *[sub.where(split=s).total_duration / 60 for s in splits]])
    header = ["speaker", *[f"{s} takes" for s in splits], *[f"{s} min" for s in splits]]
    return markdown_table(header, rows, digits=1)


def _shares(index: TakeIndex, key: Callable[[TakeRecord], Any], *, normalise: bool) -> dict[Any, float]:
    totals: dict[Any, float] = {}
    for r in index:
        if not r.usable:
            continue
        k = key(r)
        totals[k] = totals.get(k, 0.0) + r.duration
    if not normalise:
        return totals
    total = sum(totals.values())
    if total <= 0:
        raise ValueError(f"no usable take with a positive duration in the index ({len(index)} takes)")
    return {k: v / total for k, v in totals.items()}


def emotion_shares(index: TakeIndex, *, speech_only: bool = True) -> dict[str, float]:
    """Fraction of the duration per emotion, all 8 emotions in id order (0 for absent ones).

    Parameters
    ----------
    index : TakeIndex
    speech_only : bool
        Count self-talk (speech) takes only, as the paper's Fig. 2c does (conversations are
        all neutral).

    Returns
    -------
    dict
        Emotion name (:data:`EMOTION_NAMES`) -> fraction of the seconds, summing to 1.

    Examples
    --------
    45 s of neutral speech (sequence 1), 15 s of angry speech (sequence 73) and a 60-s conversation:
    the speech is 45/60 neutral; with the conversation, (45 + 60)/120.

    >>> from beatlite.data.examples import example_index  # the files are listed, never read
    >>> index = example_index({"2_scott_0_1_1": 45.0, "2_scott_0_73_73": 15.0, "2_scott_1_2_2": 60.0})
    >>> shares = emotion_shares(index)
    >>> shares["neutral"], shares["anger"], shares["sadness"]
    (0.75, 0.25, 0.0)
    >>> emotion_shares(index, speech_only=False)["neutral"]
    0.875
    """
    chosen = index.where(conversation=False) if speech_only else index
    shares = _shares(chosen, lambda r: r.emotion, normalise=True)
    return {name: shares.get(i, 0.0) for i, name in enumerate(EMOTION_NAMES)}


def language_shares(index: TakeIndex) -> dict[str, float]:
    """Fraction of the duration per language (languages present only).

    Returns
    -------
    dict
        Language (``"english"``, ``"chinese"``, ``"spanish"``, ``"japanese"``) -> fraction of the
        seconds, largest first, summing to 1.

    Examples
    --------
    The session type of a BEAT name gives the language (0, 1 English; 2, 3 Chinese): 90 s against 30 s.

    >>> from beatlite.data.examples import example_index  # the files are listed, never read
    >>> index = example_index({"2_scott_0_1_1": 90.0, "12_zhao_2_1_1": 30.0})
    >>> language_shares(index)
    {'english': 0.75, 'chinese': 0.25}
    """
    return dict(sorted(_shares(index, lambda r: r.language, normalise=True).items(), key=lambda kv: -kv[1]))


def speaker_durations(index: TakeIndex) -> dict[str, float]:
    """Seconds of usable takes per speaker, keyed ``"{id}_{name}"``, in speaker id order.

    Examples
    --------
    >>> from beatlite.data.examples import example_index  # the files are listed, never read
    >>> index = example_index({"10_kieks_0_1_1": 30.0, "2_scott_0_1_1": 45.0, "2_scott_0_73_73": 15.0})
    >>> speaker_durations(index)
    {'2_scott': 60.0, '10_kieks': 30.0}
    """
    totals = _shares(index, lambda r: (r.speaker_id, r.speaker), normalise=False)
    return {f"{sid}_{name}": v for (sid, name), v in sorted(totals.items())}


def _paired_bars(ax, names: list[str], ours: list[float], paper: dict[str, float]) -> None:
    """Bars of this corpus's shares beside the paper's (both in %), names on the x axis."""
    import numpy as np

    x = np.arange(len(names))
    ax.bar(x - 0.2, [100 * v for v in ours], 0.4, label="this corpus", color="#333333")
    ax.bar(x + 0.2, [100 * paper[n] for n in names], 0.4, label="BEAT (paper)", color="#9ecae1")
    ax.set_xticks(x, names, rotation=45, ha="right")


def plot_figure2(
    index: TakeIndex, *, out: str | Path | None = None, formats: tuple[str, ...] = ("png", "svg")
):
    """Three panels: emotion shares (corpus vs the paper's design), language share, minutes per speaker.

    BEAT (ECCV 2022) Fig. 2 (c)-(e). One legend above the panels, units on every
    axis, the style of :mod:`beatlite.viz.style`.

    Parameters
    ----------
    index : TakeIndex
    out : str or Path, optional
        Path stem to save the figure to (``out.png``, ``out.svg``) with
        :func:`beatlite.viz.style.save_figure`.
    formats : tuple of str
        Formats to save.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    The left panel's two bar series are this corpus's and the paper's 8 emotion shares.

    >>> from beatlite.data.examples import example_index  # the files are listed, never read
    >>> import matplotlib.pyplot as plt
    >>> fig = plot_figure2(example_index({"2_scott_0_1_1": 45.0, "2_scott_0_73_73": 15.0}))
    >>> len(fig.axes), len(fig.axes[0].patches)
    (3, 16)
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    from beatlite.viz.style import SYSTEM_COLOURS, figure_style, save_figure

    emo = emotion_shares(index)
    lang = language_shares(index)
    spk = speaker_durations(index)
    paper_total = sum(PAPER_LANGUAGE_HOURS.values())
    with figure_style():
        fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), layout="constrained")
        _paired_bars(axes[0], EMOTION_NAMES, [emo[n] for n in EMOTION_NAMES], PAPER_EMOTION_SHARES)
        axes[0].set_ylabel("share of self-talk duration (%)")
        axes[0].set_xlabel("emotion")
        axes[0].set_title("(c) emotions")
        paper_lang = {n: h / paper_total for n, h in PAPER_LANGUAGE_HOURS.items()}
        _paired_bars(axes[1], list(paper_lang), [lang.get(n, 0.0) for n in paper_lang], paper_lang)
        axes[1].set_ylabel("share of duration (%)")
        axes[1].set_xlabel("language")
        axes[1].set_title("(d) languages")
        axes[2].bar(list(spk), [v / 60 for v in spk.values()], color=SYSTEM_COLOURS[0])
        axes[2].set_ylabel("duration (min)")
        axes[2].set_xlabel("speaker")
        axes[2].set_title("(e) duration per speaker")
        axes[2].tick_params(axis="x", rotation=45)
        fig.legend(*axes[0].get_legend_handles_labels(), loc="outside upper center", ncols=2)
        if out is not None:
            save_figure(fig, out, formats)
    return fig
