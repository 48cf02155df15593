"""Convolutions whose input gradient is computed as a forward convolution (faster on CPU).

On CPU, torch's (oneDNN) backward pass of a stride-1 convolution with few channels over a long
signal is several times slower than its forward pass: for CaMN's 4-channel WavEncoder block
(kernel 15, 7891 steps, 32 windows, one thread) the forward takes 3.3 ms and torch's input
gradient 11.7 ms. For stride 1 the gradient with respect to the input *is* a forward convolution
(the "full" correlation of the output gradient with the flipped, transposed kernel): 3.5 ms.
On whole training epochs the gain is smaller, because these layers are one part of a step:
``bench/bench_models.py`` measured 1.05x for CaMN and 1.07x for HA2G on one thread, and
0.98-1.14x on two (within the noise of this machine).

:class:`Conv1d` and :class:`Conv2d` are drop-in subclasses of ``torch.nn.Conv1d`` / ``Conv2d``:
same parameters, same state-dict keys (checkpoints load either way), same forward. Only the
backward differs, and only where it pays: stride 1 (or a 1-wide kernel without padding, whose
stride is a slice of the input: the strided shortcuts of residual blocks), dilation 1, one group,
zero padding. The weight gradient and every other case use torch's own
``convolution_backward``. Gradients agree with torch's to float rounding
(``tests/test_models_fast_conv.py`` runs ``gradcheck``); ``bench/bench_models.py`` times CaMN
and HA2G epochs with and without them.

Not taught in a notebook (a speed detail of the models' convolutions).
"""

from __future__ import annotations

from typing import Any

import torch
import torch.nn.functional as F
from torch import nn


def _full_correlation(grad: torch.Tensor, weight: torch.Tensor) -> torch.Tensor:
    """``grad`` (B, O, *T) correlated with the flipped, transposed ``weight`` (O, C, *K): (B, C, *(T+K-1))."""
    dims = weight.ndim - 2
    flipped = weight.transpose(0, 1).flip(list(range(2, 2 + dims)))
    pad = [k - 1 for k in weight.shape[2:]]
    conv = F.conv1d if dims == 1 else F.conv2d
    return conv(grad, flipped, padding=pad)


class _ForwardGradConv(torch.autograd.Function):
    """``conv(x, w, b, padding)`` at stride 1 with the input gradient as a forward convolution."""

    @staticmethod
    def forward(  # type: ignore[override]
        ctx: Any, x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor | None, padding: tuple[int, ...]
    ) -> torch.Tensor:
        ctx.save_for_backward(x, weight)
        ctx.padding = padding
        ctx.has_bias = bias is not None
        conv = F.conv1d if weight.ndim == 3 else F.conv2d
        return conv(x, weight, bias, padding=padding)

    @staticmethod
    def backward(ctx: Any, grad: torch.Tensor) -> tuple[torch.Tensor | None, ...]:  # type: ignore[override]
        x, weight = ctx.saved_tensors
        grad = grad.contiguous()
        dims = weight.ndim - 2
        grad_x = grad_w = grad_b = None
        if ctx.needs_input_grad[0]:
            full = _full_correlation(grad, weight)  # the gradient of the padded input
            index = [slice(None), slice(None)] + [
                slice(p, p + n) for p, n in zip(ctx.padding, x.shape[2:], strict=True)
            ]
            grad_x = full[tuple(index)]
        if ctx.needs_input_grad[1]:
            grad_w = torch.ops.aten.convolution_backward(
                grad,
                x,
                weight,
                None,
                [1] * dims,
                list(ctx.padding),
                [1] * dims,
                False,
                [0] * dims,
                1,
                [False, True, False],
            )[1]
        if ctx.has_bias and ctx.needs_input_grad[2]:
            grad_b = grad.sum(dim=[0, *range(2, grad.ndim)])
        return grad_x, grad_w, grad_b, None


def _uses_forward_grad(conv: nn.Conv1d | nn.Conv2d) -> bool:
    """Stride 1, or a 1-wide kernel without padding (then a stride is a slice of the input)."""
    pointwise = all(k == 1 for k in conv.kernel_size) and all(p == 0 for p in conv.padding)
    return (
        (all(s == 1 for s in conv.stride) or pointwise)
        and all(d == 1 for d in conv.dilation)
        and conv.groups == 1
        and conv.padding_mode == "zeros"
        and not isinstance(conv.padding, str)
    )


def _forward(conv: nn.Conv1d | nn.Conv2d, x: torch.Tensor) -> torch.Tensor:
    if not (_uses_forward_grad(conv) and torch.is_grad_enabled()):
        return conv._conv_forward(x, conv.weight, conv.bias)
    if any(s > 1 for s in conv.stride):  # 1-wide kernel: keep every s-th sample, then stride 1
        x = x[(slice(None), slice(None), *(slice(None, None, s) for s in conv.stride))].contiguous()
    return _ForwardGradConv.apply(x, conv.weight, conv.bias, tuple(conv.padding))


class Conv1d(nn.Conv1d):
    """``torch.nn.Conv1d`` with a faster CPU backward at stride 1 (see the module docstring).

    Shapes
    ------
    (B, C_in, L) -> (B, C_out, L_out), as ``torch.nn.Conv1d``.
    """

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return _forward(self, x)


class Conv2d(nn.Conv2d):
    """``torch.nn.Conv2d`` with a faster CPU backward at stride 1 (see the module docstring).

    Shapes
    ------
    (B, C_in, H, W) -> (B, C_out, H_out, W_out), as ``torch.nn.Conv2d``.
    """

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return _forward(self, x)
