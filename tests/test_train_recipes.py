"""The recipes of the shipped checkpoints (beatlite.train.recipes) and the seeds table (beatlite.train.seeds)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from childproc import run_ok

from beatlite.models import MODELS
from beatlite.train.recipes import CAMN_ABLATIONS, HA2G_ABLATIONS, RECIPES, SEED, retrain, retrain_many
from beatlite.train.seeds import SeedResults


def test_every_recipe_builds_a_registered_model_and_has_a_table_label():
    labels = [recipe.label for recipe in RECIPES.values()]
    assert len(set(labels)) == len(labels) and all(labels)  # one row label per checkpoint
    for name, recipe in RECIPES.items():
        assert recipe.model in MODELS, name
        assert recipe.epochs >= 0 and recipe.batch_size >= 2 and recipe.lr > 0, name
    assert RECIPES["mean_pose"].epochs == 0 and RECIPES["random_clip"].epochs == 0


def test_each_ablation_switches_off_exactly_one_thing():
    assert CAMN_ABLATIONS["camn_tiny"][1] == {}
    for name, (_, overrides) in CAMN_ABLATIONS.items():
        if name != "camn_tiny":
            assert len(overrides) == 1 and all(v is False for v in overrides.values()), name


def test_ha2g_recipes_are_the_model_modules_switches():
    from beatlite.models.ha2g_ablations import ABLATIONS

    assert HA2G_ABLATIONS["ha2g_tiny"][1] == ABLATIONS["full"] == {}
    assert {name: HA2G_ABLATIONS[f"ha2g_tiny_{name}"][1] for name in ABLATIONS if name != "full"} == {
        name: kw for name, kw in ABLATIONS.items() if name != "full"
    }
    assert len(HA2G_ABLATIONS) == len(ABLATIONS)
    # the shipped names did not change
    for name in ("holistic", "single_audio", "no_contrastive", "no_physical"):
        assert f"ha2g_tiny_{name}" in RECIPES
    # one switch per row, except "w/o text", which also drops the contrastive loss (it needs text)
    for name, overrides in ABLATIONS.items():
        assert len(overrides) == (2 if name == "no_text" else 0 if name == "full" else 1), name


def test_ha2g_ablations_really_switch_something():
    pytest.importorskip("torch")
    from beatlite.models.ha2g import PRESETS, HA2GConfig

    tiny = HA2GConfig(**PRESETS["tiny"])
    for name, (_, overrides) in HA2G_ABLATIONS.items():
        for field, value in overrides.items():
            assert getattr(tiny, field) != value, (name, field)


@pytest.mark.slow
def test_every_generator_parameter_gets_a_gradient_in_every_recipe():
    """The contract DistributedDataParallel relies on (beatlite.train.distributed): one step's generator
    loss reaches every generator parameter, before and after the adversarial epochs start."""
    torch = pytest.importorskip("torch")
    from beatlite.data.torch_dataset import WindowDataset
    from beatlite.train.recipes import build_recipe_model, training_data

    torch.set_num_threads(1)
    data = training_data()  # the window store's train windows, as fit reads them
    for name in RECIPES:
        model = build_recipe_model(name, data, seed=1)
        generator = model.generator_parameters()
        if not generator:  # the untrained baselines
            continue
        model.prepare(data.train, data.train.normalizers)
        batch = WindowDataset(data.train, model.batch_keys(model.config))[list(range(4))]
        for epoch in (0, 1000):
            model.zero_grad(set_to_none=True)
            model.losses(batch, model(batch), epoch=epoch)["total"].backward()
            names = {id(p): n for n, p in model.named_parameters()}
            assert [names[id(p)] for p in generator if p.grad is None] == [], (name, epoch)


def test_unknown_names_and_bad_jobs_are_rejected_before_any_work():
    with pytest.raises(ValueError, match="camn_tiny_typo"):
        retrain("camn_tiny_typo")
    with pytest.raises(ValueError, match="camn_tiny_typo"):
        retrain_many([("camn_tiny_typo", SEED, None)])
    with pytest.raises(ValueError, match="jobs"):
        retrain_many([("s2g_tiny", SEED, None)], jobs=0)


@pytest.mark.slow
def test_retrain_is_deterministic_exports_float16_and_does_not_depend_on_jobs(tmp_path):
    torch = pytest.importorskip("torch")
    from beatlite.train.checkpoint import load_checkpoint
    from beatlite.train.recipes import training_data

    data = training_data()
    runs = [("s2g_tiny", 7, tmp_path / "a"), ("random_clip", 7, tmp_path / "a")]
    for name, seed, out in runs:
        retrain(name, seed=seed, epochs=1, out_dir=out, data=data, progress=False)
    again = [(name, seed, tmp_path / "b") for name, seed, _ in runs]
    seconds = retrain_many(again, jobs=2, epochs=1)
    assert set(seconds) == {("s2g_tiny", 7), ("random_clip", 7)}
    other = tmp_path / "c"
    retrain("s2g_tiny", seed=8, epochs=1, out_dir=other, data=data, progress=False)
    for name, _, _ in runs:
        a, b = load_checkpoint(tmp_path / "a" / f"{name}.pt"), load_checkpoint(tmp_path / "b" / f"{name}.pt")
        assert (tmp_path / "a" / "train" / f"{name}.pt").is_file()  # the resumable full checkpoint
        assert a["state"].keys() == b["state"].keys()
        for key, value in a["state"].items():
            assert torch.equal(value, b["state"][key]), (name, key)
            if value.is_floating_point():
                assert value.dtype == torch.float16, (name, key)
    s2g, s2g8 = load_checkpoint(tmp_path / "a" / "s2g_tiny.pt"), load_checkpoint(other / "s2g_tiny.pt")
    assert any(not torch.equal(v, s2g8["state"][k]) for k, v in s2g["state"].items())
    clip = load_checkpoint(tmp_path / "a" / "random_clip.pt")
    assert clip["model"]["seed"] == 7  # the seed also picks the random clips


def test_seed_results_mean_and_sample_sd_by_hand():
    res = SeedResults(
        {
            "A": {"FGD": [1.0, 2.0, 4.0], "SRGR": [0.1, math.nan, 0.3]},
            "B": {"FGD": [5.0], "SRGR": [math.nan]},
        },
        seeds=[1, 2, 3],
        info={},
    )
    assert res.mean("A", "FGD") == pytest.approx(7 / 3)
    assert res.sd("A", "FGD") == pytest.approx(math.sqrt(7 / 3))  # sum of squares 42/9 over n-1 = 2
    assert res.mean("A", "SRGR") == pytest.approx(0.2) and res.sd("A", "SRGR") == pytest.approx(
        math.sqrt(0.02)
    )
    assert res.mean("B", "FGD") == 5.0 and math.isnan(res.sd("B", "FGD"))
    assert res.count("A", "FGD") == 3 and res.count("A", "SRGR") == 2 and res.count("B", "SRGR") == 0
    assert math.isnan(res.mean("B", "SRGR"))
    md = res.to_markdown()
    assert "| A | 2.33 ± 1.53 | 0.200 ± 0.141 |" in md
    assert "| B | 5.00 | — |" in md
    d = res.to_dict()
    assert d["rows"]["A"]["SRGR"]["values"] == [0.1, None, 0.3] and d["rows"]["B"]["FGD"]["sd"] is None
    assert np.isclose(d["rows"]["A"]["FGD"]["mean"], 7 / 3)


def test_seed_difference_is_welch_by_hand_and_the_table_round_trips(tmp_path):
    import json

    from beatlite.io import FormatError
    from beatlite.train.seeds import recorded_seed_results

    res = SeedResults(
        {"A": {"FGD": [1.0, 3.0]}, "B": {"FGD": [4.0, 4.0, 7.0]}, "C": {"FGD": [2.0]}}, [1, 2, 3], {}
    )
    delta, se = res.difference("A", "B", "FGD")
    # var(A) = 2 (ddof 1), var(B) = 3; se = sqrt(2/2 + 3/3) = sqrt(2)
    assert delta == pytest.approx(2.0 - 5.0) and se == pytest.approx(math.sqrt(2.0))
    assert math.isnan(res.difference("A", "C", "FGD")[1])
    path = tmp_path / "seeds.json"
    path.write_text(json.dumps(res.to_dict()))
    back = recorded_seed_results(path)
    assert back.values == res.values and back.seeds == [1, 2, 3]
    with pytest.raises(FileNotFoundError, match="make seeds"):
        recorded_seed_results(tmp_path / "missing.json")
    path.write_text('{"rows": 3}')
    with pytest.raises(FormatError, match="seeds.json"):
        recorded_seed_results(path)


def test_compare_rows_need_two_standard_errors_and_know_each_metrics_direction():
    from beatlite.train.seeds import compare_rows

    res = SeedResults(
        {
            "full": {"FGD": [4.0, 4.2, 3.8], "SRGR": [0.20, 0.21, 0.19]},
            "no_x": {"FGD": [6.0, 6.2, 5.8], "SRGR": [0.20, 0.22, 0.18]},  # FGD +2 (se 0.163): worse
            "no_y": {"FGD": [3.9, 4.5, 3.6], "SRGR": [0.25, 0.26, 0.24]},  # SRGR +0.05 (se 0.0082): better
        },
        [1, 2, 3],
        {},
    )
    effects = {(e.variant, e.metric): e for e in compare_rows(res, "full", ["no_x", "no_y"])}
    assert effects["no_x", "FGD"].verdict == "worse" and effects["no_x", "FGD"].delta == pytest.approx(2.0)
    # sd of both FGD rows is 0.2: se = sqrt(0.04/3 + 0.04/3)
    assert effects["no_x", "FGD"].se == pytest.approx(math.sqrt(0.08 / 3))
    assert effects["no_x", "SRGR"].verdict == "noise"
    assert effects["no_y", "SRGR"].verdict == "better" and effects["no_y", "FGD"].verdict == "noise"
    assert effects["no_x", "FGD"].cell() == f"+2.00 ± {2 * math.sqrt(0.08 / 3):.2f} worse"
    with pytest.raises(ValueError, match="metric"):
        compare_rows(res, "full", ["no_x"], metrics=["speed"])


def _checkpoint_of(name: str, **train_changes):
    """What retrain's export of recipe ``name`` stores about its training (config dicts only)."""
    from beatlite.models import build_model
    from beatlite.train import TrainConfig

    recipe = RECIPES[name]
    config = TrainConfig(
        epochs=recipe.epochs, batch_size=recipe.batch_size, lr=recipe.lr, lr_schedule=recipe.lr_schedule
    ).to_dict()
    config.update(train_changes)
    kw = dict(recipe.overrides)
    if recipe.uses_text:
        kw["vocab_size"] = 207
    from beatlite.train.checkpoint import FORMAT

    model = build_model(recipe.model, preset="tiny", **kw).to_config()
    return {"format": FORMAT, "train_config": config, "model": model, "state": {}}


def test_recipe_mismatch_sees_changed_settings_and_model_configs():
    pytest.importorskip("torch")
    from beatlite.train.seeds import recipe_mismatch

    for name in ("camn_tiny", "ha2g_tiny_holistic", "random_clip"):
        assert recipe_mismatch(name, _checkpoint_of(name)) is None, name
    why = recipe_mismatch("camn_tiny", _checkpoint_of("camn_tiny", epochs=60, lr=1e-3))
    assert (
        why is not None
        and "epochs=60" in why
        and "lr=0.001" in why
        and f"epochs={RECIPES['camn_tiny'].epochs}" in why
    )
    old = _checkpoint_of("camn_tiny")
    del old["train_config"]["lr_schedule"]  # checkpoints from before the option: constant
    del old["train_config"]["deterministic"]  # ... and before this one: deterministic
    assert recipe_mismatch("camn_tiny", old) is None
    # trained in bf16 or nondeterministically (fit --precision bf16 / --nondeterministic): not the recipe's
    assert "amp=True" in recipe_mismatch("camn_tiny", _checkpoint_of("camn_tiny", amp=True))
    assert "deterministic=False" in recipe_mismatch(
        "camn_tiny", _checkpoint_of("camn_tiny", deterministic=False)
    )
    other = _checkpoint_of("ha2g_tiny")
    other["model"]["audio_freq_stride"] = 1  # a preset change since it was trained
    assert "audio_freq_stride" in recipe_mismatch("ha2g_tiny", other)
    # a checkpoint from before a config field loads with the field's default (load_model does so): current when
    # that default is the recipe's (audio_order, added after the shipped HA2G checkpoints), stale otherwise
    older = _checkpoint_of("ha2g_tiny")
    del older["model"]["audio_order"]
    assert recipe_mismatch("ha2g_tiny", older) is None
    changed = _checkpoint_of("ha2g_tiny_no_contrastive")
    field = next(k for k, v in RECIPES["ha2g_tiny_no_contrastive"].overrides.items())
    del changed["model"][field]  # its default is the full model's, not the ablation's
    assert field in recipe_mismatch("ha2g_tiny_no_contrastive", changed)
    gone = _checkpoint_of("camn_tiny")
    gone["model"]["retired_option"] = 1
    assert "does not load" in recipe_mismatch("camn_tiny", gone)
    # an ablation's checkpoint is not the full model's
    assert "use_audio" in recipe_mismatch("camn_tiny", _checkpoint_of("camn_tiny_no_audio"))


def test_train_seeds_keeps_current_checkpoints_and_retrains_stale_ones(tmp_path, monkeypatch):
    pytest.importorskip("torch")
    from beatlite.paths import checkpoints_dir
    from beatlite.train import checkpoint, seeds

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path))
    checkpoint.save_checkpoint(seeds.checkpoint_path("s2g_tiny", 7), _checkpoint_of("s2g_tiny"))
    checkpoint.save_checkpoint(
        seeds.checkpoint_path("trimodal_tiny", 7), _checkpoint_of("trimodal_tiny", lr=5e-4)
    )
    asked = []
    monkeypatch.setattr(seeds, "retrain_many", lambda todo, **kw: asked.extend(todo) or {})
    own = seeds.shipped_seed(checkpoints_dir() / "s2g_tiny.pt")  # the shipped one stands for its seed
    seeds.train_seeds(["s2g_tiny", "trimodal_tiny", "mean_pose"], seeds=[own, 7], verbose=False)
    assert [(name, seed) for name, seed, _ in asked] == [("trimodal_tiny", 7), ("mean_pose", 7)]
    assert all(out == tmp_path / "seeds" / "7" for _, _, out in asked)  # never into checkpoints/
    asked.clear()
    seeds.train_seeds(["s2g_tiny"], seeds=[7], force=True, verbose=False)
    assert [(name, seed) for name, seed, _ in asked] == [("s2g_tiny", 7)]


@pytest.mark.slow
def test_fit_command_writes_only_under_out(tmp_path):
    """``python -m beatlite.train fit`` on data_samples/: checkpoints and caches under --out, the repository untouched."""
    import sys

    from beatlite.paths import checkpoints_dir, repo_root

    before = {p.name: p.stat().st_mtime_ns for p in checkpoints_dir().iterdir()}
    out = tmp_path / "run"
    cmd = [
        sys.executable,
        "-m",
        "beatlite.train",
        "fit",
        "s2g_tiny",
        "--data",
        str(repo_root() / "data_samples"),
    ]
    env = {k: v for k, v in __import__("os").environ.items() if k != "BEATLITE_BUILD"}
    options = ["--epochs", "1", "--device", "cpu", "--batch-size", "24", "--lr-scaling", "sqrt",
               "--data-on-device", "always", "--precision", "bf16", "--compile", "aot_eager"]  # fmt: skip
    run_ok([*cmd, "--out", str(out), *options], env=env, timeout=600)
    assert (out / "s2g_tiny.pt").is_file() and (out / "train" / "s2g_tiny.pt").is_file()
    assert list((out / "build" / "cache" / "store").rglob("meta.json"))  # the window store went under --out
    assert list((out / "build" / "cache" / "index").glob("*.json"))  # and the index cache
    assert {p.name: p.stat().st_mtime_ns for p in checkpoints_dir().iterdir()} == before
    from beatlite.train.checkpoint import load_checkpoint

    full = load_checkpoint(out / "train" / "s2g_tiny.pt")
    assert full["epoch"] == 1 and full["train_config"]["device"] == "cpu"
    from beatlite.train.recipes import RECIPES

    recipe, used = RECIPES["s2g_tiny"], full["train_config"]
    assert used["batch_size"] == 24 and used["data_on_device"] == "always"
    assert used["amp"] is True and used["compile"] == "aot_eager"
    assert used["lr"] == pytest.approx(recipe.lr * (24 / recipe.batch_size) ** 0.5)
    assert full["best"] is not None  # the validation FGD scored the epoch


def small_corpus(root, stems):
    """The ``data_samples/`` takes ``stems`` copied into the new folder ``root``."""
    import shutil

    from beatlite.paths import repo_root

    root.mkdir()
    for stem in stems:
        for src in (repo_root() / "data_samples").glob(f"{stem}.*"):
            shutil.copy(src, root)
    return root


def test_training_data_reads_the_words_of_usable_takes_only(tmp_path, monkeypatch):
    """A malformed TextGrid makes its take unusable; ``training_data`` (what ``fit`` prepares) then skips its
    words as the windows skip its frames, instead of failing to read them: the vocabulary is that of the
    other takes' TextGrids, read here one by one."""
    from beatlite.data.vocab import vocab_from_sentences
    from beatlite.io import read_words
    from beatlite.train.recipes import training_data

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    good, bad = ["2_scott_0_9_9", "2_scott_0_57_57"], "2_scott_0_10_10"
    root = small_corpus(tmp_path / "corpus", [*good, bad])
    (root / f"{bad}.TextGrid").write_text(
        'File type = "ooTextFile"\nObject class = "TextGrid"\nxmin = 0\nxmax = garbage\n'
    )
    with pytest.warns(UserWarning, match="skipping 1 unusable"):
        data = training_data(root)
    assert not data.index[bad].usable and all(data.index[stem].usable for stem in good)
    expected = [list(read_words(root / f"{stem}.TextGrid").words) for stem in good]
    assert data.vocab.itos == vocab_from_sentences(expected).itos
    assert len(data.sentences) == 2
    # the evaluation set's default vocabulary is the same (a model trained by fit is scored with its word ids)
    from beatlite.data.index import index_folder
    from beatlite.train.testset import load_test_set

    with pytest.warns(UserWarning, match="skipping 1 unusable"):
        assert load_test_set(index_folder(root), split="val").vocab == data.vocab.itos


def test_fit_command_says_when_the_corpus_has_no_val_take(tmp_path, monkeypatch, capsys):
    """Two train takes and no val take: ``fit`` stops with one ``error:`` line saying the val split is empty
    and which takes BEAT's names put there (not a window store's "no take ... is at least 34 frames long")."""
    from beatlite.train import __main__ as command

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    root = small_corpus(tmp_path / "corpus", ["2_scott_0_9_9", "2_scott_0_10_10"])
    out = tmp_path / "run"
    assert command.main(["fit", "s2g_tiny", "--data", str(root), "--out", str(out), "--epochs", "1"]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith(f"error: training_data: {root} has no usable take of the 'val' split")
        and err.count("\n") == 1
    )
    assert "57-64" in err and not (out / "fgd_dirvec.pt").exists()


def test_fit_command_names_the_folder_it_cannot_write_in_one_error_line(tmp_path, monkeypatch, capsys):
    """A store or ``--out`` folder that cannot be written (here one under a regular file; a full disk or a
    read-only folder alike) ended ``fit`` with a traceback (exit 1); it is one ``error:`` line naming it, exit 2."""
    from beatlite.train import __main__ as command

    root = small_corpus(tmp_path / "corpus", ["2_scott_0_9_9", "2_scott_0_57_57"])  # a train and a val take
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(
        "BEATLITE_BUILD", str(blocker / "build")
    )  # the index cache is skipped, the store fails
    argv = ["fit", "random_clip", "--data", str(root), "--epochs", "0"]
    for out, said in ((tmp_path / "run", f"cannot write the window store {blocker / 'build'}"),
                      (blocker / "run", f"cannot write --out {blocker / 'run'}")):  # fmt: skip
        assert command.main([*argv, "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: ") and said in err and err.count("\n") == 1, err


class _Stop(Exception):
    """Raised by a stand-in ``fit``, with the config it was given."""


def _fit_command_with(fit, tmp_path, monkeypatch) -> list[str]:
    """The arguments of ``fit diffgesture_tiny`` on data_samples with its data, model and training stood in for
    (``fit`` replaces :func:`beatlite.train.training.fit`); a recipe without best-epoch selection: no extractor or
    validation takes to stand in for."""
    import types

    from beatlite.paths import repo_root
    from beatlite.train import __main__ as command
    from beatlite.train import recipes, training

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    data = types.SimpleNamespace(train=None, val=None, meta={})
    monkeypatch.setattr(command, "training_data", lambda folder, progress: data)
    monkeypatch.setattr(recipes, "build_recipe_model", lambda name, data, seed, preset="tiny": None)
    monkeypatch.setattr(training, "fit", fit)
    return [
        "fit",
        "diffgesture_tiny",
        "--data",
        str(repo_root() / "data_samples"),
        "--out",
        str(tmp_path / "run"),
    ]


def test_fit_command_passes_val_every_to_the_training_config(tmp_path, monkeypatch):
    """``fit --val-every N``, ``--nondeterministic`` and ``--audio-matmul`` reach ``TrainConfig`` (data, model and
    training stood in for)."""
    from beatlite.train import __main__ as command

    def stand_in_fit(model, train, config, val=None, **kw):
        raise _Stop(config)

    argv = _fit_command_with(stand_in_fit, tmp_path, monkeypatch)
    for extra, expected in (([], None), (["--val-every", "25"], 25)):
        with pytest.raises(_Stop) as stopped:
            command.main([*argv, "--epochs", "1", *extra])
        assert stopped.value.args[0].val_every == expected
    for extra, expected in (([], True), (["--nondeterministic"], False)):
        with pytest.raises(_Stop) as stopped:
            command.main([*argv, "--epochs", "1", *extra])
        assert stopped.value.args[0].deterministic is expected
    for extra, expected in (
        ([], "auto"),
        (["--audio-matmul", "on"], "on"),
        (["--audio-matmul", "off"], "off"),
    ):
        with pytest.raises(_Stop) as stopped:
            command.main([*argv, "--epochs", "1", *extra])
        assert stopped.value.args[0].audio_matmul == expected


def test_fit_command_refuses_bad_flag_values_before_preparing_anything(tmp_path, monkeypatch, capsys):
    """Values ``TrainConfig`` refuses, zero epochs of a recipe that trains and CUDA on a machine without it stop
    ``fit`` at once: exit 2, one ``error:`` line naming the value, nothing indexed or written under ``--out``."""
    torch = pytest.importorskip("torch")
    from beatlite.paths import repo_root
    from beatlite.train import __main__ as command
    from beatlite.train.recipes import recipe_train_config

    def no_data(folder, progress):
        raise AssertionError("the data were prepared")

    monkeypatch.setattr(command, "training_data", no_data)
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    out = tmp_path / "run"
    argv = ["fit", "camn_tiny", "--data", str(repo_root() / "data_samples"), "--out", str(out)]
    cases = ((["--checkpoint-every", "0"], "checkpoint_every must be >= 1"),
             (["--batch-size", "1"], "batch_size must be >= 2"), (["--val-every", "0"], "val_every must be >= 1"),
             (["--epochs", "-1"], "camn_tiny: epochs must be >= 1"), (["--epochs", "0"], "camn_tiny: epochs must be >= 1"),
             (["--device", "cuda"], "device 'cuda' asked for CUDA"), (["--device", "gpu"], "not a torch device"),
             (["--preset", "huge"], "camn_tiny: camn has no preset 'huge' (its presets: paper, tiny)"),
             (["--lr", "0"], "lr must be positive"))  # fmt: skip
    for extra, said in cases:
        assert command.main([*argv, *extra]) == 2, extra
        err = capsys.readouterr().err
        assert err.startswith("error: ") and said in err and err.count("\n") == 1, (extra, err)
    # under torchrun --nproc_per_node=4 (WORLD_SIZE, as it sets it; no process group is started here), a global
    # batch of 6 leaves a process 1 window: every step was skipped and the untrained weights were exported
    monkeypatch.setenv("WORLD_SIZE", "4")
    assert command.main([*argv, "--batch-size", "6"]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith("error: fit: batch_size 6 split into 4 micro-batches (4 processes")
        and err.count("\n") == 1
    )
    assert not out.exists()
    assert recipe_train_config("random_clip", epochs=0).epochs == 0  # an untrained baseline: nothing to train


def test_fit_command_reports_a_refused_resume_as_one_error_line(tmp_path, monkeypatch, capsys):
    """A ``ResumeError`` of ``fit --resume`` (data, model or batch plan changed) ends the command with exit 2 and
    its message on one ``error:`` line, no traceback (data and training stood in for)."""
    from beatlite.train import __main__ as command
    from beatlite.train import training

    def refusing_fit(model, train, config, val=None, **kw):
        raise training.ResumeError("fit: cannot resume from x.pt: changed: batch_size 32 -> 64")

    argv = _fit_command_with(refusing_fit, tmp_path, monkeypatch)
    assert command.main([*argv, "--epochs", "1", "--resume"]) == 2
    err = capsys.readouterr().err
    assert err == "error: fit: cannot resume from x.pt: changed: batch_size 32 -> 64\n"


def test_fit_command_refuses_a_second_run_of_the_recipe_into_the_same_out(tmp_path, monkeypatch, capsys):
    """Two ``fit`` runs of one recipe into one ``--out`` at once both trained and wrote the same checkpoints (the
    resumable one and the export were whichever run wrote last, and both said they wrote them): a run holds
    ``<out>/train/.<RECIPE>.lock`` while it trains, and a second one refuses at once with one ``error:`` line,
    exit 2, before preparing anything; another recipe into the same ``--out`` is not held up."""
    from beatlite.io.atomic import exclusive_lock
    from beatlite.train import __main__ as command

    calls = []

    def stand_in_fit(model, train, config, val=None, **kw):
        calls.append(config.checkpoint)
        with pytest.raises(BlockingIOError):  # while this run trains, its lock is held
            with exclusive_lock(tmp_path / "run" / "train" / ".diffgesture_tiny.lock", wait=False):
                pass
        raise _Stop(config)

    argv = [*_fit_command_with(stand_in_fit, tmp_path, monkeypatch), "--epochs", "1"]
    with pytest.raises(_Stop):
        command.main(argv)
    assert len(calls) == 1
    with exclusive_lock(tmp_path / "run" / "train" / ".diffgesture_tiny.lock"):  # another run trains it
        monkeypatch.setattr(command, "training_data", lambda folder, progress: pytest.fail("data prepared"))
        assert command.main(argv) == 2
        err = capsys.readouterr().err
        assert (
            err.startswith("error: another fit is training diffgesture_tiny into ") and err.count("\n") == 1
        )
        with exclusive_lock(tmp_path / "run" / "train" / ".s2g_tiny.lock", wait=False):  # (another recipe's)
            pass
    assert len(calls) == 1


def test_fit_command_trains_the_extractor_again_for_other_data_or_epochs(tmp_path, monkeypatch, capsys):
    """``<out>/fgd_dirvec.pt`` is kept while its recorded data fingerprint and epochs are this run's train
    windows' and ``--extractor-epochs``, trained again (saying why) when either changes (data, extractor
    training and model training stood in for)."""
    import types

    from beatlite.metrics.extractor import ExtractorConfig, MotionAutoencoder, save_extractor
    from beatlite.train import __main__ as command

    trained = []

    def stand_in_train_extractor(data_dir, path, epochs):
        trained.append((data.train.fingerprint, epochs))
        model = MotionAutoencoder(ExtractorConfig(input_dim=126, latent_dim=4, channels=8, epochs=epochs))
        info = {"mean": np.zeros(126), "std": np.ones(126), "history": []}
        save_extractor(path, model, info, space="dirvec", meta={"data_fingerprint": data.train.fingerprint})

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    data = types.SimpleNamespace(train=types.SimpleNamespace(fingerprint="a" * 16), val=None, meta={})
    monkeypatch.setattr(command, "training_data", lambda folder, progress: data)
    monkeypatch.setattr(command, "_train_extractor", stand_in_train_extractor)
    monkeypatch.setattr(command, "retrain", lambda name, **kw: 0.0)
    out = tmp_path / "run"
    argv = [
        "fit",
        "s2g_tiny",
        "--data",
        str(tmp_path / "corpus"),
        "--out",
        str(out),
        "--extractor-epochs",
        "3",
    ]
    for _ in range(2):
        assert command.main(argv) == 0
    assert trained == [("a" * 16, 3)]  # once, then kept
    assert "stale" not in capsys.readouterr().out
    data.train.fingerprint = "b" * 16  # another corpus fitted into the same --out
    assert command.main(argv) == 0
    assert trained[-1] == ("b" * 16, 3)
    assert f"trained on data {'a' * 16}, the train windows are {'b' * 16}" in capsys.readouterr().out
    assert command.main([*argv[:-1], "5"]) == 0
    assert trained[-1] == ("b" * 16, 5) and len(trained) == 3
    assert "trained for 3 epochs, --extractor-epochs is 5" in capsys.readouterr().out


def test_fit_command_refuses_inductor_for_a_model_stating_a_failure_before_preparing_anything(
    tmp_path, capsys, monkeypatch
):
    """A model's ``inductor_failure`` (none ships one; stated here for HA2G): ``fit ha2g_tiny --compile
    default`` stops at once (exit 2, the reason on stderr), before the data are indexed or anything is
    written under ``--out``."""
    from beatlite.models.ha2g import HA2G
    from beatlite.paths import repo_root
    from beatlite.train import __main__ as command

    monkeypatch.setattr(HA2G, "inductor_failure", "a stated reason")
    out = tmp_path / "run"
    argv = ["fit", "ha2g_tiny", "--data", str(repo_root() / "data_samples"), "--out", str(out)]
    assert command.main([*argv, "--compile", "default"]) == 2
    err = capsys.readouterr().err
    assert "ha2g cannot be compiled with inductor" in err and "a stated reason" in err
    assert not out.exists()


def test_ablation_table_values_changes_and_paper_rows():
    from beatlite.train.seeds import SeedResults, ablation_table

    rec = SeedResults(
        {
            "Full": {"FGD": [1.0, 2.0, 3.0], "SRGR": [0.2, 0.2, 0.2]},
            "No X": {"FGD": [5.0, 6.0, 7.0], "SRGR": [0.1, 0.1, 0.1]},
        },
        [1, 2, 3],
        {},
    )
    paper = {"full": {"FGD": 9.0}, "w/o X": {"FGD": 12.0}}
    text = ablation_table(rec, "Full", {"Full": "full", "No X": "w/o X"}, paper, deltas=("FGD", "SRGR"))
    lines = text.splitlines()
    assert lines[0].startswith(
        "| variant | paper row | paper FGD ↓ | paper SRGR ↑ | ours FGD ↓ | ours SRGR ↑ |"
    )
    full, no_x = lines[2].split(" | "), lines[3].split(" | ")
    assert full[2:6] == ["9.00", "—", "2.00 ± 1.00", "0.200 ± 0.000"]
    # FGD: +4 with SE sqrt(1/3 + 1/3) = 0.816 -> 2 SE 1.63: worse (FGD is lower-is-better)
    assert no_x[6] == "+4.00 ± 1.63 worse"
    # SRGR: -0.1 with SE 0 -> worse
    assert no_x[7] == "-0.100 ± 0.000 worse"
    assert lines[3].endswith("| 3 |")


def test_ablation_table_shows_the_papers_value_of_a_metric_beside_our_variant():
    # The paper reports "BC"; our column is the variant "BC (ha2g)": the paper's column is headed "paper BC" and
    # holds the paper's BC; a variant's change gets the metric's 3 decimals.
    from beatlite.train.seeds import SeedResults, ablation_table

    rec = SeedResults(
        {"Full": {"BC (ha2g)": [0.70, 0.72, 0.74]}, "A": {"BC (ha2g)": [0.60, 0.61, 0.62]}}, [1, 2, 3], {}
    )
    paper = {"full": {"BC": 0.727}, "a": {"BC": 0.651}}
    lines = ablation_table(
        rec, "Full", {"Full": "full", "A": "a"}, paper, metrics=("BC (ha2g)",), deltas=("BC (ha2g)",)
    )
    lines = lines.splitlines()
    assert lines[0] == "| variant | paper row | paper BC ↑ | ours BC (ha2g) ↑ | Δ BC (ha2g) ± 2 SE | seeds |"
    # -0.11, SE sqrt(0.02^2/3 + 0.01^2/3) = 0.0129 -> 2 SE 0.026: worse (BC is higher-is-better)
    assert lines[3] == "| A | a | 0.651 | 0.610 ± 0.010 | -0.110 ± 0.026 worse | 3 |"


def test_the_shipped_checkpoint_is_the_median_seed_and_the_replaced_one_is_kept(tmp_path, monkeypatch):
    pytest.importorskip("torch")
    from beatlite.train import checkpoint, seeds

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    import beatlite.paths

    monkeypatch.setattr(beatlite.paths, "checkpoints_dir", lambda: tmp_path / "checkpoints")
    for seed in (1, 2, 3):
        data = _checkpoint_of("s2g_tiny")
        data["train_config"]["seed"] = seed
        target = (
            tmp_path / "checkpoints" / "s2g_tiny.pt" if seed == 1 else seeds.checkpoint_path("s2g_tiny", seed)
        )
        checkpoint.save_checkpoint(target, data)
    assert seeds.checkpoint_path("s2g_tiny", 1) == tmp_path / "checkpoints" / "s2g_tiny.pt"
    # FGD 5.0, 3.0, 4.0 over seeds 1, 2, 3: the median is seed 3's
    record = SeedResults({"S2G-style": {"FGD": [5.0, 3.0, 4.0]}}, [1, 2, 3], {})
    assert seeds.ship_median_seeds(record) == {"s2g_tiny": 3}
    assert seeds.shipped_seed(tmp_path / "checkpoints" / "s2g_tiny.pt") == 3
    assert record.info["shipped"] == {"S2G-style": 3}
    # seed 1's checkpoint (shipped until now) is still there for its seed
    assert seeds.shipped_seed(seeds.checkpoint_path("s2g_tiny", 1)) == 1
    assert seeds.checkpoint_path("s2g_tiny", 3) == tmp_path / "build" / "seeds" / "3" / "s2g_tiny.pt"


def test_an_undecided_difference_says_how_many_seeds_would_decide_it():
    from beatlite.train.seeds import compare_rows

    # sd 1 in both rows, delta 1: 2 se(n) = 2 sqrt(2 / n) is 1.0 at n = 8 (still noise: 1.0 is not > 1.0),
    # below 1 from n = 9 seeds
    rec = SeedResults({"Full": {"FGD": [1.0, 2.0, 3.0]}, "A": {"FGD": [2.0, 3.0, 4.0]}}, [1, 2, 3], {})
    (effect,) = compare_rows(rec, "Full", ["A"], metrics=("FGD",))
    assert effect.verdict == "noise" and effect.seeds_needed == 9
    assert effect.cell() == "+1.00 ± 1.63 noise (9 seeds)"
    n = effect.seeds_needed
    assert 2 * math.sqrt(2 / n) < abs(effect.delta) <= 2 * math.sqrt(2 / (n - 1))
    same = SeedResults({"Full": {"FGD": [1.0, 2.0]}, "A": {"FGD": [2.0, 1.0]}}, [1, 2], {})
    assert compare_rows(same, "Full", ["A"], metrics=("FGD",))[0].seeds_needed is None  # no difference


def test_retrain_all_uses_the_recorded_shipped_seed(tmp_path):
    import json

    from beatlite.train.seeds import recorded_shipped_seed

    record = SeedResults(
        {"S2G-style": {"FGD": [1.0, 2.0, 3.0]}}, [2021, 2022, 2023], {"shipped": {"S2G-style": 2022}}
    )
    path = tmp_path / "results_seeds.json"
    path.write_text(json.dumps(record.to_dict()))
    assert recorded_shipped_seed("s2g_tiny", path) == 2022
    assert recorded_shipped_seed("camn_tiny", path) == SEED  # a row the record does not name
    assert recorded_shipped_seed("camn_tiny", tmp_path / "none.json") == SEED


#: Other speakers for the copies of data_samples' speakers 2, 4, 6, 8 (a BEAT name must parse).
OTHER_SPEAKERS = [{2: "1_wayne", 4: "3_solomon", 6: "5_stewart", 8: "7_sophie"},
                  {2: "9_miranda", 4: "11_nidal", 6: "13_lu", 8: "15_carlos"},
                  {2: "17_jorge", 4: "19_jaime", 6: "21_ayana", 8: "23_hailing"}]  # fmt: skip


def symlinked_corpus(root, copies: int):
    """data_samples/ ``copies`` times over (copy 0 as it is, the others under other speakers), as symlinks."""
    from beatlite.paths import repo_root

    root.mkdir()
    for src in (repo_root() / "data_samples").iterdir():
        sid, _, rest = src.name.partition("_")
        if not sid.isdigit():
            continue
        for k in range(copies):
            name = src.name if k == 0 else f"{OTHER_SPEAKERS[k - 1][int(sid)]}_{rest.partition('_')[2]}"
            (root / name).symlink_to(src)
    return root


PEAK_RSS = """
import resource, subprocess, sys
done = subprocess.run(sys.argv[1:], capture_output=True, text=True)
sys.stderr.write(done.stderr[-6000:])
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)  # KiB: the largest process of the command
sys.exit(done.returncode)
"""


@pytest.mark.slow
def test_fit_command_memory_does_not_grow_with_the_corpus(tmp_path):
    """``fit`` reads windows from the store: on 4x the corpus its peak RSS stays within 150 MB of 1x
    (the in-memory windows it built before would add about 3 x 190 MB: 658 train + 153 val windows of
    about 244 KB per copy)."""
    import os
    import sys

    peaks = {}
    for copies in (1, 4):
        corpus = symlinked_corpus(tmp_path / f"corpus{copies}", copies)
        out = tmp_path / f"run{copies}"
        cmd = [sys.executable, "-m", "beatlite.train", "fit", "s2g_tiny", "--data", str(corpus), "--out", str(out),
               "--epochs", "1", "--device", "cpu", "--extractor-epochs", "1"]  # fmt: skip
        env = {k: v for k, v in os.environ.items() if k != "BEATLITE_BUILD"}
        done = run_ok([sys.executable, "-c", PEAK_RSS, *cmd], env=env, timeout=1200)
        peaks[copies] = int(done.stdout.strip().splitlines()[-1]) / 1024  # MiB
        assert (out / "s2g_tiny.pt").is_file() and (out / "fgd_dirvec.pt").is_file()
    from beatlite.data.store import WindowStore

    train = [WindowStore.open(next((tmp_path / f"run{c}" / "build" / "cache" / "store").iterdir())).n_frames("train")
             for c in (1, 4)]  # fmt: skip
    assert train[1] >= 3 * train[0], train  # (the 1-hour speakers' split rule leaves a few copied takes out)
    print(f"peak RSS: 1x {peaks[1]:.0f} MiB, 4x {peaks[4]:.0f} MiB")
    assert peaks[4] < peaks[1] + 150, peaks


def test_every_paper_row_of_a_recipe_is_a_published_row_and_every_published_row_has_one():
    from beatlite.train.evaluation import PAPER_TABLES
    from beatlite.train.recipes import RECIPES, paper_rows

    for name, recipe in RECIPES.items():
        for row in recipe.paper_rows:
            assert (row.paper, row.table) in PAPER_TABLES, (name, row)
            assert row.row is None or row.row in PAPER_TABLES[row.paper, row.table], (name, row)
    for (paper, table), rows in PAPER_TABLES.items():
        ours = set(paper_rows(paper, [table]).values())
        if table in ("Table 3", "Table 4"):  # one published dict for both HA2G studies: "(T3)" / "(T4)" rows
            rows = [r for r in rows if not r.endswith(")") or r.endswith(f"(T{table[-1]})")]
        missing = set(rows) - ours - {"Ground Truth", "HA2G-ASR (T3)"}  # no checkpoint can stand for these
        assert not missing, (paper, table, missing)
    # the order of the ablation tables: the full model, then each study's rows in RECIPES order
    ablations = paper_rows("HA2G", ["Table 3", "Table 4"])
    assert list(ablations.values())[:2] == ["HA2G Full", "f_a^low only (T3)"]
    assert ablations["ha2g_tiny_no_contrastive"] is None and list(ablations)[-1] == "ha2g_tiny_no_physical"
    assert paper_rows("BEAT", ["Table 4"], ["camn_tiny", "mean_pose"]) == {"camn_tiny": "CaMN"}


def test_seeds_only_records_its_rows_into_the_table_beside_the_others(tmp_path, monkeypatch, capsys):
    """`make seeds ONLY=NAME` (`seeds --only NAME --out checkpoints/results_seeds`) keeps the other rows."""
    import argparse

    from beatlite.train import __main__ as cli
    from beatlite.train.seeds import recorded_seed_results, write_seed_results

    out = tmp_path / "results_seeds"
    write_seed_results(SeedResults({"CaMN": {"FGD": [3.0, 4.0]}}, [1, 2], {"shipped": {"CaMN": 1}}), out)
    mine = SeedResults({"Mine": {"FGD": [2.0, 2.5]}}, [1, 2], {"shipped": {"Mine": 2}})
    monkeypatch.setattr(cli, "evaluate_seeds", lambda *a, **kw: mine)
    args = argparse.Namespace(
        only=["mine_tiny"], seeds=[1, 2], evaluate_only=True, jobs=1, force=False, ship=False
    )
    assert cli._seeds_command(argparse.Namespace(**vars(args), out=str(out))) == 0
    back = recorded_seed_results(f"{out}.json")
    assert back.values == {"CaMN": {"FGD": [3.0, 4.0]}, "Mine": {"FGD": [2.0, 2.5]}}
    assert back.info["shipped"] == {"CaMN": 1, "Mine": 2}
    # without --only the table is the new one alone
    assert cli._seeds_command(argparse.Namespace(**{**vars(args), "only": None}, out=str(out))) == 0
    assert list(recorded_seed_results(f"{out}.json").values) == ["Mine"]


def test_scaled_lr_follows_the_batch_linearly_or_by_its_square_root():
    from beatlite.train import TrainConfig
    from beatlite.train.recipes import Recipe, scaled_lr

    recipe = Recipe("camn", "CaMN", batch_size=32, lr=2e-3)
    assert scaled_lr(recipe, 32) == scaled_lr(recipe, 32, "sqrt") == 2e-3
    assert scaled_lr(recipe, 8) == pytest.approx(2e-3 / 4) and scaled_lr(recipe, 8, "sqrt") == pytest.approx(
        1e-3
    )
    default = Recipe(
        "ha2g", "HA2G", batch_size=64, lr=None
    )  # TrainConfig's default rate, linear in the batch
    assert scaled_lr(default, 256) is None
    assert TrainConfig(batch_size=256).learning_rate == pytest.approx(
        4 * TrainConfig(batch_size=64).learning_rate
    )
    assert scaled_lr(default, 256, "sqrt") == pytest.approx(2 * TrainConfig(batch_size=64).learning_rate)
    with pytest.raises(ValueError, match="sqrt"):
        scaled_lr(recipe, 64, "cubic")
    with pytest.raises(ValueError, match="batch_size must be >= 1"):
        scaled_lr(recipe, 0, "sqrt")


def test_results_command_names_a_checkpoint_that_is_not_there(monkeypatch, capsys):
    """``results --only NAME`` of no checkpoint: one ``error:`` line naming it (and those there), exit 2, before any
    evaluation (it was a FileNotFoundError traceback after loading the test set)."""
    from beatlite.train import __main__ as command

    def no_evaluation(*args, **kwargs):
        raise AssertionError("evaluated")

    monkeypatch.setattr(command, "evaluate_models", no_evaluation)
    assert command.main(["results", "--only", "camn_tiny", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: results: no checkpoint nope in ") and err.count("\n") == 1
    assert "camn_tiny" in err.split("(there: ")[1] and "fgd_dirvec" not in err


def test_checkpoints_name_no_folder_of_the_machine_that_wrote_them(tmp_path, monkeypatch):
    """``retrain``'s resumable and exported checkpoints, made to be shared, record the data folder by its name and the
    resumable checkpoint by its file name (before: ``meta["data"]`` and ``train_config["checkpoint"]`` were absolute
    paths, e.g. ``/home/alice/corpus``, naming the writer's home folder and user); ``export_checkpoint`` writes such
    names for a checkpoint of an older beatlite too. Checked on the files' bytes."""
    import torch

    from beatlite.train.checkpoint import export_checkpoint, load_checkpoint, save_checkpoint
    from beatlite.train.recipes import training_data

    home = tmp_path / "home" / "alice"
    home.mkdir(parents=True)
    monkeypatch.setenv("BEATLITE_BUILD", str(home / "build"))
    root = small_corpus(home / "corpus", ["2_scott_0_9_9", "2_scott_0_57_57"])
    retrain("mean_pose", out_dir=home / "run", data=training_data(root), progress=False)
    written = [home / "run" / "mean_pose.pt", home / "run" / "train" / "mean_pose.pt"]
    for path in written:
        data = load_checkpoint(path)
        assert data["meta"]["data"] == "corpus" and data["train_config"]["checkpoint"] == "mean_pose.pt", path
    old = load_checkpoint(written[1])  # as an older beatlite wrote it
    old["meta"]["data"], old["train_config"]["checkpoint"] = str(root), str(written[1])
    save_checkpoint(home / "old.pt", old)
    assert str(root).encode() in (home / "old.pt").read_bytes()  # (the check below sees such paths)
    export_checkpoint(home / "old.pt", home / "shared.pt")
    shared = load_checkpoint(home / "shared.pt")
    assert shared["meta"]["data"] == "corpus" and shared["train_config"]["checkpoint"] == "mean_pose.pt"
    assert torch.equal(shared["state"]["mean"], old["state"]["mean"].half())
    for path in [*written, home / "shared.pt"]:
        raw = path.read_bytes()
        assert str(tmp_path).encode() not in raw and b"alice" not in raw, path


FIRST_STEPS = {
    "s2g_tiny": (351.54962158203125, 363.60009765625, 329.1720275878906),
    "trimodal_tiny": (309.51220703125, 333.9689025878906, 313.64263916015625),
    "seq2seq_tiny": (221.4296875, 253.5569610595703, 221.08889770507812),
    "a2g_tiny": (2.1895740032196045, 2.3496880531311035, 2.2336037158966064),
    "joint_embedding_tiny": (0.6799216866493225, 0.7162935733795166, 0.6759359836578369),
    "camn_tiny": (406.6547546386719, 421.4700012207031, 404.4474182128906),
    "ha2g_tiny": (212.46322631835938, 181.69532775878906, 179.2856903076172),
    "diffgesture_tiny": (0.8908261656761169, 0.672417402267456, 0.6887287497520447),
}
"""The total loss of the first three optimiser steps of each model's first recipe (seed 2021, one batch of the
recipe's size per step, ``data_samples/``), recorded on 2026-11-27 (torch 2.13.0+cpu, one thread). 441ba3b, the
code of the seed table's CaMN, HA2G, S2G, Trimodal and Seq2Seq rows, gives the same five rows to the bit; A2G's
seed rows were re-recorded with the code of these numbers (README, "Larger batches")."""


@pytest.mark.slow
def test_the_first_training_steps_are_the_recorded_ones():
    """A change to what a recipe trains (its data, initialisation, random draws, losses, optimiser, frozen
    parameters) moves these numbers, and then the seed table's rows of that model (checkpoints/results_seeds.json,
    the shipped checkpoint) no longer describe the code: retrain them (`make seeds ONLY=NAME`) and record the new
    values here, or say in the commit why the rows stand. Kernels and thread counts move them by at most 9.1e-7
    (measured here: BEATLITE_THREADS=2, ONEDNN_MAX_CPU_ISA=AVX2 or SSE41, ATEN_CPU_CAPABILITY=avx2 or default); A2G's
    frozen log-variance heads moved its second step by 2.3e-4: rtol 2e-5 holds on any machine and sees such a change."""
    pytest.importorskip("torch")
    from beatlite.train.config import TrainConfig
    from beatlite.train.recipes import build_recipe_model, training_data
    from beatlite.train.training import fit

    data = training_data()
    firsts = {}
    for name, recipe in RECIPES.items():
        if recipe.epochs > 0:
            firsts.setdefault(recipe.model, name)
    assert sorted(firsts.values()) == sorted(FIRST_STEPS), "a new model: record its first steps here"
    moved = {}
    for name in firsts.values():
        recipe = RECIPES[name]
        config = TrainConfig(
            epochs=3,
            batch_size=recipe.batch_size,
            lr=recipe.lr,
            lr_schedule=recipe.lr_schedule,
            seed=2021,
            windows_per_epoch=recipe.batch_size,
            progress=False,
        )
        model = build_recipe_model(name, data, seed=2021)
        got = [epoch["train"]["total"] for epoch in fit(model, data.train, config, meta=data.meta).history]
        if not np.allclose(got, FIRST_STEPS[name], rtol=2e-5, atol=0):
            moved[name] = got
    assert not moved, f"training numbers changed (recorded: FIRST_STEPS): {moved}"


def test_a_recipe_states_its_batch_and_learning_rate_on_cuda(monkeypatch):
    """``Recipe.gpu_batch_size`` and ``gpu_lr``: with no batch size given, ``recipe_train_config`` (the ``fit``
    command) trains on CUDA at that batch and rate (CaMN's: the reference trainer's 256 at 5e-4,
    docs/reference_code.md), ``--lr`` still overriding the rate; on the CPU, or with a batch size given, the
    recipe's batch and its rate scaled to it. (CUDA is stood in for: ``torch.device("cuda")`` needs no GPU.)"""
    torch = pytest.importorskip("torch")
    from beatlite.train.recipes import RECIPES, recipe_train_config

    recipe = RECIPES["camn_tiny"]
    assert (recipe.gpu_batch_size, recipe.gpu_lr, recipe.batch_size, recipe.lr) == (256, 5e-4, 32, 2e-3)
    cpu = recipe_train_config("camn_tiny", device="cpu")
    assert (cpu.batch_size, cpu.lr) == (32, 2e-3)
    monkeypatch.setattr(torch.cuda, "is_available", lambda: True)
    for rule in ("linear", "sqrt"):  # (a stated rate is not scaled)
        config = recipe_train_config("camn_tiny", device="cuda", lr_scaling=rule)
        assert (config.batch_size, config.lr) == (256, 5e-4)
    assert recipe_train_config("camn_tiny", device="auto").batch_size == 256
    assert recipe_train_config("camn_tiny", device="cuda", lr=1e-3).lr == 1e-3
    given = recipe_train_config("camn_tiny", device="cuda", batch_size=64)
    assert given.batch_size == 64 and given.lr == pytest.approx(
        recipe.lr * 2, rel=1e-12
    )  # linear, 2e-3 x 64/32
    assert RECIPES["s2g_tiny"].gpu_batch_size is None
    s2g = recipe_train_config("s2g_tiny", device="cuda")
    assert (s2g.batch_size, s2g.lr) == (RECIPES["s2g_tiny"].batch_size, RECIPES["s2g_tiny"].lr)


def test_fit_command_trains_the_paper_preset_under_its_own_name_at_the_lr_given(tmp_path, monkeypatch):
    """``fit RECIPE --preset paper --lr LR``: the recipe's model at the paper's size (the recipe's switches on
    top), the generator at ``LR`` whatever the batch, the checkpoints named ``RECIPE-paper`` (a tiny run's
    beside it is another file). The model is built for real; the training is stood in for."""
    from beatlite.models import build_model
    from beatlite.train import __main__ as command
    from beatlite.train import recipes

    real_build = recipes.build_recipe_model  # (_fit_command_with stands one in)
    seen = {}

    def stand_in_fit(model, train, config, val=None, **kw):
        seen.update(model=model, config=config)
        raise _Stop(config)

    argv = _fit_command_with(stand_in_fit, tmp_path, monkeypatch)
    monkeypatch.setattr(recipes, "build_recipe_model", real_build)
    with pytest.raises(_Stop):
        command.main([*argv, "--epochs", "1", "--preset", "paper", "--batch-size", "8", "--lr", "5e-4"])
    model, config = seen["model"], seen["config"]
    paper = build_model("diffgesture", preset="paper", seed=SEED)  # (its config draws with the training seed)
    assert model.config.preset == "paper" and model.config == paper.config
    assert config.lr == 5e-4 and config.batch_size == 8
    assert str(config.checkpoint).endswith("train/diffgesture_tiny-paper.pt")
    with pytest.raises(_Stop):
        command.main([*argv, "--epochs", "1", "--batch-size", "8"])
    assert seen["model"].config.preset == "tiny"
    assert str(seen["config"].checkpoint).endswith("train/diffgesture_tiny.pt")
    assert seen["config"].lr == recipes.scaled_lr(recipes.RECIPES["diffgesture_tiny"], 8)


def test_retrain_writes_a_paper_preset_run_under_its_own_name(tmp_path, monkeypatch):
    """``retrain(name, preset="paper")`` exports ``name-paper.pt`` (and its resumable ``train/`` copy), whose
    config is the paper preset's: it loads as that model (mean_pose, a recipe of no training steps)."""
    from beatlite.train.checkpoint import load_model
    from beatlite.train.recipes import training_data

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    data = training_data(small_corpus(tmp_path / "corpus", ["2_scott_0_9_9", "2_scott_0_57_57"]))
    retrain("mean_pose", out_dir=tmp_path / "run", data=data, progress=False, preset="paper")
    assert sorted(p.name for p in (tmp_path / "run").rglob("*.pt")) == [
        "mean_pose-paper.pt",
        "mean_pose-paper.pt",
    ]
    for path in (tmp_path / "run" / "mean_pose-paper.pt", tmp_path / "run" / "train" / "mean_pose-paper.pt"):
        model, _ = load_model(path)
        assert model.config.preset == "paper"
    with pytest.raises(ValueError, match="mean_pose has no preset 'huge'"):
        retrain("mean_pose", out_dir=tmp_path / "run", data=data, progress=False, preset="huge")
