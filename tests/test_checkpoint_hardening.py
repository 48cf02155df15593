"""Hostile checkpoints (beatlite.train.checkpoint, beatlite.metrics.extractor): refused with a FormatError
naming the file and the field, before anything large is allocated and without running code."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from zipdamage import flag_every_member  # noqa: E402

from beatlite.io import FormatError  # noqa: E402
from beatlite.models.base import GestureModel  # noqa: E402
from beatlite.paths import checkpoints_dir  # noqa: E402
from beatlite.train.checkpoint import load_checkpoint, load_model, save_checkpoint  # noqa: E402


@pytest.fixture(scope="module")
def shipped():
    """The shipped seq2seq checkpoint's dict (small, float16 weights)."""
    return load_checkpoint(checkpoints_dir() / "seq2seq_tiny.pt")


def test_a_config_asking_for_a_huge_model_is_refused_before_the_model_is_built(
    shipped, tmp_path, monkeypatch
):
    """hidden=6000 with the shipped (hidden=64) weights: before, the full model (2.5 GB) was built and
    initialised and only load_state_dict refused it; now it is compared on the meta device first."""
    path = save_checkpoint(tmp_path / "huge.pt", {**shipped, "model": {**shipped["model"], "hidden": 6000}})
    devices = []
    build = GestureModel.from_config.__func__

    def recording(cls, config):
        devices.append(torch.empty(0).device.type)  # where factory functions put tensors during this build
        return build(cls, config)

    monkeypatch.setattr(GestureModel, "from_config", classmethod(recording))
    with pytest.raises(FormatError) as refused:
        load_model(path)
    err = refused.value
    assert err.path == path and err.field == "state"
    # the first weights hidden sizes: the GRU encoder's input weights, 3 gates x hidden rows of word_dim (64)
    assert "encoder.weight_ih_l0" in shipped["state"]
    assert "'encoder.weight_ih_l0'" in err.reason, err.reason
    assert "(192, 64)" in err.reason and "(18000, 64)" in err.reason, err.reason
    assert set(devices) == {"meta"}, f"a model was built for real: {devices}"


def test_weights_of_other_names_are_refused_naming_the_first_key(shipped, tmp_path):
    first = next(iter(shipped["state"]))
    missing = {k: v for k, v in shipped["state"].items() if k != first}
    path = save_checkpoint(tmp_path / "missing.pt", {**shipped, "state": missing})
    with pytest.raises(FormatError, match=repr(first).replace(".", r"\.")) as refused:
        load_model(path)
    assert refused.value.field == "state"
    extra = {**shipped["state"], "no_such.weight": torch.zeros(2)}
    path = save_checkpoint(tmp_path / "extra.pt", {**shipped, "state": extra})
    with pytest.raises(FormatError, match="'no_such.weight'") as refused:
        load_model(path)
    assert refused.value.field == "state"
    model, _ = load_model(checkpoints_dir() / "seq2seq_tiny.pt")  # the shipped file still loads
    assert not model.training


def _bomb(src, dst, inflated: int) -> str:
    """A copy of the torch file ``src`` whose last tensor record is ``inflated`` zero bytes, DEFLATEd (torch.save
    stores members uncompressed, and torch.load inflates a record in full); returns the record's name."""
    import zipfile

    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        records = [n for n in zin.namelist() if "/data/" in n and n.rsplit("/", 1)[1].isdigit()]
        last = max(records, key=lambda n: int(n.rsplit("/", 1)[1]))
        for info in zin.infolist():
            if info.filename != last:
                zout.writestr(info, zin.read(info))
        info = zipfile.ZipInfo(last)
        info.compress_type = zipfile.ZIP_DEFLATED
        with zout.open(info, "w", force_zip64=True) as f:
            for _ in range(inflated // 2**20):
                f.write(bytes(2**20))
    return last


def test_a_decompression_bomb_in_a_checkpoint_is_refused_before_torch_reads_it(tmp_path, monkeypatch):
    """Before, torch.load inflated the member in full (3 GiB: 3.3 GB RSS, 11 s) before anything refused it."""
    from beatlite.metrics.extractor import load_extractor

    inflated = 80 * 2**20  # > 64 MiB (ZIP_SMALL_MEMBER_BYTES) at ~1000x: beyond GZIP_MAX_RATIO (100)
    for name, load in (
        ("seq2seq_tiny.pt", load_model),
        ("fgd_dirvec.pt", lambda p: load_extractor("dirvec", p)),
    ):
        path = tmp_path / f"bomb_{name}"
        record = _bomb(checkpoints_dir() / name, path, inflated)
        assert path.stat().st_size < inflated / 100
        with monkeypatch.context() as m:
            m.setattr(torch, "load", lambda *a, **k: pytest.fail("torch.load read the bomb"))
            with pytest.raises(FormatError, match="decompression bomb") as refused:
                load(path)
        assert refused.value.path == path and refused.value.field == record, refused.value


def _extractor_payload():
    return torch.load(checkpoints_dir() / "fgd_dirvec.pt", weights_only=True)


def _hostile_extractors():
    """(label, payload or raw bytes, the field the refusal must name) of the audit's hostile extractors."""
    import pickle

    base = _extractor_payload()
    state = base["state_dict"]
    first = next(k for k, v in state.items() if v.is_floating_point())
    return [
        ("a pickled object", pickle.dumps(_Evil(), protocol=2), None),
        ("a list", [1, 2], "format"),
        ("no config", {k: v for k, v in base.items() if k != "config"}, "config"),
        ("an unknown config field", {**base, "config": {**base["config"], "no_such": 1}}, "config"),
        ("no weights", {k: v for k, v in base.items() if k != "state_dict"}, "state_dict"),
        ("weights a list", {**base, "state_dict": [1]}, "state_dict"),
        (
            "a missing weight",
            {**base, "state_dict": {k: v for k, v in state.items() if k != first}},
            "state_dict",
        ),
        (
            "NaN weights",
            {**base, "state_dict": {**state, first: torch.full_like(state[first], float("nan"))}},
            "state_dict",
        ),
        ("std all zero", {**base, "input_std": torch.zeros_like(base["input_std"])}, "input_std"),
        ("NaN mean", {**base, "input_mean": torch.full_like(base["input_mean"], float("nan"))}, "input_mean"),
        ("a dirvec of 6 channels", {**base, "config": {**base["config"], "input_dim": 6}}, "config"),
        ("an unknown space", {**base, "space": "nosuch"}, "space"),
    ]


class _Evil:
    def __reduce__(self):
        return (pytest.fail, ("unpickling ran code",))


@pytest.mark.parametrize("label", [h[0] for h in _hostile_extractors()])
def test_a_hostile_extractor_is_one_format_error_naming_the_field(label, tmp_path):
    """Before: UnpicklingError, AttributeError, KeyError, TypeError or RuntimeError; NaN weights, a zero std and a
    6-channel dirvec extractor were accepted (and scoring failed later, blaming the predictions)."""
    from beatlite.metrics.extractor import load_extractor

    _, payload, field = next(h for h in _hostile_extractors() if h[0] == label)
    path = tmp_path / "ex.pt"
    if isinstance(payload, bytes):
        path.write_bytes(payload)
    else:
        torch.save(payload, path)
    with pytest.raises(FormatError) as refused:
        load_extractor("dirvec", path)
    assert refused.value.path == path and refused.value.field == field, refused.value


def test_metadata_tensors_of_any_layout_read_back_or_are_a_format_error_naming_the_key(shipped, tmp_path):
    """bfloat16, requires_grad and sparse tensors in the metadata raised a raw TypeError or RuntimeError."""
    values = torch.tensor([1.5, 0.0, -2.0])
    meta = {
        "bf16": values.to(torch.bfloat16),
        "grad": values.clone().requires_grad_(True),
        "sparse": values.to_sparse(),
        "float8": values.to(torch.float8_e4m3fn),
    }
    path = tmp_path / "meta.pt"
    torch.save({**shipped, "meta": meta}, path)
    back = load_checkpoint(path)["meta"]
    for key in meta:
        assert back[key].tolist() == [1.5, 0.0, -2.0], key  # exact in every dtype here
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # quantized tensors are deprecated: what numpy cannot hold
        quantized = torch.quantize_per_tensor(values, 0.5, 0, torch.qint8)
    torch.save({**shipped, "meta": {"q": quantized}}, path)
    with pytest.raises(FormatError) as refused, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        load_checkpoint(path)
    assert refused.value.path == path and refused.value.field == "meta.q"


def test_metadata_sharing_its_parts_is_converted_once_per_object(shipped, tmp_path):
    """40 levels each holding the previous twice (a 10 KB file) were walked path by path: 2**40 conversions,
    memory exhausted on export. Now each object once, and what was shared stays shared."""
    from beatlite.train.checkpoint import _tensors_for_numpy, export_checkpoint

    def nested(depth):
        level = [leaf]
        for _ in range(depth):
            level = [level, level]
        return level

    leaf = np.arange(3.0)
    cycle = [leaf]
    cycle.append(cycle)
    out = _tensors_for_numpy({"nest": nested(12), "cycle": cycle})  # small first: before, 2**12 copies
    walk = out["nest"]
    for _ in range(12):
        assert walk[0] is walk[1]
        walk = walk[0]
    assert torch.is_tensor(walk[0]) and walk[0].tolist() == [0.0, 1.0, 2.0]
    assert out["cycle"][1] is out["cycle"] and out["cycle"][0] is walk[0]
    src = save_checkpoint(tmp_path / "nest.pt", {**shipped, "meta": {"nest": nested(40)}})
    back = load_checkpoint(export_checkpoint(src, tmp_path / "small.pt"))["meta"]["nest"]
    assert back[0] is back[1] and (tmp_path / "small.pt").stat().st_size < 2 * src.stat().st_size


def test_convert_legacy_is_advised_only_for_a_blocked_object_and_config_errors_name_the_model(
    shipped, tmp_path
):
    """Before, a text file was told to convert_legacy(trust=True) (running any code it held), and an unknown
    config field was reported as field 'state'."""
    import pathlib

    text = tmp_path / "notes.pt"
    text.write_text("hello world\n")
    with pytest.raises(FormatError, match="not a torch checkpoint") as refused:
        load_checkpoint(text)
    assert "convert_legacy" not in refused.value.reason and refused.value.path == text
    legacy = tmp_path / "legacy.pt"
    torch.save({**shipped, "meta": {"source": pathlib.PurePosixPath("/data")}}, legacy)
    with pytest.raises(FormatError, match=r"GLOBAL pathlib\.PurePosixPath.*convert_legacy"):
        load_checkpoint(legacy)
    path = save_checkpoint(tmp_path / "field.pt", {**shipped, "model": {**shipped["model"], "no_such": 1}})
    with pytest.raises(FormatError, match="no_such") as refused:
        load_model(path)
    assert refused.value.field == "model"
    path = save_checkpoint(tmp_path / "name.pt", {**shipped, "model": {"name": "no_such_model"}})
    with pytest.raises(FormatError, match="no_such_model") as refused:
        load_model(path)
    assert refused.value.field == "model"


def test_a_flipped_byte_in_a_weight_is_refused_by_the_zip_crc(tmp_path):
    """torch.load does not check the CRC-32 of the members: one flipped bit in a tensor's bytes loaded as a
    silently different weight (a2g_tiny: motion_encoder.0.net.0.weight off by 4.9e-4). Now a FormatError."""
    import struct
    import zipfile

    from beatlite.metrics.extractor import load_extractor

    for name, load in (("a2g_tiny.pt", load_model), ("fgd_dirvec.pt", lambda p: load_extractor("dirvec", p))):
        src = checkpoints_dir() / name
        with zipfile.ZipFile(src) as z:
            big = max(z.infolist(), key=lambda i: i.file_size)  # the largest tensor's storage
        data = bytearray(src.read_bytes())
        name_len, extra_len = struct.unpack("<HH", data[big.header_offset + 26 : big.header_offset + 30])
        data[big.header_offset + 30 + name_len + extra_len + big.file_size // 2] ^= 0x40
        path = tmp_path / name
        path.write_bytes(bytes(data))
        with pytest.raises(FormatError, match=f"member {big.filename} fails its CRC-32 check"):
            load(path)
        load(src)  # the file as shipped loads


@pytest.mark.parametrize("damage", ["name", "method", "encrypted"])
def test_a_member_zipfile_cannot_open_is_a_format_error(tmp_path, damage):
    """The CRC check opens every member: a damaged name in a local header (UnicodeDecodeError), an unknown
    compression method (NotImplementedError) or the encryption flag (RuntimeError) must be a FormatError too."""
    import struct

    data = bytearray((checkpoints_dir() / "a2g_tiny.pt").read_bytes())
    local = data.index(b"PK\x03\x04")  # the first member's local header
    if damage == "name":
        data[local + 30] = 0xFF  # the first byte of its name: not UTF-8
        data[local + 6 : local + 8] = struct.pack("<H", 0x800)  # flagged as a UTF-8 name
    else:
        flag_every_member(data, damage)  # local and central headers alike
    path = tmp_path / "damaged.pt"
    path.write_bytes(bytes(data))
    with pytest.raises(FormatError, match="truncated or corrupted"):
        load_model(path)


def test_numpy_arrays_nested_in_the_metadata_come_back_as_numpy_arrays_of_their_dtype(shipped, tmp_path):
    """save_checkpoint stores every numpy array of the metadata as a tensor, nested ones too, but load_checkpoint
    gave only the top-level ones back as numpy arrays: an array in a dict or list came back a torch tensor."""
    mean = np.array([0.5, -1.25], dtype=np.float32)
    counts = np.array([3, 4], dtype=np.int64)
    path = save_checkpoint(
        tmp_path / "nested.pt", {**shipped, "meta": {"stats": {"mean": mean}, "n": [counts]}}
    )
    back = load_checkpoint(path)["meta"]
    for got, want in ((back["stats"]["mean"], mean), (back["n"][0], counts)):
        assert isinstance(got, np.ndarray) and got.dtype == want.dtype and np.array_equal(got, want)
