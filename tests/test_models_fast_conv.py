"""beatlite.models.fast_conv: the same convolution as torch's, with the input gradient as a forward conv."""

from __future__ import annotations

import pytest
import torch
from torch import nn

from beatlite.models import fast_conv


def _pair(cls: type, base: type, *args: object, **kwargs: object) -> tuple[nn.Module, nn.Module]:
    torch.manual_seed(0)
    fast = cls(*args, **kwargs).double()
    ref = base(*args, **kwargs).double()
    ref.load_state_dict(fast.state_dict())
    return fast, ref


CASES_1D = [
    # in, out, kernel, stride, padding, bias, length
    (4, 4, 15, 1, 7, False, 60),
    (3, 5, 3, 1, 0, True, 20),
    (2, 3, 5, 1, 4, True, 9),  # padding = kernel - 1 ("full")
    (1, 4, 15, 5, 40, False, 200),  # strided: torch's own backward
]
CASES_2D = [
    (4, 4, 3, 1, 1, False, (12, 9)),
    (2, 3, 3, 1, 0, True, (7, 8)),
    (3, 2, (3, 2), 1, (1, 0), True, (6, 7)),
    (4, 8, 3, (2, 1), 1, False, (10, 7)),  # strided: torch's own backward
]


@pytest.mark.parametrize("c_in, c_out, k, stride, pad, bias, length", CASES_1D)
def test_conv1d_gradcheck_and_matches_torch(c_in, c_out, k, stride, pad, bias, length):
    fast, ref = _pair(fast_conv.Conv1d, nn.Conv1d, c_in, c_out, k, stride=stride, padding=pad, bias=bias)
    x = torch.randn(2, c_in, length, dtype=torch.double, requires_grad=True)
    assert torch.autograd.gradcheck(lambda v: fast(v), (x,))
    y_fast, y_ref = fast(x), ref(x)
    torch.testing.assert_close(y_fast, y_ref)
    g = torch.randn_like(y_ref)
    grads_fast = torch.autograd.grad(y_fast, [x, *fast.parameters()], g)
    grads_ref = torch.autograd.grad(y_ref, [x, *ref.parameters()], g)
    for a, b in zip(grads_fast, grads_ref, strict=True):
        torch.testing.assert_close(a, b)


@pytest.mark.parametrize("c_in, c_out, k, stride, pad, bias, size", CASES_2D)
def test_conv2d_gradcheck_and_matches_torch(c_in, c_out, k, stride, pad, bias, size):
    fast, ref = _pair(fast_conv.Conv2d, nn.Conv2d, c_in, c_out, k, stride=stride, padding=pad, bias=bias)
    x = torch.randn(2, c_in, *size, dtype=torch.double, requires_grad=True)
    assert torch.autograd.gradcheck(lambda v: fast(v), (x,))
    g = torch.randn_like(ref(x))
    grads_fast = torch.autograd.grad(fast(x), [x, *fast.parameters()], g)
    grads_ref = torch.autograd.grad(ref(x), [x, *ref.parameters()], g)
    for a, b in zip(grads_fast, grads_ref, strict=True):
        torch.testing.assert_close(a, b)


def test_weight_gradient_without_input_gradient():
    """The first layer of an encoder: the input needs no gradient, the weight does."""
    fast, ref = _pair(fast_conv.Conv1d, nn.Conv1d, 1, 4, 15, padding=7)
    x = torch.randn(3, 1, 50, dtype=torch.double)
    fast(x).square().sum().backward()
    ref(x).square().sum().backward()
    torch.testing.assert_close(fast.weight.grad, ref.weight.grad)
    torch.testing.assert_close(fast.bias.grad, ref.bias.grad)


def test_state_dict_keys_match_torch():
    """Checkpoints of models built with torch's classes load into these and back."""
    assert set(fast_conv.Conv2d(2, 3, 3).state_dict()) == set(nn.Conv2d(2, 3, 3).state_dict())
    assert set(fast_conv.Conv1d(2, 3, 3, bias=False).state_dict()) == {"weight"}


def test_no_grad_forward_is_torch_forward():
    fast, ref = _pair(fast_conv.Conv1d, nn.Conv1d, 2, 3, 5, padding=2)
    x = torch.randn(1, 2, 11, dtype=torch.double)
    with torch.no_grad():
        torch.testing.assert_close(fast(x), ref(x))
