import math

import pytest
import torch

from depthnet.model import (TINY, BinSplitter, DepthNet, ModelConfig, bin_centres,
                            log_binomial_coefficients, log_binomial_probabilities)


def tiny(**kw):
    d = TINY.to_dict()
    d.update(kw)
    return ModelConfig.from_dict(d)


def test_forward_backward_shapes():
    torch.manual_seed(0)
    model = DepthNet(TINY)
    x = torch.rand(2, 3, TINY.input_height, TINY.input_width)
    out = model.forward_all(x)
    assert out["depth"].shape == (2, 1, TINY.input_height, TINY.input_width)
    assert out["q"].shape == out["t"].shape == (2, 1, TINY.input_height // 2, TINY.input_width // 2)
    assert out["probs"].shape == (2, TINY.num_bins, TINY.input_height // 2, TINY.input_width // 2)
    out["depth"].mean().backward()
    for name, p in model.named_parameters():
        assert p.grad is not None, name
        assert p.grad.shape == p.shape
        assert torch.isfinite(p.grad).all(), name
    # Gradient reaches the input image too.
    x2 = x.clone().requires_grad_(True)
    model(x2).sum().backward()
    assert x2.grad.shape == x.shape and x2.grad.abs().sum() > 0


def test_depth_is_expectation_over_bins_and_in_range():
    torch.manual_seed(1)
    model = DepthNet(TINY).eval()
    x = torch.rand(1, 3, TINY.input_height, TINY.input_width)
    out = model.forward_all(x)
    low = (out["probs"] * out["centres"]).sum(1, keepdim=True)
    up = torch.nn.functional.interpolate(low, size=x.shape[-2:], mode="bilinear", align_corners=False)
    assert torch.allclose(up, out["depth"])
    assert out["depth"].min() >= TINY.min_depth and out["depth"].max() <= TINY.max_depth
    assert (out["t"] >= TINY.min_temperature).all() and (out["t"] <= TINY.max_temperature).all()


@pytest.mark.parametrize("num_bins", [2, 16, 128])
def test_log_binomial_sums_to_one_and_peaks_at_qN(num_bins):
    n = num_bins - 1
    coeffs = log_binomial_coefficients(num_bins)
    assert coeffs[0] == 0 and abs(coeffs[-1]) < 1e-5
    assert math.isclose(float(coeffs[1]), math.log(n), rel_tol=1e-6, abs_tol=1e-6)
    for k in range(n + 1):
        q = torch.full((1, 1, 2, 3), k / n)
        for temp in (0.3, 1.0, 4.0):
            p = log_binomial_probabilities(q, torch.full_like(q, temp), coeffs)
            assert p.shape == (1, num_bins, 2, 3)
            assert torch.allclose(p.sum(1), torch.ones(1, 2, 3), atol=1e-5)
            assert (p.argmax(1) == k).all(), (k, temp)


def test_log_binomial_matches_binomial_pmf_at_unit_temperature():
    coeffs = log_binomial_coefficients(5)  # N = 4
    q = torch.full((1, 1, 1, 1), 0.3)
    p = log_binomial_probabilities(q, torch.ones_like(q), coeffs)[0, :, 0, 0]
    expected = [math.comb(4, i) * 0.3 ** i * 0.7 ** (4 - i) for i in range(5)]
    assert torch.allclose(p, torch.tensor(expected), atol=1e-6)
    # Lower temperature sharpens around the mode (i = 1).
    sharp = log_binomial_probabilities(q, torch.full_like(q, 0.2), coeffs)[0, :, 0, 0]
    assert sharp[1] > p[1]


@pytest.mark.parametrize("stages,seeds", [((8, 16, 32), 4), ((8, 8, 16, 16, 32), 3)])
def test_bin_splitting_counts(stages, seeds):
    cfg = tiny(encoder_channels=stages, num_seed_bins=seeds, input_height=64, input_width=96)
    model = DepthNet(cfg)
    out = model.forward_all(torch.rand(1, 3, 64, 96))
    widths = out["widths"]
    assert len(widths) == len(stages)  # seed + one per decoder layer
    for n, w in enumerate(widths):
        stride = 2 ** (len(stages) - n)
        assert w.shape == (1, seeds * 2 ** n, 64 // stride, 96 // stride)
        assert torch.allclose(w.sum(1), torch.ones_like(w.sum(1)), atol=1e-5)
        assert (w > 0).all()
    assert cfg.num_bins == seeds * 2 ** (len(stages) - 1) == out["probs"].shape[1]


def test_splitter_children_sum_to_parent():
    torch.manual_seed(2)
    split = BinSplitter(cfeat=5, num_bins=6, hidden=4)
    parent = torch.softmax(torch.randn(2, 6, 3, 4), 1)
    children = split(torch.randn(2, 5, 3, 4), parent)
    assert children.shape == (2, 12, 3, 4)
    assert torch.allclose(children[:, 0::2] + children[:, 1::2], parent, atol=1e-6)


def test_bin_centres():
    w = torch.tensor([0.5, 0.25, 0.25]).view(1, 3, 1, 1)
    c = bin_centres(w, 1.0, 5.0)[0, :, 0, 0]
    assert torch.allclose(c, torch.tensor([2.0, 3.5, 4.5]))


def test_config_check_rejects_bad_sizes():
    with pytest.raises(ValueError):
        tiny(input_height=30).check()
    with pytest.raises(ValueError):
        tiny(min_depth=5.0, max_depth=1.0).check()
    with pytest.raises(ValueError):
        tiny(encoder_channels=(8,)).check()
