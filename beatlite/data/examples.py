"""Small example corpora for docstring Examples and quick experiments (as ``librosa.ex`` gives example audio).

:func:`example_corpus` copies a few takes of the shipped ``data_samples/`` into a temporary folder, so an Example
can index, window or build a store without writing into the repository.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from beatlite.paths import repo_root

if TYPE_CHECKING:
    from beatlite.data.index import TakeIndex

#: The default takes: test take ``2_scott_0_1_1`` (222 frames) and train take ``2_scott_0_9_9``.
DEFAULT_PATTERN = "2_scott_0_[19]_[19]"


def example_corpus(pattern: str = DEFAULT_PATTERN) -> tempfile.TemporaryDirectory:
    """A temporary copy of the ``data_samples/`` takes whose stems match the glob ``pattern``.

    Returns
    -------
    tempfile.TemporaryDirectory
        ``.name`` is the folder (every file of each matching take: ``.bvh.gz``, ``.wav``, ``.json.gz``, ...);
        ``.cleanup()`` removes it (so does the end of the process).

    Examples
    --------
    >>> tmp = example_corpus()
    >>> from pathlib import Path
    >>> sorted(p.name for p in Path(tmp.name).glob("*.wav"))
    ['2_scott_0_1_1.wav', '2_scott_0_9_9.wav']
    >>> tmp.cleanup()
    """
    tmp = tempfile.TemporaryDirectory(prefix="beatlite_example_")
    for path in sorted((repo_root() / "data_samples").glob(f"{pattern}.*")):
        shutil.copy(path, tmp.name)
    return tmp


def example_index(seconds: dict[str, float]) -> TakeIndex:
    """A :class:`~beatlite.data.index.TakeIndex` of BEAT takes named by ``{stem: seconds of motion}``.

    Every field comes from the take's name (:func:`beatlite.data.index.index_take`); the takes' ``.bvh`` and
    ``.wav`` files are listed, never read, so the names need not exist: for Examples of corpus statistics.

    Examples
    --------
    >>> index = example_index({"2_scott_0_1_1": 45.0, "10_kieks_1_2_2": 30.0})
    >>> [(r.speaker, r.language, r.durations["motion"]) for r in index]
    [('scott', 'english', 45.0), ('kieks', 'english', 30.0)]
    """
    from beatlite.data.index import TakeIndex, index_take

    records = []
    for stem, duration in seconds.items():
        files = {"motion": [Path(f"{stem}.bvh")], "audio": [Path(f"{stem}.wav")]}
        record = index_take(stem, files, read_durations=False)
        record.durations["motion"] = float(duration)
        records.append(record)
    return TakeIndex(records)


def example_beat2_corpus(pattern: str = DEFAULT_PATTERN) -> tempfile.TemporaryDirectory:
    """The takes of :func:`example_corpus` in BEAT2's layout (:func:`beatlite.data.beat2.write_beat2_folder`).

    Returns
    -------
    tempfile.TemporaryDirectory
        ``.name`` is a BEAT2 root: ``smplxflame_30/{stem}.npz`` (30 fps SMPL-X retargeted from the BVH; zero
        ``betas`` and ``expressions``), ``wave16k/``, ``textgrid/``, ``train_test_split.csv``.

    Examples
    --------
    >>> tmp = example_beat2_corpus()
    >>> from pathlib import Path
    >>> (Path(tmp.name) / "train_test_split.csv").read_text().splitlines()
    ['id,type', '2_scott_0_1_1,test', '2_scott_0_9_9,train']
    >>> tmp.cleanup()
    """
    from beatlite.data.beat2 import write_beat2_folder

    src = example_corpus(pattern)
    tmp = tempfile.TemporaryDirectory(prefix="beatlite_beat2_")
    write_beat2_folder(src.name, tmp.name)
    src.cleanup()
    return tmp
