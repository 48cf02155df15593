"""beatlite.data.resident: windows gathered on the device from resident streams equal the store's batches."""

from __future__ import annotations

import numpy as np
import pytest
from test_data_windows import TAKES, VOCAB, write_take

from beatlite.constants import FPS, SR
from beatlite.data.index import index_folder
from beatlite.data.store import WindowStore, build_store

torch = pytest.importorskip("torch")

from beatlite.data.resident import RESIDENT_KEYS, ResidentWindows, fits_on_device, resident_bytes  # noqa: E402


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> WindowStore:
    root = tmp_path_factory.mktemp("resident_corpus")
    for stem, n in TAKES.items():
        write_take(root, stem, n)
    return build_store(
        index_folder(root, cache=False), root / "store", vocab=VOCAB, workers=0, positions=True
    )


@pytest.mark.parametrize("split", ["train", "test", None])
def test_every_key_equals_the_stores_batch_bit_for_bit(store: WindowStore, split: str | None) -> None:
    view = store.windows(split)
    keys = [k for k in RESIDENT_KEYS if k in view]
    assert {"pose", "dirvec", "audio", "mel", "word", "speaker", "positions"} <= set(keys)
    resident = ResidentWindows(view, keys, device="cpu")
    idx = np.random.default_rng(0).permutation(len(view))  # every window, in a shuffled order
    want = view.batch(idx, keys=keys)
    got = resident.batch(torch.from_numpy(idx))
    for k in keys:
        assert got[k].dtype == torch.from_numpy(want[k]).dtype, k
        np.testing.assert_array_equal(got[k].numpy(), want[k], err_msg=k)
    assert resident.nbytes == resident_bytes(view, keys)


def test_windows_running_past_their_take_are_padded_as_the_store_pads_them(store: WindowStore) -> None:
    # Windows end inside their take, so the end padding (audio zeros, the mel's last row repeated) is only reached
    # by a window moved past its end: the last window of every take, 3 frames later than the last start possible.
    view = store.windows(None, keys=("audio", "mel"))
    last = np.flatnonzero(np.diff(view.take_ids, append=-1) != 0)
    view.starts = view.starts.copy()
    view.starts[last] = [store.takes[int(t)].n_frames - view.length + 3 for t in view.take_ids[last]]
    idx = np.arange(len(view))
    want, got = view.batch(idx), ResidentWindows(view, ["audio", "mel"]).batch(idx)
    for k in ("audio", "mel"):
        np.testing.assert_array_equal(got[k].numpy(), want[k], err_msg=k)
    assert np.all(
        want["audio"][last, -(3 * SR // FPS - 200) :] == 0
    )  # the padding was reached (3 frames, less rounding)
    assert np.all(want["mel"][last, -1] == want["mel"][last, -2])


def test_keys_are_checked_and_the_cpu_is_not_chosen_by_default(store: WindowStore) -> None:
    view = store.windows("train", keys=("pose",))
    with pytest.raises(KeyError, match=r"\['audio'\] not in the view"):
        ResidentWindows(view, ["pose", "audio"])
    with pytest.raises(KeyError, match="cannot be held"):
        ResidentWindows(view, ["take"])
    assert not fits_on_device(view, ["pose"], "cpu")


def test_fit_on_resident_windows_takes_the_same_steps_as_the_store_loader(store: WindowStore) -> None:
    """The loop's two routes for a store view, in fp32 on the CPU: the same losses and weights to the bit."""
    from beatlite.models import build_model
    from beatlite.train import TrainConfig, fit

    runs = {}
    for mode in ("never", "always"):
        torch.manual_seed(0)
        model = build_model(
            "camn", preset="tiny"
        )  # reads pose, audio, face, word, emotion, speaker, semantic
        config = TrainConfig(epochs=2, batch_size=4, seed=1, threads=1, progress=False, data_on_device=mode)
        history = fit(model, store.windows("train"), config, store.windows("test")).history
        runs[mode] = (history, [p.detach().clone() for p in model.parameters()])
    assert runs["always"][0] == runs["never"][0]
    assert all(torch.equal(a, b) for a, b in zip(runs["always"][1], runs["never"][1], strict=True))


def test_streams_reach_the_device_a_take_at_a_time(tmp_path) -> None:
    """Host memory while the streams are gathered holds one take's rows, never a whole stream: numpy's peak
    (tracemalloc) stays under the bytes of the audio stream itself, where a concatenation of every take held
    it twice (the list of takes and their concatenation)."""
    import tracemalloc

    for k in range(1, 11):  # ten equal takes: one take's temporaries are a tenth of the stream's
        write_take(tmp_path, f"2_scott_0_{k}_{k}", 40)
    store = build_store(index_folder(tmp_path, cache=False), tmp_path / "store", workers=0)
    view = store.windows(None, keys=("audio",))
    stream = resident_bytes(view, ["audio"]) - 24 * len(view)  # (float32 samples and padding, no offsets)
    tracemalloc.start()
    try:
        resident = ResidentWindows(view, ["audio"], device="cpu")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert resident.nbytes - 24 * len(view) == stream
    assert peak < stream / 2, (peak, stream)
