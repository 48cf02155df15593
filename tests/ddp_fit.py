"""Run by tests/test_train_distributed.py under ``torchrun`` (and once without it): one epoch of the
CaMN tiny recipe (dropout 0, so that nothing random differs between processes) on data_samples' train
windows, then process 0 saves the parameters to argv[1]."""

import sys

import torch

from beatlite.train import TrainConfig, fit
from beatlite.train.recipes import RECIPES, build_recipe_model, training_data
from beatlite.train.training import distributed_rank

out, micro = sys.argv[1], int(sys.argv[2])
data = training_data()
recipe = RECIPES["camn_tiny"]
model = build_recipe_model("camn_tiny", data, seed=7)
for module in model.modules():  # dropout 0: the processes draw no random masks
    if isinstance(module, torch.nn.Dropout):
        module.p = 0.0
config = TrainConfig(
    epochs=1, batch_size=16, lr=recipe.lr, seed=7, windows_per_epoch=64, no_adv_epochs=0,
    micro_batches=micro, threads=1, progress=False,
)  # fmt: skip
start = {k: v.detach().clone() for k, v in model.named_parameters()}
history = fit(model, data.train, config, meta=data.meta).history
if distributed_rank()[0] == 0:
    params = {k: v.detach() for k, v in model.named_parameters()}
    torch.save({"start": start, "params": params, "history": history}, out)
