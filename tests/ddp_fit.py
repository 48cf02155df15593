"""Run by tests/test_train_distributed.py under ``torchrun`` (and once without it): one epoch of the
CaMN tiny recipe (dropout 0, so that nothing random differs between processes) on ``argv[3]`` of
data_samples' train windows with ``argv[2]`` micro-batches per global batch of 16 (``argv[4]``, optional: the
``TrainConfig.data_on_device`` of the store view, default "never"), then process 0 saves the parameters and the
generator's gradients of the last step to ``argv[1]``."""

import sys

import torch
from ddp_model import camn_without_dropout

from beatlite.train import TrainConfig, fit
from beatlite.train.distributed import distributed_rank
from beatlite.train.recipes import RECIPES, training_data

out, micro, windows = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
on_device = sys.argv[4] if len(sys.argv) > 4 else "never"
data = training_data()
recipe = RECIPES["camn_tiny"]
model = camn_without_dropout(data)
config = TrainConfig(
    epochs=1, batch_size=16, lr=recipe.lr, seed=7, windows_per_epoch=windows, no_adv_epochs=0,
    micro_batches=micro, threads=1, progress=False, data_on_device=on_device,
)  # fmt: skip
start = {k: v.detach().clone() for k, v in model.named_parameters()}
history = fit(model, data.train, config, meta=data.meta).history
if distributed_rank()[0] == 0:
    params = {k: v.detach() for k, v in model.named_parameters()}
    generator = {id(p) for p in model.generator_parameters()}
    grads = {k: v.grad for k, v in model.named_parameters() if id(v) in generator}
    torch.save({"start": start, "params": params, "grads": grads, "history": history}, out)
