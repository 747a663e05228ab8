"""Training losses. All take B x 1 x H x W tensors and a boolean valid mask of the same shape.

SILog (scale-invariant log loss, Eigen et al.; the AdaBins/ZoeDepth form):
  g = log(pred) - log(gt) over the valid pixels of one image,
  L = 10 * sqrt(mean(g^2) - lambda * mean(g)^2), lambda = 0.85, averaged over the batch.
  lambda = 1 makes it fully scale-invariant (used for relative pre-training).

Global consistency (paper Eq. 5-6), per image over its valid pixels M:
  S_global = mean_M(D_s / D_ade)                   (D_s reference depth, D_ade network depth)
  L_gc     = sum_M |D_s - D_ade * S_global| / |M|  (normalised by the valid-pixel count so it
                                                    does not depend on resolution; metres)
  averaged over the batch. Gradients flow through S_global, so L_gc only constrains the depth
  up to a global scale: it is the relative-depth (pre-training) objective.
"""

from __future__ import annotations

import torch


def _per_image(mask: torch.Tensor) -> torch.Tensor:
    return mask.flatten(1).float()


def silog_loss(pred: torch.Tensor, gt: torch.Tensor, mask: torch.Tensor, lam: float = 0.85,
               scale: float = 10.0, eps: float = 1e-6) -> torch.Tensor:
    m = _per_image(mask)
    g = torch.log(pred.clamp_min(eps)).flatten(1) - torch.log(gt.clamp_min(eps)).flatten(1)
    g = g * m
    n = m.sum(1)
    keep = n > 0
    if not keep.any():
        return pred.sum() * 0.0
    n = n[keep]
    g = g[keep]
    mean_g = g.sum(1) / n
    mean_g2 = (g * g).sum(1) / n
    d = (mean_g2 - lam * mean_g * mean_g).clamp_min(1e-12)  # >= 0 for lam <= 1; clamp for sqrt'
    return (scale * torch.sqrt(d)).mean()


def global_scale(ref: torch.Tensor, pred: torch.Tensor, mask: torch.Tensor,
                 eps: float = 1e-6) -> torch.Tensor:
    """S_global per image (shape B): mean over valid pixels of ref / pred (Eq. 5)."""
    m = _per_image(mask)
    ratio = ref.flatten(1) / pred.flatten(1).clamp_min(eps)
    return (ratio * m).sum(1) / m.sum(1).clamp_min(1.0)


def global_consistency_loss(ref: torch.Tensor, pred: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """L_gc of Eq. 6, normalised by the valid-pixel count, averaged over images with valid pixels."""
    m = _per_image(mask)
    n = m.sum(1)
    keep = n > 0
    if not keep.any():
        return pred.sum() * 0.0
    s = global_scale(ref, pred, mask)
    err = (ref.flatten(1) - pred.flatten(1) * s[:, None]).abs() * m
    return (err.sum(1)[keep] / n[keep]).mean()
