"""beatlite.data.vocab: ids, corpus vocabulary, word -> frame ids, offline word vectors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_data_fixtures import make_tiny_take, write_textgrid

from beatlite.data.index import index_folder
from beatlite.data.vocab import (
    EOS,
    PAD,
    SOS,
    UNK,
    Vocab,
    build_vocab,
    cooccurrence,
    ppmi,
    read_vec_file,
    take_sentences,
    vocab_from_sentences,
    word_vectors,
)


def test_special_ids_and_lookup() -> None:
    v = Vocab(["hello", "world"])
    assert (PAD, SOS, EOS, UNK) == (0, 1, 2, 3)
    assert v.itos[:4] == ("<pad>", "<sos>", "<eos>", "<unk>")
    assert v["hello"] == 4 and v["World,"] == 5 and v.id("HELLO!") == 4
    assert v.id("unseen") == UNK and v.id("") == PAD and v.get("unseen", UNK) == UNK
    with pytest.raises(KeyError):
        v["unseen"]
    assert "world" in v and "nope" not in v and len(v) == 6
    assert v.encode(["hello", "x"]).tolist() == [4, 3] and v.decode([0, 5]) == ["<pad>", "world"]
    with pytest.raises(IndexError, match="id 6"):
        v.decode([6])


def test_vocab_rejects_bad_words() -> None:
    with pytest.raises(ValueError, match="duplicate"):
        Vocab(["a", "A,"])
    with pytest.raises(ValueError, match="empty"):
        Vocab(["a", "..."])
    with pytest.raises(TypeError, match="single str"):
        Vocab("abc")  # type: ignore[arg-type]


def test_vocab_from_sentences_order_and_min_count() -> None:
    v = vocab_from_sentences([["b", "a", "b"], ["c", "a", "b", ""]])
    assert v.words == ("b", "a", "c")  # counts 3, 2, 1
    assert vocab_from_sentences([["b", "a", "b"], ["c", "a", "b"]], min_count=2).words == ("b", "a")
    # ties are alphabetical
    assert vocab_from_sentences([["z", "y"]]).words == ("y", "z")


def test_save_load_round_trip(tmp_path: Path) -> None:
    v = Vocab(["don't", "well-known", "x"])
    v.save(tmp_path / "vocab.json")
    assert Vocab.load(tmp_path / "vocab.json").itos == v.itos
    (tmp_path / "bad.json").write_text("[1, 2]", encoding="utf-8")
    with pytest.raises(ValueError, match="'words'"):
        Vocab.load(tmp_path / "bad.json")


def test_build_vocab_from_textgrids(tmp_path: Path) -> None:
    make_tiny_take(tmp_path, "2_scott_0_9_9", 3.0, modalities=("bvh", "wav"))
    write_textgrid(
        tmp_path / "2_scott_0_9_9.TextGrid", [(0.1, 0.5, "So"), (0.5, 0.9, "we"), (1.0, 1.2, "so,")], 3.0
    )
    make_tiny_take(tmp_path, "2_scott_0_1_1", 3.0, modalities=("bvh", "wav"))
    write_textgrid(tmp_path / "2_scott_0_1_1.TextGrid", [(0.1, 0.5, "Go")], 3.0)
    idx = index_folder(tmp_path)
    assert take_sentences(idx) == [["go"], ["so", "we", "so"]]  # index order: test 1 before train 9
    assert build_vocab(idx).words == ("so", "go", "we")
    assert build_vocab(idx, splits=["train"]).words == ("so", "we")


def test_word_to_frame_ids_with_vocab(tmp_path: Path) -> None:
    from beatlite.io import read_words, words_to_frames

    write_textgrid(tmp_path / "a.TextGrid", [(0.5, 1.0, "Hello"), (1.0, 1.4, "world,")], 2.0)
    v = Vocab(["hello", "world"])
    ids = words_to_frames(read_words(tmp_path / "a.TextGrid"), 20, 10.0, v, rule="span")
    # frame i at t = i / 10: [0.5, 1.0) -> frames 5-9 hello (4); [1.0, 1.4) -> frames 10-13 world (5)
    assert ids.tolist() == [0] * 5 + [4] * 5 + [5] * 4 + [0] * 6


def test_cooccurrence_and_ppmi_hand_computed() -> None:
    v = Vocab(["a", "b"])
    a, b = v["a"], v["b"]
    c = cooccurrence([["a", "b", "a"]], v, window=2).toarray()
    # distance 1: (a,b), (b,a) -> C[a,b] = C[b,a] = 2; distance 2: (a,a) weight 1/2, both directions -> 1
    assert c[a, b] == 2 and c[b, a] == 2 and c[a, a] == 1 and c[b, b] == 0 and c[:4].sum() == 0
    m = ppmi(c).toarray()
    # N = 5, row a = 3, row b = 2: PMI(a,b) = log(2*5/(3*2)) > 0, PMI(a,a) = log(1*5/(3*3)) < 0 -> 0
    assert m[a, b] == pytest.approx(np.log(10 / 6)) and m[a, a] == 0


def test_word_vectors_properties() -> None:
    # "cat" and "dog" occur in identical contexts, "sun" elsewhere
    sentences = [
        ["the", "cat", "sat"],
        ["the", "dog", "sat"],
        ["a", "sun", "rose"],
        ["a", "moon", "rose"],
    ] * 5
    v = vocab_from_sentences(sentences)
    vec = word_vectors(v, sentences, dim=4, window=1)
    assert vec.shape == (len(v), 4) and vec.dtype == np.float32
    assert np.all(vec[PAD] == 0) and np.all(np.linalg.norm(vec[[SOS, EOS, UNK]], axis=1) > 0)
    cos = vec @ vec.T
    assert cos[v["cat"], v["dog"]] > 0.99 and cos[v["cat"], v["sun"]] < 0.5
    assert np.allclose(np.linalg.norm(vec[4:], axis=1), 1.0, atol=1e-5)
    assert np.array_equal(vec, word_vectors(v, sentences, dim=4, window=1))  # deterministic
    big = word_vectors(v, sentences, dim=300, window=1)  # more dims than the corpus has rank
    assert big.shape == (len(v), 300) and np.all(big[4:, 10:] == 0)
    with pytest.raises(ValueError, match="dim"):
        word_vectors(v, sentences, dim=0)


def test_read_vec_file(tmp_path: Path) -> None:
    (tmp_path / "w.vec").write_text("3 2\nhello 1 2\nWorld 3 4\nzzz 5 6\n", encoding="utf-8")
    v = Vocab(["hello", "world", "missing"])
    vec = read_vec_file(tmp_path / "w.vec", v)
    assert vec.shape == (4 + 3, 2)
    assert vec[v["hello"]].tolist() == [1, 2] and vec[v["world"]].tolist() == [3, 4]
    assert np.all(vec[PAD] == 0) and np.any(vec[v["missing"]] != 0)
    (tmp_path / "bad.vec").write_text("hello 1 2\nworld 3\n", encoding="utf-8")
    with pytest.raises(ValueError, match="line 2"):
        read_vec_file(tmp_path / "bad.vec", v)


def test_randomized_svd_branch(monkeypatch: pytest.MonkeyPatch) -> None:
    import beatlite.data.vocab as vocab_module

    sentences = [
        ["the", "cat", "sat"],
        ["the", "dog", "sat"],
        ["a", "sun", "rose"],
        ["a", "moon", "rose"],
    ] * 5
    v = vocab_from_sentences(sentences)
    monkeypatch.setattr(vocab_module, "DENSE_SVD_MAX", 0)  # force scikit-learn's TruncatedSVD
    vec = word_vectors(v, sentences, dim=4, window=1)
    cos = vec @ vec.T
    assert cos[v["cat"], v["dog"]] > 0.99 and cos[v["cat"], v["sun"]] < 0.5
    assert np.array_equal(vec, word_vectors(v, sentences, dim=4, window=1))  # seeded: deterministic
