"""The model contract suite (:func:`beatlite.models.testing.check_model`) over every registered model."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from beatlite.models import MODELS
from beatlite.models.testing import CHECKS, STORE_CHECKS, model_case


@pytest.mark.parametrize("check", sorted(CHECKS))
@pytest.mark.parametrize("name", sorted(MODELS))
def test_model_contract(name: str, check: str, tmp_path: Path) -> None:
    CHECKS[check](model_case(name, tmp_path))


@pytest.mark.parametrize("check", sorted(STORE_CHECKS))
@pytest.mark.parametrize("name", sorted(MODELS))
def test_model_trains_from_a_store(name: str, check: str, small_store_windows: tuple, tmp_path: Path) -> None:
    train, reference = small_store_windows
    STORE_CHECKS[check](model_case(name, tmp_path, train=train, reference=reference))


def test_window_helpers_read_a_store_as_the_windows_in_memory(small_store_windows: tuple) -> None:
    """``prepare``'s readers: a store view in several chunks gives the in-memory arrays exactly."""
    import numpy as np

    from beatlite.models.base import window_chunks, window_count, window_rows

    train, reference = small_store_windows
    n = window_count(reference, "dirvec")
    assert window_count(train, "dirvec") == n == len(reference) > 5
    idx = [5, 0, 5, n - 1]
    assert np.array_equal(window_rows(train, "dirvec", idx), reference["dirvec"][idx])
    chunks = list(window_chunks(train, "dirvec", max_bytes=3 * 34 * 126 * 4))  # 3 windows per chunk
    assert len(chunks) == -(-n // 3) and np.array_equal(np.concatenate(chunks), reference["dirvec"])
    assert len(list(window_chunks(reference, "dirvec"))) == 1


def test_window_helpers_name_a_missing_key_and_the_keys_there() -> None:
    """A window dict without the key: window_count named it and listed the keys, window_rows and window_chunks
    raised a bare KeyError('dirvec')."""
    import numpy as np

    from beatlite.models.base import window_chunks, window_count, window_rows

    windows = {"pose": np.zeros((3, 34, 141)), "speaker": np.zeros(3, dtype=np.int64)}
    message = r"no 'dirvec' \(keys: \['pose', 'speaker'\]\)"
    with pytest.raises(KeyError, match=message):
        window_count(windows, "dirvec")
    with pytest.raises(KeyError, match=message):
        window_rows(windows, "dirvec", [0])
    with pytest.raises(KeyError, match=message):
        next(window_chunks(windows, "dirvec"))


def test_a_store_view_without_a_key_the_losses_read_is_refused_by_name(small_store_windows: tuple) -> None:
    """CaMN's loss reads ``semantic``, which its forward pass (``keys_for``) does not: ``batch_keys`` has it,
    and a view of ``keys_for`` alone is refused before any step, naming the key."""
    from beatlite.models import build_model
    from beatlite.models.camn import CaMN
    from beatlite.train import TrainConfig, fit

    train, _ = small_store_windows
    model = build_model("camn", preset="tiny", vocab_size=len(train.vocab))
    assert "semantic" in CaMN.batch_keys(model.config) and "semantic" not in CaMN.keys_for(model.config)
    view = train.store.windows("train", keys=CaMN.keys_for(model.config), stats=train.normalizers)
    with pytest.raises(KeyError, match="semantic"):
        fit(model, view, TrainConfig(epochs=1, batch_size=4, progress=False))


def test_check_model_runs_every_check_and_returns_their_names(
    small_store_windows: tuple, tmp_path: Path
) -> None:
    train, reference = small_store_windows
    from beatlite.models.testing import check_model

    assert check_model("s2g", tmp_path, train=train, reference=reference) == [*CHECKS, *STORE_CHECKS]
    assert check_model("s2g", tmp_path) == list(CHECKS)
    with pytest.raises(ValueError, match="reference"):
        check_model("s2g", tmp_path, train=train)


def _broken_models() -> dict[str, tuple[type, str]]:
    """S2G variants that each break one rule: class -> (rule's check, words of its message)."""
    import numpy as np
    import torch

    from beatlite.models.baselines import S2G

    class DeadParameter(S2G):
        def __init__(self, config) -> None:  # noqa: ANN001
            super().__init__(config)
            self.unused = torch.nn.Linear(3, 3)

    class ReadsTheFuture(S2G):  # generate without the base class's zeroing of the later target frames
        def forward(self, batch):  # noqa: ANN001, ANN202
            out = super().forward(batch)
            return {"pose": out["pose"] + batch["pose"].mean(dim=1, keepdim=True)}

        @torch.no_grad()
        def generate(self, batch):  # noqa: ANN001, ANN202
            return self.forward(batch)["pose"]

    class ForgetsAKey(S2G):
        @classmethod
        def batch_keys(cls, config) -> tuple[str, ...]:  # noqa: ANN001
            return ("mel",)

    class ChecksOnTheHost(S2G):  # a per-step range check that copies the ids to the host
        def forward(self, batch):  # noqa: ANN001, ANN202
            if int(batch["pose"].abs().max()) > 1e6:
                raise ValueError("pose out of range")
            return super().forward(batch)

    class CopiesToTheDevice(S2G):  # a per-step table built on the host and moved to the batch's device
        def forward(self, batch):  # noqa: ANN001, ANN202
            out = super().forward(batch)
            return {"pose": out["pose"] * torch.ones(out["pose"].shape[-1]).to(out["pose"].device)}

    class ReadsAnUnlistedKey(S2G):  # input_keys does not list face
        def forward(self, batch):  # noqa: ANN001, ANN202
            return {"pose": super().forward(batch)["pose"] + 0 * batch["face"].mean()}

    class LossesReadAnUnlistedKey(S2G):  # losses read semantic, batch_keys not overridden (CaMN overrides it)
        def losses(self, batch, out, *, epoch):  # noqa: ANN001, ANN202
            return {"total": ((out["pose"] - batch["pose"]).abs().mean(-1) * batch["semantic"]).mean()}

    class ZeroesTheTargetInPlace(
        S2G
    ):  # the losses then compare with zeros: trained silently on a wrong target
        def forward(self, batch):  # noqa: ANN001, ANN202
            batch["pose"][:, self.n_pre :] = 0.0
            return super().forward(batch)

    class Float64Buffer(S2G):  # a statistics buffer made from numpy promotes the output to float64
        def __init__(self, config) -> None:  # noqa: ANN001
            super().__init__(config)
            self.register_buffer("offset", torch.from_numpy(np.linspace(0.0, 1.0, 141)))

        def forward(self, batch):  # noqa: ANN001, ANN202
            return {"pose": super().forward(batch)["pose"] + self.offset}

    class NoisyGenerate(S2G):  # unseeded noise in eval mode too: another pose at every call
        def forward(self, batch):  # noqa: ANN001, ANN202
            pose = super().forward(batch)["pose"]
            return {"pose": pose + 0.1 * torch.randn_like(pose)}

    class ReturnsTheTensor(S2G):
        def forward(self, batch):  # noqa: ANN001, ANN202
            return super().forward(batch)["pose"]

    class NoTotal(S2G):
        def losses(self, batch, out, *, epoch):  # noqa: ANN001, ANN202
            return {"rec": (out["pose"] - batch["pose"]).abs().mean()}

    class FloatLoss(S2G):
        def losses(self, batch, out, *, epoch):  # noqa: ANN001, ANN202
            rec = (out["pose"] - batch["pose"]).abs().mean()
            return {"rec": rec.item(), "total": rec}

    return {
        "reads an unlisted key": (
            ReadsAnUnlistedKey,
            "shapes",
            "forward reads batch['face'], which batch_keys(config) = (",
        ),
        "losses read an unlisted key": (
            LossesReadAnUnlistedKey,
            "gradients",
            "losses reads batch['semantic'], which batch_keys(config)",
        ),
        "zeroes the target in place": (
            ZeroesTheTargetInPlace,
            "shapes",
            "forward changed the batch's ['pose']",
        ),
        "float64 buffer": (
            Float64Buffer,
            "shapes",
            "forward pose is torch.float64, the batch's 'pose' torch.float32 (float64",
        ),
        "noisy generate": (NoisyGenerate, "shapes", "generate gives another pose for the same batch"),
        "returns the tensor": (
            ReturnsTheTensor,
            "shapes",
            "forward must return a dict with 'pose', got Tensor",
        ),
        "no total": (NoTotal, "gradients", "losses must return a dict with 'total', got ['rec']"),
        "a float loss": (FloatLoss, "gradients", "losses ['rec'] are not tensors"),
        "dead parameter": (DeadParameter, "gradients", "no gradient: ['unused.weight', 'unused.bias']"),
        "checks on the host": (
            ChecksOnTheHost,
            "no_host_reads",
            "the training pass fails on the meta device",
        ),
        "copies to the device": (CopiesToTheDevice, "no_host_reads", "copies host data to the device"),
        "reads the future": (ReadsTheFuture, "shapes", "generate reads frames after the seed"),
        "forgets a key": (ForgetsAKey, "shapes", "batch_keys lacks ['pose']"),
    }


@pytest.mark.parametrize(
    "broken",
    ["dead parameter", "reads the future", "forgets a key", "checks on the host", "copies to the device",
     "reads an unlisted key", "losses read an unlisted key", "zeroes the target in place", "float64 buffer",
     "noisy generate", "returns the tensor", "no total", "a float loss"],
)  # fmt: skip
def test_the_contract_names_the_rule_a_model_breaks(broken: str, tmp_path: Path) -> None:
    cls, check, message = _broken_models()[broken]
    with pytest.raises(AssertionError, match=re.escape(message)):
        CHECKS[check](model_case(cls, tmp_path))


def test_the_registry_table_of_the_models_package_lists_the_registry() -> None:
    """``beatlite.models``' docstring table: one row per built-in model, its class and representation."""
    import beatlite.models
    from beatlite.models import model_class

    rows = re.findall(r"^``(\w+)``\s+(?::class:)?`+([\w.]+)`+\s+(\w+)$", beatlite.models.__doc__, re.M)
    built_in = [n for n, e in MODELS.items() if isinstance(e, tuple) and e[0].startswith("beatlite.models.")]
    want = [
        (n, f"{model_class(n).__module__}.{model_class(n).__name__}", model_class(n).representation)
        for n in built_in
    ]
    assert rows == want


def test_validation_losses_of_a_store_view_equal_those_of_the_windows_in_memory(
    small_store_windows: tuple,
) -> None:
    """``evaluate_losses`` (fit's per-epoch validation) reads a store view batch by batch: same means."""
    import torch

    from beatlite.models import build_model
    from beatlite.train.training import evaluate_losses

    train, reference = small_store_windows
    torch.manual_seed(0)
    model = build_model("trimodal", preset="tiny", vocab_size=len(train.vocab))
    got = evaluate_losses(model, train, epoch=0, batch_size=8)
    assert got == evaluate_losses(model, reference, epoch=0, batch_size=8) and set(got) >= {"rec", "total"}


def test_batches_of_ids_and_numbers_of_the_wrong_kind_are_named():
    """Float word ids and integer poses are refused naming the key (they failed deep inside torch, or not at all)."""
    import torch

    from beatlite.models.base import check_batch

    with pytest.raises(
        TypeError, match=r"batch\['speaker'\] holds ids: an integer tensor, got torch.float64"
    ):
        check_batch({"speaker": torch.zeros(2, dtype=torch.float64)}, ("speaker",), "X")
    with pytest.raises(TypeError, match=r"batch\['pose'\] holds numbers: a floating tensor, got torch.int64"):
        check_batch({"pose": torch.zeros(2, 34, 141, dtype=torch.int64)}, ("pose",), "X")
    check_batch(
        {"word": torch.zeros(2, 34, dtype=torch.int32), "audio": torch.zeros(2, 9)}, ("word", "audio"), "X"
    )


def test_store_training_finds_a_model_that_reads_memory_it_never_wrote(
    small_store_windows: tuple, tmp_path: Path
) -> None:
    """``fit`` turns deterministic mode's filling of new tensors off on CUDA (``set_deterministic``): a model that
    reads a tensor it never wrote would then train on whatever the memory held. The contract trains the store route
    unfilled and the in-memory route filled (NaN) and asks for the same bits, so such a model fails on the CPU: on
    the bits of the unfilled read, or on NaN where the allocator hands back memory that an earlier fill wrote."""
    import torch

    from beatlite.models.baselines import S2G
    from beatlite.models.testing import check_store_training

    class ReadsUnwrittenMemory(S2G):
        def forward(self, batch):  # noqa: ANN001, ANN202
            pose = super().forward(batch)["pose"]
            return {"pose": pose + 0.0 * torch.empty_like(pose)}  # 0 * NaN is NaN once filled

    train, reference = small_store_windows
    check_store_training(
        model_case("s2g", tmp_path, train=train, reference=reference)
    )  # the model itself passes
    with pytest.raises(AssertionError, match="store route, new tensors unfilled|non-finite losses"):
        check_store_training(model_case(ReadsUnwrittenMemory, tmp_path, train=train, reference=reference))
