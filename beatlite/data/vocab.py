"""Word vocabulary and offline word vectors from the corpus transcripts.

The reference (BEAT ``build_vocab.py``, docs/reference_code.md#vocabulary) indexes every word of the
train + val + test TextGrids after the special tokens PAD=0, SOS=1, EOS=2,
UNK=3, and gives each word its 300-d FastText ``cc.en.300.bin`` vector. That
file is 7 GB and needs a download, so beatlite *learns* vectors from the
corpus itself instead: a PPMI word-word co-occurrence matrix (symmetric
window) factorised by truncated SVD (:func:`word_vectors`). This is
deterministic, offline and takes well under a second on ``data_samples/``;
unlike FastText it knows only the corpus's words (no sub-word information,
no vectors for unseen words, much weaker semantics on a small corpus). If you
have a FastText ``.vec`` text file offline, :func:`read_vec_file` maps it onto
a :class:`Vocab` instead.

Taught in notebooks/03_audio_and_text_features.ipynb, sections 6 (words to frames: three rules) and 7 (the vocabulary and word vectors).
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from beatlite.data.index import TakeIndex

PAD, SOS, EOS, UNK = 0, 1, 2, 3
SPECIAL_TOKENS = ("<pad>", "<sos>", "<eos>", "<unk>")
_STRIP = ' \t,.?!;:"()[]{}'
#: Vocabularies up to this size use an exact dense SVD; larger ones scikit-learn's randomized one.
DENSE_SVD_MAX = 3000


def normalize_word(word: str) -> str:
    """Lower-case ``word`` and strip surrounding punctuation/quotes (``"Hello,"`` -> ``"hello"``).

    Internal apostrophes and hyphens stay (``"don't"``). Returns ``""`` for silence marks.

    Examples
    --------
    >>> normalize_word('"Hello,"'), normalize_word("Don't"), normalize_word("")
    ('hello', "don't", '')
    """
    return word.strip(_STRIP).lower()


def _checked_words(words: Sequence[str]) -> list[str]:
    """``words`` normalised (:func:`normalize_word`); ``TypeError`` for a single str, ``ValueError`` for
    an empty word, duplicates or a special token."""
    if isinstance(words, str):
        raise TypeError("Vocab: words must be a sequence of str, got a single str")
    normalised = [normalize_word(w) for w in words]
    if "" in normalised:
        raise ValueError("Vocab: empty word (after normalisation) in words")
    counts = Counter(normalised)
    dupes = [w for w, c in counts.items() if c > 1]
    if dupes:
        raise ValueError(f"Vocab: duplicate words after normalisation: {dupes[:5]}")
    clash = [w for w in normalised if w in SPECIAL_TOKENS]
    if clash:
        raise ValueError(f"Vocab: words clash with special tokens: {clash}")
    return normalised


class Vocab(Mapping[str, int]):
    """Word <-> id table with PAD=0, SOS=1, EOS=2, UNK=3.

    A read-only ``Mapping[str, int]`` (``vocab["hello"]`` raises ``KeyError`` for an
    unknown word, ``vocab.get(w, UNK)`` or :meth:`id` return UNK), so it can be passed
    as the ``vocab`` of :func:`beatlite.io.words_to_frames`.

    Parameters
    ----------
    words : sequence of str
        The ordinary words, in id order; they get ids 4, 5, ... Words are stored
        normalised (:func:`normalize_word`); duplicates and empty strings are rejected.

    Examples
    --------
    >>> v = Vocab(["hello", "world"])
    >>> v.id("Hello,"), v.id("unseen"), len(v)
    (4, 3, 6)
    >>> v.decode([4, 5])
    ['hello', 'world']
    """

    def __init__(self, words: Sequence[str]) -> None:
        normalised = _checked_words(words)
        self.itos: tuple[str, ...] = (*SPECIAL_TOKENS, *normalised)
        self._stoi = {w: i for i, w in enumerate(self.itos)}

    # Mapping interface ------------------------------------------------------
    def __getitem__(self, word: str) -> int:
        return self._stoi[normalize_word(word) if word not in self._stoi else word]

    def __iter__(self) -> Iterator[str]:
        return iter(self.itos)

    def __len__(self) -> int:
        return len(self.itos)

    def __contains__(self, word: object) -> bool:
        return isinstance(word, str) and (word in self._stoi or normalize_word(word) in self._stoi)

    def __repr__(self) -> str:
        preview = ", ".join(self.itos[4:9])
        return f"Vocab({len(self)} tokens: {preview}{', ...' if len(self) > 9 else ''})"

    # lookups ----------------------------------------------------------------
    def id(self, word: str) -> int:
        """Id of ``word`` (normalised); PAD for an empty/silence mark, UNK if unknown."""
        w = normalize_word(word)
        if not w:
            return PAD
        return self._stoi.get(w, UNK)

    def encode(self, words: Iterable[str]) -> np.ndarray:
        """(W,) int64 ids of ``words`` (see :meth:`id`)."""
        return np.array([self.id(w) for w in words], dtype=np.int64)

    def decode(self, ids: Iterable[int]) -> list[str]:
        """Words of ``ids``; ``IndexError`` naming the id when out of range."""
        out = []
        for i in ids:
            i = int(i)
            if not 0 <= i < len(self.itos):
                raise IndexError(f"Vocab.decode: id {i} not in [0, {len(self.itos)})")
            out.append(self.itos[i])
        return out

    @property
    def words(self) -> tuple[str, ...]:
        """The ordinary words (ids 4...), in id order."""
        return self.itos[4:]

    # persistence --------------------------------------------------------------
    def save(self, path: str | Path) -> None:
        """Write the vocabulary as JSON ``{"words": [...]}`` (atomic)."""
        from beatlite.io.atomic import atomic_write

        with atomic_write(path) as f:
            json.dump({"special": list(SPECIAL_TOKENS), "words": list(self.words)}, f, indent=0)

    @classmethod
    def load(cls, path: str | Path) -> Vocab:
        """Read a vocabulary written by :meth:`save`; ``FormatError`` if the file is not one."""
        from beatlite.io.errors import FormatError

        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except json.JSONDecodeError as e:
            raise FormatError(path, f"invalid JSON: {e.msg}", line=e.lineno, column=e.colno) from None
        if not isinstance(data, dict) or not isinstance(data.get("words"), list):
            raise FormatError(path, "expected an object with a 'words' list", field="words")
        return cls(data["words"])


def take_sentences(index: TakeIndex, *, splits: Iterable[str] | None = None) -> list[list[str]]:
    """The normalised word sequence of every take's TextGrid (tier ``words``), in index order.

    Takes without a TextGrid are skipped. Silence marks (``""``) are dropped.

    Parameters
    ----------
    index : TakeIndex
        Indexed corpus.
    splits : iterable of str, optional
        Only takes of these splits (default: all, as the reference does).

    Examples
    --------
    >>> from beatlite.data.index import TakeIndex, index_take
    >>> from beatlite.paths import repo_root
    >>> record = index_take("2_scott_0_1_1", {"text": [repo_root() / "data_samples" / "2_scott_0_1_1.TextGrid"]})
    >>> sentences = take_sentences(TakeIndex([record]))
    >>> len(sentences), sentences[0][:4]
    (1, ['my', 'idea', 'is', 'to'])
    """
    from beatlite.io import read_words

    wanted = None if splits is None else set(splits)
    sentences = []
    for record in index:
        if "text" not in record.files or (wanted is not None and record.split not in wanted):
            continue
        words = read_words(record.files["text"])
        sentence = [normalize_word(w) for w in words.words]
        sentences.append([w for w in sentence if w])
    return sentences


def vocab_from_sentences(sentences: Iterable[Iterable[str]], *, min_count: int = 1) -> Vocab:
    """Build a :class:`Vocab` from token lists: words by decreasing count, ties alphabetical.

    Parameters
    ----------
    sentences : iterable of iterable of str
        Words (normalised here).
    min_count : int
        Keep words seen at least this many times (others map to UNK).

    Examples
    --------
    >>> vocab = vocab_from_sentences([["The", "cat"], ["the", "dog"]])
    >>> vocab.itos  # special tokens, then words by count, ties alphabetical
    ('<pad>', '<sos>', '<eos>', '<unk>', 'the', 'cat', 'dog')
    >>> vocab.encode(["the", "bird"])  # unknown words map to UNK
    array([4, 3])
    """
    if min_count < 1:
        raise ValueError(f"vocab_from_sentences: min_count must be >= 1, got {min_count}")
    counts: Counter[str] = Counter()
    for sentence in sentences:
        counts.update(w for w in (normalize_word(t) for t in sentence) if w and w not in SPECIAL_TOKENS)
    kept = sorted((w for w, c in counts.items() if c >= min_count), key=lambda w: (-counts[w], w))
    return Vocab(kept)


def build_vocab(index: TakeIndex, *, splits: Iterable[str] | None = None, min_count: int = 1) -> Vocab:
    """The vocabulary of the corpus TextGrids (all splits by default, as BEAT's ``build_vocab.py``).

    Parameters
    ----------
    index : TakeIndex
        Indexed corpus (takes with a ``.TextGrid``).
    splits : iterable of str, optional
        Restrict to these splits.
    min_count : int
        Minimum count of a word (default 1).

    Examples
    --------
    >>> from beatlite.data.index import TakeIndex, index_take
    >>> from beatlite.paths import repo_root
    >>> record = index_take("2_scott_0_1_1", {"text": [repo_root() / "data_samples" / "2_scott_0_1_1.TextGrid"]})
    >>> vocab = build_vocab(TakeIndex([record]))
    >>> vocab.itos[:4], "idea" in vocab
    (('<pad>', '<sos>', '<eos>', '<unk>'), True)
    """
    return vocab_from_sentences(take_sentences(index, splits=splits), min_count=min_count)


def corpus_vocab(index: TakeIndex) -> Vocab:
    """The vocabulary ``fit``, the window store and the evaluation set use by default: :func:`build_vocab` of the
    index's usable takes (an unusable take's TextGrid may not read; its words feed no window).

    Examples
    --------
    >>> from beatlite.data.index import TakeIndex, index_take
    >>> from beatlite.paths import repo_root
    >>> record = index_take("2_scott_0_1_1", {"text": [repo_root() / "data_samples" / "2_scott_0_1_1.TextGrid"]})
    >>> len(corpus_vocab(TakeIndex([record])))  # a take without motion or audio is not usable: no words
    4
    """
    return build_vocab(index.where(usable=True))


def cooccurrence(sentences: Iterable[Sequence[str]], vocab: Vocab, *, window: int = 4):
    """Symmetric word-word co-occurrence counts within ``window`` tokens, weighted 1/distance.

    Returns
    -------
    scipy.sparse.csr_matrix, (V, V) float64
        Row/column = vocabulary id; special tokens' rows are empty.

    Examples
    --------
    >>> vocab = vocab_from_sentences([["a", "b", "c"]])
    >>> counts = cooccurrence([["a", "b", "c"]], vocab, window=2)
    >>> a, b, c = vocab.encode(["a", "b", "c"])
    >>> float(counts[a, b]), float(counts[a, c]), float(counts[b, a])  # weighted 1 / distance, symmetric
    (1.0, 0.5, 1.0)
    """
    from scipy import sparse

    if window < 1:
        raise ValueError(f"cooccurrence: window must be >= 1, got {window}")
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    vals: list[np.ndarray] = []
    for sentence in sentences:
        ids = vocab.encode(sentence)
        ids = ids[ids > UNK]
        for d in range(1, window + 1):
            if len(ids) <= d:
                break
            a, b = ids[:-d], ids[d:]
            w = np.full(len(a), 1.0 / d)
            rows += [a, b]
            cols += [b, a]
            vals += [w, w]
    n = len(vocab)
    if not rows:
        return sparse.csr_matrix((n, n))
    matrix = sparse.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )
    return matrix.tocsr()


def ppmi(counts) -> object:
    """Positive pointwise mutual information of a sparse co-occurrence matrix.

    ``PPMI_ij = max(0, log(c_ij * N / (c_i * c_j)))`` with ``N = sum c``; zero rows stay zero.

    Returns
    -------
    scipy.sparse.csr_matrix, same shape, float64

    Examples
    --------
    >>> import scipy.sparse
    >>> counts = scipy.sparse.csr_matrix(np.array([[0.0, 2.0], [2.0, 0.0]]))
    >>> ppmi(counts).toarray().round(6)  # log(2 * 4 / (2 * 2)) = log 2
    array([[0.      , 0.693147],
           [0.693147, 0.      ]])
    """
    from scipy import sparse

    counts = sparse.csr_matrix(counts, dtype=np.float64)
    total = counts.sum()
    if total == 0:
        return counts.copy()
    row = np.asarray(counts.sum(axis=1)).ravel()
    col = np.asarray(counts.sum(axis=0)).ravel()
    coo = counts.tocoo()
    pmi = np.log(coo.data * total / (row[coo.row] * col[coo.col]))
    keep = pmi > 0
    return sparse.csr_matrix((pmi[keep], (coo.row[keep], coo.col[keep])), shape=counts.shape)


def word_vectors(
    vocab: Vocab,
    sentences: Iterable[Sequence[str]],
    *,
    dim: int = 64,
    window: int = 4,
    seed: int = 0,
) -> np.ndarray:
    """Offline word vectors: truncated SVD of the corpus PPMI matrix.

    Row ``i`` is the vector of token ``vocab.itos[i]``. Ordinary words get
    ``U_k * sqrt(S_k)`` from the SVD (exact numpy SVD up to :data:`DENSE_SVD_MAX` tokens,
    scikit-learn's seeded randomized ``TruncatedSVD`` beyond), scaled to unit L2 norm (signs fixed so that each
    column's largest-magnitude entry is positive; deterministic). If the corpus has
    rank < ``dim`` the remaining columns are zero. PAD is the zero vector; SOS, EOS
    and UNK get fixed random N(0, 1/dim) vectors from ``seed`` (as the reference gives
    special tokens random N(0, 1/sqrt(300)) vectors). A word without any co-occurrence
    gets a zero vector.

    Parameters
    ----------
    vocab : Vocab
        Vocabulary (rows of the result).
    sentences : iterable of sequence of str
        Corpus token lists, e.g. :func:`take_sentences`.
    dim : int
        Vector dimension (default 64 for the tiny models; 300 matches FastText's shape).
    window : int
        Co-occurrence half-window, tokens.
    seed : int
        Seed of the SVD and the special-token vectors.

    Returns
    -------
    (len(vocab), dim) float32

    Examples
    --------
    >>> sentences = [["the", "cat", "sat"], ["the", "dog", "sat"]]
    >>> vocab = vocab_from_sentences(sentences)
    >>> vectors = word_vectors(vocab, sentences, dim=2)
    >>> vectors.shape, bool(np.all(vectors[0] == 0))  # PAD is the zero vector
    ((8, 2), True)
    >>> np.allclose(np.linalg.norm(vectors[4:], axis=1), 1.0)  # ordinary words: unit length
    True
    """
    if not isinstance(dim, int | np.integer) or dim < 1:
        raise ValueError(f"word_vectors: dim must be a positive int, got {dim!r}")
    matrix = ppmi(cooccurrence(sentences, vocab, window=window))
    out = np.zeros((len(vocab), dim), dtype=np.float64)
    rank = min(dim, len(vocab) - 5, matrix.nnz)
    if rank >= 1:
        if len(vocab) <= DENSE_SVD_MAX:  # exact and fast for small vocabularies
            u_full, s_full, _ = np.linalg.svd(matrix.toarray(), full_matrices=False)
            u, s = u_full[:, :rank] * s_full[:rank], s_full[:rank]
        else:
            from sklearn.decomposition import TruncatedSVD

            svd = TruncatedSVD(n_components=rank, algorithm="randomized", n_iter=10, random_state=seed)
            u, s = svd.fit_transform(matrix), svd.singular_values_  # u = U * S
        u = u / np.sqrt(np.maximum(s, 1e-12))  # U * sqrt(S)
        signs = np.sign(u[np.argmax(np.abs(u), axis=0), np.arange(u.shape[1])])
        u = u * np.where(signs == 0, 1.0, signs)
        norms = np.linalg.norm(u, axis=1, keepdims=True)
        u = np.divide(u, norms, out=np.zeros_like(u), where=norms > 0)
        out[4:, :rank] = u[4:]
    rng = np.random.default_rng(seed)
    out[1:4] = rng.normal(0.0, 1.0 / np.sqrt(dim), size=(3, dim))
    return out.astype(np.float32)


def read_vec_file(path: str | Path, vocab: Vocab, *, seed: int = 0) -> np.ndarray:
    r"""Map a FastText/word2vec ``.vec`` text file (``word v1 ... vD`` per line) onto ``vocab``.

    For users who have the paper's ``cc.en.300.vec`` offline. Words missing from the
    file get random N(0, 1/D) vectors (seeded), PAD the zero vector.

    Returns
    -------
    (len(vocab), D) float32

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "words.vec"
    >>> _ = path.write_text("2 3\nhello 1 0 0\nworld 0 1 0\n")  # fastText header: count and dimension
    >>> vocab = vocab_from_sentences([["hello", "there"]])
    >>> vectors = read_vec_file(path, vocab)
    >>> vectors.shape, vectors[vocab.id("hello")].tolist(), bool(np.all(vectors[0] == 0))
    ((6, 3), [1.0, 0.0, 0.0], True)
    >>> tmp.cleanup()
    """
    from beatlite.io.errors import FormatError

    path = Path(path)
    out, found = _vectors_of_vocab(path, vocab)
    if out is None:
        raise FormatError(path, "no vectors in the file")
    rng = np.random.default_rng(seed)
    missing = ~found
    missing[PAD] = False
    out[missing] = rng.normal(0.0, 1.0 / np.sqrt(out.shape[1]), size=(int(missing.sum()), out.shape[1]))
    return out.astype(np.float32)


def _vectors_of_vocab(path: Path, vocab: Vocab) -> tuple[np.ndarray | None, np.ndarray]:
    """Read a ``.vec`` file: the (len(vocab), D) float64 rows of the vocabulary's ordinary words
    (first occurrence wins, zeros elsewhere; None for a file without vectors) and which were found."""
    from beatlite.io.errors import FormatError
    from beatlite.io.textfile import open_text

    out: np.ndarray | None = None
    found = np.zeros(len(vocab), dtype=bool)
    with open_text(path) as f:
        for lineno, line in enumerate(f, start=1):
            parts = line.rstrip().split(" ")
            if lineno == 1 and _is_vec_header(parts):
                continue
            if out is None:
                out = np.zeros((len(vocab), len(parts) - 1), dtype=np.float64)
            if len(parts) - 1 != out.shape[1]:
                raise FormatError(path, f"expected {out.shape[1]} numbers, got {len(parts) - 1}", line=lineno)
            i = vocab.get(normalize_word(parts[0]))
            if i is None or i <= UNK or found[i]:
                continue
            out[i] = _vec_numbers(path, lineno, parts[1:])
            found[i] = True
    return out, found


def _is_vec_header(parts: list[str]) -> bool:
    """Whether a first line split on spaces is the ``n_words dim`` header of a ``.vec`` file."""
    return len(parts) == 2 and all(p.isdigit() for p in parts)


def _vec_numbers(path: Path, lineno: int, numbers: list[str]) -> np.ndarray:
    """(D,) float64 of a ``.vec`` line's numbers; ``FormatError`` naming the line when one is not a number."""
    from beatlite.io.errors import FormatError

    try:
        return np.array(numbers, dtype=np.float64)
    except ValueError:
        raise FormatError(path, "non-numeric vector entry", line=lineno) from None
