"""Run by tests/test_train_distributed.py under ``torchrun``: two epochs of the CaMN tiny recipe (dropout 0)
over 48 windows (3 steps of 16 per epoch) with a checkpoint after every step, written to ``argv[1]``.
With ``argv[2] == "kill"`` every process stops in its 5th optimiser step (epoch 2, step 2), then resumes
from the checkpoint; process 0 saves the final parameters and history to ``argv[1] + ".out"``. With
``argv[3] == "val"`` it also validates every 2 steps (``val_every=2``: the val windows' losses and a score that
is a function of the weights alone) and saves the run's best too. With ``argv[3] == "dropout"`` the model keeps
its dropout (each process draws its own masks) and process 0 validates after every epoch with a score that also
draws random numbers (as HA2G's validation does), so that its generator runs ahead of process 1's."""

import sys

import torch
from ddp_model import camn_without_dropout
from killed_run import step_killed_after

from beatlite.train import TrainConfig, fit
from beatlite.train.distributed import distributed_rank
from beatlite.train.recipes import RECIPES, build_recipe_model, training_data

path, mode = sys.argv[1], sys.argv[2]
validate = sys.argv[3:] == ["val"]
dropout = sys.argv[3:] == ["dropout"]
data = training_data()


def config(resume: bool) -> TrainConfig:
    return TrainConfig(
        epochs=2, batch_size=16, lr=RECIPES["camn_tiny"].lr, seed=7, windows_per_epoch=48, no_adv_epochs=0,
        threads=1, progress=False, checkpoint=path, checkpoint_every=1, resume=resume,
        val_every=2 if validate else None,
    )  # fmt: skip


def weight_score(model) -> float:
    """The same for the same weights (however many times it was called before)."""
    return float(sum(p.double().square().sum() for p in model.parameters()))


def drawing_score(model) -> float:
    """:func:`weight_score`, after drawing from torch's generator (process 0's, where it is called)."""
    torch.rand(8)
    return weight_score(model)


val = {"val_windows": data.val, "val_score": weight_score} if validate else {}
if dropout:
    val = {"val_score": drawing_score}


def model():
    return build_recipe_model("camn_tiny", data, seed=7) if dropout else camn_without_dropout(data)


net = model()
if mode == "kill":
    with step_killed_after(4):
        try:
            fit(net, data.train, config(False), meta=data.meta, **val)
        except KeyboardInterrupt:
            pass
    net = model()
result = fit(net, data.train, config(mode == "kill"), meta=data.meta, **val)
if distributed_rank()[0] == 0:
    params = {k: v.detach() for k, v in net.named_parameters()}
    best = (result.best_epoch, result.best_step, result.best_score)
    torch.save({"params": params, "history": result.history, "best": best}, path + ".out")
