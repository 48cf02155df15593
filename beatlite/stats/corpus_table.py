"""Table 1 analog: one row describing the indexed corpus, beside the BEAT paper's rows.

The paper's rows are copied from Table 1 of Liu et al., "BEAT: A Large-Scale
Semantic and Emotional Multi-Modal Dataset for Conversational Gestures
Synthesis", ECCV 2022 (``/work/shared/papers/beat_camn_eccv2022.txt``).

Taught in notebooks/02_dataset_statistics.ipynb, section 1 (Table 1: what kind of dataset is this?).
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from beatlite.data.index import TakeIndex

#: Columns of Table 1, in the paper's order.
TABLE1_COLUMNS = (
    "dataset",
    "quality",
    "body",
    "hand",
    "face",
    "audio",
    "text",
    "speakers",
    "emotions",
    "semantic",
    "sequences",
    "duration",
)

#: BEAT paper, Table 1 ("Comparison of Datasets"), as published. "-" = not available.
PAPER_TABLE1: tuple[dict[str, Any], ...] = (
    {"dataset": "TED [52]", "quality": "pseudo label", "body": "9", "hand": "-", "face": "-", "audio": "En",
     "text": "yes", "speakers": ">100", "emotions": "-", "semantic": "-", "sequences": "1400", "duration": "97h"},
    {"dataset": "S2G [20,21]", "quality": "pseudo label", "body": "14", "hand": "42", "face": "2D LM",
     "audio": "En", "text": "-", "speakers": "6", "emotions": "-", "semantic": "-", "sequences": "N/A",
     "duration": "33h"},
    {"dataset": "MPI [47]", "quality": "mo-cap", "body": "23", "hand": "-", "face": "-", "audio": "-",
     "text": "yes", "speakers": "1", "emotions": "11", "semantic": "-", "sequences": "1408", "duration": "1.5h"},
    {"dataset": "VOCA [16]", "quality": "mo-cap", "body": "-", "hand": "-", "face": "3D Mesh", "audio": "En",
     "text": "-", "speakers": "12", "emotions": "-", "semantic": "-", "sequences": "480", "duration": "0.5h"},
    {"dataset": "Takechi [46]", "quality": "mo-cap", "body": "24", "hand": "38", "face": "-", "audio": "Jp",
     "text": "-", "speakers": "2", "emotions": "-", "semantic": "-", "sequences": "1049", "duration": "5h"},
    {"dataset": "Trinity [17]", "quality": "mo-cap", "body": "24", "hand": "38", "face": "-", "audio": "En",
     "text": "yes", "speakers": "1", "emotions": "-", "semantic": "-", "sequences": "23", "duration": "4h"},
    {"dataset": "BEAT (Ours)", "quality": "mo-cap", "body": "27", "hand": "48", "face": "3D BSW",
     "audio": "E/C/S/J", "text": "yes", "speakers": "30", "emotions": "8", "semantic": "yes",
     "sequences": "2508", "duration": "76h"},
)  # fmt: skip

_LANGUAGE_CODES = {"english": "E", "chinese": "C", "spanish": "S", "japanese": "J"}


def _face_dims(index: TakeIndex) -> int | None:
    from beatlite.io.textfile import open_text

    for r in index:
        if r.usable and "face" in r.files:
            try:
                with open_text(r.files["face"]) as f:
                    return len(json.load(f)["names"])
            except (OSError, ValueError, KeyError, TypeError):
                continue
    return None


def _joint_counts(index: TakeIndex) -> tuple[int, int] | None:
    """(body, hand) joint counts of the first readable BVH header; hand = joints named ``*Hand*``."""
    from beatlite.io import read_bvh_header

    for r in index:
        if r.usable:
            try:
                skeleton, _, _ = read_bvh_header(r.files["motion"])
            except (OSError, ValueError):
                continue
            hand = sum("Hand" in name for name in skeleton.names)
            return skeleton.n_joints - hand, hand
    return None


def corpus_row(
    index: TakeIndex, *, name: str = "beatlite corpus", quality: str = "synthetic"
) -> dict[str, Any]:
    """The Table 1 row of the usable takes of ``index``.

    Counts joints as the paper does (BEAT: 27 body + 48 hand = 75; "hand" = joints whose
    name contains ``Hand``), face dims from the first JSON's ``names``, emotions from the
    take names, duration = sum of motion durations in hours.

    Parameters
    ----------
    index : TakeIndex
    name : str
        Row label.
    quality : str
        The "quality" cell ("synthetic" for ``data_samples/``, "mo-cap" for real BEAT).

    Returns
    -------
    dict with the keys of :data:`TABLE1_COLUMNS` (strings, as in the paper's table) plus
    numeric ``n_speakers``, ``n_sequences``, ``hours``, ``n_body``, ``n_hand``, ``n_face``,
    ``n_emotions``, ``languages`` (list).

    Examples
    --------
    Two 14.8-s takes of one English speaker on BEAT's skeleton (27 body + 48 hand joints, as the paper's
    row) with 51 blendshapes: 29.6 s = 0.0082 h.

    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> tmp = example_corpus()
    >>> row = corpus_row(index_folder(tmp.name, cache=False))
    >>> row["body"], row["hand"], row["face"], row["audio"], row["speakers"], row["sequences"]
    ('27', '48', '51 BSW', 'E', '1', '2')
    >>> round(row["hours"] * 3600, 3), row["duration"]
    (29.6, '0.01h')
    >>> tmp.cleanup()
    """
    usable = index.where(usable=True)
    joints = _joint_counts(usable)
    counts = {
        "n_speakers": len(usable.speaker_ids()),
        "n_sequences": len(usable),
        "hours": usable.total_duration / 3600.0,
        "n_body": None if joints is None else joints[0],
        "n_hand": None if joints is None else joints[1],
        "n_face": _face_dims(usable),
        "n_emotions": len({r.emotion for r in usable if r.emotion is not None}),
        "languages": sorted({r.language for r in usable if r.language}, key=list(_LANGUAGE_CODES).index),
    }
    has = {kind: any(kind in r.files for r in usable) for kind in ("text", "semantic")}
    return {**_table1_cells(name, quality, counts, has), **counts}


def _table1_cells(name: str, quality: str, counts: dict[str, Any], has: dict[str, bool]) -> dict[str, str]:
    """The string cells of :data:`TABLE1_COLUMNS` from :func:`corpus_row`'s numeric ``counts``
    ("-" where a modality is absent); ``has`` says whether any take has ``text`` / ``semantic`` files."""
    return {
        "dataset": name,
        "quality": quality,
        "body": "-" if counts["n_body"] is None else str(counts["n_body"]),
        "hand": "-" if counts["n_hand"] is None else str(counts["n_hand"]),
        "face": "-" if counts["n_face"] is None else f"{counts['n_face']} BSW",
        "audio": "/".join(_LANGUAGE_CODES[lang] for lang in counts["languages"]) or "-",
        "text": "yes" if has["text"] else "-",
        "speakers": str(counts["n_speakers"]),
        "emotions": str(counts["n_emotions"]) if counts["n_emotions"] else "-",
        "semantic": "yes" if has["semantic"] else "-",
        "sequences": str(counts["n_sequences"]),
        "duration": f"{counts['hours']:.2f}h",
    }


def table1(
    index: TakeIndex, *, name: str = "beatlite corpus", quality: str = "synthetic"
) -> list[dict[str, Any]]:
    """The paper's Table 1 rows followed by the corpus row (string cells of :data:`TABLE1_COLUMNS`).

    Parameters
    ----------
    index : TakeIndex
    name, quality : str
        The corpus row's "dataset" and "quality" cells (see :func:`corpus_row`).

    Returns
    -------
    list of dict
        ``len(PAPER_TABLE1) + 1`` rows, each with exactly the keys of :data:`TABLE1_COLUMNS`.

    Examples
    --------
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> tmp = example_corpus()
    >>> rows = table1(index_folder(tmp.name, cache=False), name="two takes")
    >>> len(rows) == len(PAPER_TABLE1) + 1, [r["dataset"] for r in rows[-2:]]
    (True, ['BEAT (Ours)', 'two takes'])
    >>> tuple(rows[-1]) == TABLE1_COLUMNS
    True
    >>> tmp.cleanup()
    """
    row = corpus_row(index, name=name, quality=quality)
    return [dict(r) for r in PAPER_TABLE1] + [{k: row[k] for k in TABLE1_COLUMNS}]


def table1_markdown(index: TakeIndex, *, name: str = "beatlite corpus", quality: str = "synthetic") -> str:
    """:func:`table1` as a Markdown table (the last row is the corpus).

    Parameters
    ----------
    index : TakeIndex
    name, quality : str
        The corpus row's "dataset" and "quality" cells (see :func:`corpus_row`).

    Returns
    -------
    str
        A header line, a ``|---|`` line, then one line per row of :func:`table1`.

    Examples
    --------
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> tmp = example_corpus()
    >>> lines = table1_markdown(index_folder(tmp.name, cache=False)).splitlines()
    >>> len(lines) == 2 + len(PAPER_TABLE1) + 1
    True
    >>> lines[-1]
    '| beatlite corpus | synthetic | 27 | 48 | 51 BSW | E | yes | 1 | 1 | yes | 2 | 0.01h |'
    >>> tmp.cleanup()
    """
    rows = table1(index, name=name, quality=quality)
    lines = ["| " + " | ".join(TABLE1_COLUMNS) + " |", "|" + "|".join("---" for _ in TABLE1_COLUMNS) + "|"]
    lines += ["| " + " | ".join(str(r[c]) for c in TABLE1_COLUMNS) + " |" for r in rows]
    return "\n".join(lines)
