"""ZoeDepth-style metric depth network with a log-binomial metric-bins head (paper section 3.1).

Shape contract (B = batch, H x W = input size, both divisible by 2**num_stages):
  input  : B x 3 x H x W float RGB in [0, 1] (ImageNet normalisation happens inside the model)
  output : B x 1 x H x W metric depth in metres, inside [min_depth, max_depth]

Structure
  encoder : ``num_stages`` stride-2 conv stages (channels ``encoder_channels``); the last stage
            output at H / 2**num_stages is the bottleneck.
  seed    : a 1x1-conv MLP on the bottleneck predicts ``num_seed_bins`` (Ns) positive bin widths
            per pixel; widths are normalised to sum to one over [min_depth, max_depth].
  decoder : ``num_stages - 1`` layers, each upsampling x2 and fusing the encoder skip. After each
            decoder layer n a split MLP (1x1 convs on the layer's features and the current
            widths) splits every bin in two, so layer n carries 2**n * Ns bins per pixel. The
            widths are bilinearly upsampled to the next resolution (a convex combination of
            normalised widths stays normalised).
  head    : from the last decoder features, q in (0, 1) and t in [t_min, t_max]; probabilities
            P(i) = softmax_i(log(C(N, i) q^i (1 - q)^(N - i)) / t), N = bins - 1 (Eq. 3-4);
            depth = sum_k P_k C_k (Eq. 2), computed at H/2 and bilinearly upsampled to H x W.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Dict, List, Sequence

import torch
import torch.nn as nn
import torch.nn.functional as F

IMAGENET_MEAN = (0.485, 0.456, 0.406)
IMAGENET_STD = (0.229, 0.224, 0.225)


@dataclasses.dataclass
class ModelConfig:
    encoder_channels: Sequence[int] = (16, 32, 64, 128)  # one entry per stage (width and depth)
    blocks_per_stage: int = 1  # extra 3x3 conv blocks after each stride-2 conv
    decoder_channels: int = 32  # base width of the decoder (layer n uses this * 2**(L-1-n))
    num_seed_bins: int = 16  # Ns
    min_depth: float = 0.1
    max_depth: float = 10.0
    min_temperature: float = 0.05
    max_temperature: float = 5.0
    mlp_hidden: int = 32
    input_height: int = 144
    input_width: int = 192

    def check(self) -> None:
        if len(self.encoder_channels) < 2:
            raise ValueError("encoder_channels needs at least 2 stages")
        if any(c <= 0 for c in self.encoder_channels):
            raise ValueError("encoder_channels must be positive")
        if self.num_seed_bins < 2:
            raise ValueError("num_seed_bins must be >= 2")
        if not 0 < self.min_depth < self.max_depth:
            raise ValueError("need 0 < min_depth < max_depth")
        if not 0 < self.min_temperature < self.max_temperature:
            raise ValueError("need 0 < min_temperature < max_temperature")
        stride = 2 ** len(self.encoder_channels)
        if self.input_height % stride or self.input_width % stride:
            raise ValueError(f"input size must be divisible by {stride}")

    @property
    def num_decoder_layers(self) -> int:
        return len(self.encoder_channels) - 1

    @property
    def num_bins(self) -> int:
        return self.num_seed_bins * 2 ** self.num_decoder_layers

    def to_dict(self) -> Dict:
        d = dataclasses.asdict(self)
        d["encoder_channels"] = list(self.encoder_channels)
        return d

    @staticmethod
    def from_dict(d: Dict) -> "ModelConfig":
        d = dict(d)
        d["encoder_channels"] = tuple(d["encoder_channels"])
        return ModelConfig(**d)


SMALL = ModelConfig()
TINY = ModelConfig(encoder_channels=(8, 16, 32), decoder_channels=8, num_seed_bins=4,
                   mlp_hidden=8, input_height=32, input_width=48)


def conv_bn_relu(cin: int, cout: int, stride: int = 1) -> nn.Sequential:
    return nn.Sequential(nn.Conv2d(cin, cout, 3, stride, 1, bias=False), nn.BatchNorm2d(cout),
                         nn.ReLU(inplace=True))


def mlp(cin: int, hidden: int, cout: int) -> nn.Sequential:
    """Per-pixel MLP as 1x1 convolutions."""
    return nn.Sequential(nn.Conv2d(cin, hidden, 1), nn.ReLU(inplace=True), nn.Conv2d(hidden, cout, 1))


def log_binomial_coefficients(num_bins: int) -> torch.Tensor:
    """log C(N, i) for i = 0..N with N = num_bins - 1 (a constant: keeps lgamma out of the ONNX)."""
    n = num_bins - 1
    return torch.tensor([math.lgamma(n + 1) - math.lgamma(i + 1) - math.lgamma(n - i + 1)
                         for i in range(num_bins)], dtype=torch.float32)


def log_binomial_probabilities(q: torch.Tensor, t: torch.Tensor, log_coeffs: torch.Tensor,
                               eps: float = 1e-6) -> torch.Tensor:
    """P(i) = softmax_i(log(C(N,i) q^i (1-q)^(N-i)) / t) over the channel axis.

    q, t: B x 1 x H x W; log_coeffs: (N+1,). Returns B x (N+1) x H x W summing to 1 over dim 1.
    """
    k = log_coeffs.shape[0]
    i = torch.arange(k, dtype=q.dtype, device=q.device).view(1, k, 1, 1)
    q = q.clamp(eps, 1.0 - eps)
    log_p = log_coeffs.view(1, k, 1, 1) + i * torch.log(q) + (k - 1 - i) * torch.log(1.0 - q)
    return torch.softmax(log_p / t, dim=1)


def bin_centres(widths: torch.Tensor, min_depth: float, max_depth: float) -> torch.Tensor:
    """Centres of consecutive bins with normalised widths (B x K x H x W) over [min, max]."""
    edges_right = torch.cumsum(widths, dim=1)
    return min_depth + (max_depth - min_depth) * (edges_right - 0.5 * widths)


class SeedBins(nn.Module):
    def __init__(self, cin: int, hidden: int, num_bins: int):
        super().__init__()
        self.mlp = mlp(cin, hidden, num_bins)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        w = F.softplus(self.mlp(x)) + 1e-3
        return w / w.sum(dim=1, keepdim=True)


class BinSplitter(nn.Module):
    """Splits each of K bins in two: a sigmoid ratio r gives children widths (w r, w (1 - r))."""

    def __init__(self, cfeat: int, num_bins: int, hidden: int):
        super().__init__()
        self.mlp = mlp(cfeat + num_bins, hidden, num_bins)

    def forward(self, feat: torch.Tensor, widths: torch.Tensor) -> torch.Tensor:
        # Keep the ratio away from 0/1 so no child bin collapses to zero width.
        r = 0.05 + 0.9 * torch.sigmoid(self.mlp(torch.cat([feat, widths * widths.shape[1]], 1)))
        b, k, h, w = widths.shape
        children = torch.stack([widths * r, widths * (1.0 - r)], dim=2)  # B x K x 2 x H x W
        return children.reshape(b, 2 * k, h, w)


class DecoderLayer(nn.Module):
    def __init__(self, cin: int, cskip: int, cout: int):
        super().__init__()
        self.fuse = nn.Sequential(conv_bn_relu(cin + cskip, cout), conv_bn_relu(cout, cout))

    def forward(self, x: torch.Tensor, skip: torch.Tensor) -> torch.Tensor:
        x = F.interpolate(x, size=skip.shape[-2:], mode="bilinear", align_corners=False)
        return self.fuse(torch.cat([x, skip], 1))


class DepthNet(nn.Module):
    def __init__(self, config: ModelConfig = SMALL):
        super().__init__()
        config.check()
        self.config = config
        ch = list(config.encoder_channels)
        stages = []
        cin = 3
        for c in ch:
            layers = [conv_bn_relu(cin, c, stride=2)]
            layers += [conv_bn_relu(c, c) for _ in range(config.blocks_per_stage)]
            stages.append(nn.Sequential(*layers))
            cin = c
        self.encoder = nn.ModuleList(stages)
        num_layers = config.num_decoder_layers
        self.bottleneck = conv_bn_relu(ch[-1], ch[-1])
        self.seed = SeedBins(ch[-1], config.mlp_hidden, config.num_seed_bins)
        decoders, splitters = [], []
        cprev = ch[-1]
        bins = config.num_seed_bins
        for n in range(num_layers):
            cout = config.decoder_channels * 2 ** (num_layers - 1 - n)
            skip = ch[-2 - n]
            decoders.append(DecoderLayer(cprev, skip, cout))
            splitters.append(BinSplitter(cout, bins, config.mlp_hidden))
            bins *= 2
            cprev = cout
        self.decoders = nn.ModuleList(decoders)
        self.splitters = nn.ModuleList(splitters)
        # q and t from the finest decoder features (Eq. 3-4).
        self.qt_head = mlp(cprev, config.mlp_hidden, 2)
        self.register_buffer("log_coeffs", log_binomial_coefficients(config.num_bins))
        self.register_buffer("mean", torch.tensor(IMAGENET_MEAN).view(1, 3, 1, 1))
        self.register_buffer("std", torch.tensor(IMAGENET_STD).view(1, 3, 1, 1))

    def forward_all(self, rgb: torch.Tensor) -> Dict[str, object]:
        """Depth plus intermediates (bin widths per layer, q, t, probabilities) for tests/losses."""
        cfg = self.config
        x = (rgb - self.mean) / self.std
        skips: List[torch.Tensor] = []
        for stage in self.encoder:
            x = stage(x)
            skips.append(x)
        x = self.bottleneck(skips[-1])
        widths = self.seed(x)
        widths_per_layer = [widths]
        for n, (decoder, splitter) in enumerate(zip(self.decoders, self.splitters)):
            x = decoder(x, skips[-2 - n])
            widths = F.interpolate(widths, size=x.shape[-2:], mode="bilinear", align_corners=False)
            widths = splitter(x, widths)
            widths_per_layer.append(widths)
        qt = self.qt_head(x)
        q = torch.sigmoid(qt[:, :1])
        t = cfg.min_temperature + (cfg.max_temperature - cfg.min_temperature) * torch.sigmoid(qt[:, 1:])
        probs = log_binomial_probabilities(q, t, self.log_coeffs)
        centres = bin_centres(widths, cfg.min_depth, cfg.max_depth)
        depth_low = (probs * centres).sum(dim=1, keepdim=True)
        depth = F.interpolate(depth_low, size=rgb.shape[-2:], mode="bilinear", align_corners=False)
        return {"depth": depth, "widths": widths_per_layer, "q": q, "t": t, "probs": probs,
                "centres": centres}

    def forward(self, rgb: torch.Tensor) -> torch.Tensor:
        return self.forward_all(rgb)["depth"]


def count_parameters(model: nn.Module) -> int:
    return sum(p.numel() for p in model.parameters())
