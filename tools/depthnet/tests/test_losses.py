import math

import pytest
import torch

from depthnet.losses import global_consistency_loss, global_scale, silog_loss


def t(values):
    return torch.tensor(values, dtype=torch.float32).view(1, 1, 1, -1)


def test_silog_hand_values():
    # g = log(pred) - log(gt) = [1, -1, 2] on valid pixels; the 4th pixel is masked out.
    gt = t([1.0, 2.0, 0.5, 3.0])
    pred = gt * torch.exp(t([1.0, -1.0, 2.0, 7.0]))
    mask = t([1, 1, 1, 0]).bool()
    # mean g = 2/3, mean g^2 = 2 -> 10 * sqrt(2 - 0.85 * 4 / 9)
    assert silog_loss(pred, gt, mask).item() == pytest.approx(12.736648783028562, rel=1e-5)
    assert 10 * math.sqrt(2 - 0.85 * 4 / 9) == pytest.approx(12.736648783028562, rel=1e-12)
    # lambda = 1: variance only -> 10 * sqrt(2 - 4/9)
    assert silog_loss(pred, gt, mask, lam=1.0).item() == pytest.approx(12.472191289246473, rel=1e-5)


def test_silog_zero_for_exact_and_scale_invariant_for_lambda_one():
    gt = t([1.0, 2.0, 4.0])
    mask = torch.ones_like(gt, dtype=torch.bool)
    assert silog_loss(gt.clone(), gt, mask).item() < 1e-4
    assert silog_loss(3 * gt, gt, mask, lam=1.0).item() < 1e-4
    # lambda = 0.85 keeps a scale penalty: 10 * sqrt(0.15) * |log 3|
    assert silog_loss(3 * gt, gt, mask).item() == pytest.approx(10 * math.sqrt(0.15) * math.log(3), rel=1e-5)


def test_silog_batch_is_mean_over_images_and_ignores_empty():
    gt = torch.ones(3, 1, 1, 2)
    pred = torch.ones(3, 1, 1, 2)
    pred[0] *= math.e  # g = 1 everywhere: 10 * sqrt(1 - 0.85)
    mask = torch.ones_like(gt, dtype=torch.bool)
    mask[2] = False  # no valid pixels: left out of the mean
    expected = (10 * math.sqrt(0.15) + 10 * math.sqrt(1e-12)) / 2
    assert silog_loss(pred, gt, mask).item() == pytest.approx(expected, rel=1e-5)


def test_silog_gradient_only_from_valid_pixels():
    gt = t([1.0, 2.0, 3.0])
    pred = t([2.0, 1.0, 5.0]).requires_grad_(True)
    mask = t([1, 1, 0]).bool()
    silog_loss(pred, gt, mask).backward()
    assert pred.grad[0, 0, 0, 2] == 0
    assert pred.grad[0, 0, 0, :2].abs().sum() > 0


def test_global_consistency_hand_values():
    ref = t([2.0, 4.0, 6.0, 100.0])
    pred = t([1.0, 1.0, 2.0, 0.01])
    mask = t([1, 1, 1, 0]).bool()
    # S = mean(2, 4, 3) = 3; pred * S = [3, 3, 6]; |ref - pred S| = [1, 1, 0]; sum 2 / 3 pixels
    assert global_scale(ref, pred, mask).item() == pytest.approx(3.0)
    assert global_consistency_loss(ref, pred, mask).item() == pytest.approx(2.0 / 3.0, rel=1e-6)


def test_global_consistency_batch_and_scale_invariance():
    ref = torch.tensor([[2.0, 4.0, 6.0], [1.0, 1.0, 1.0]]).view(2, 1, 1, 3)
    pred = torch.tensor([[1.0, 1.0, 2.0], [0.5, 0.5, 0.25]]).view(2, 1, 1, 3)
    mask = torch.ones_like(ref, dtype=torch.bool)
    # image 2: S = mean(2, 2, 4) = 8/3; pred S = [4/3, 4/3, 2/3]; errors 1/3, 1/3, 1/3 -> 1/3
    assert global_consistency_loss(ref, pred, mask).item() == pytest.approx((2 / 3 + 1 / 3) / 2, rel=1e-6)
    assert global_consistency_loss(ref, ref / 5.0, mask).item() < 1e-6
    assert global_consistency_loss(ref, pred * 7.0, mask).item() == pytest.approx(0.5, rel=1e-5)
