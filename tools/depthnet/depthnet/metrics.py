"""Depth accuracy metrics (per image, then averaged over images by the caller).

Valid pixels: ground truth inside (min_depth, max_depth]. AbsRel = mean |p - g| / g,
RMSE = sqrt(mean (p - g)^2) in metres, delta1 = fraction with max(p/g, g/p) < 1.25.
"""

from __future__ import annotations

from typing import Dict

import numpy as np


def depth_metrics(pred: np.ndarray, gt: np.ndarray, min_depth: float, max_depth: float,
                  median_scale: bool = False) -> Dict[str, float]:
    if pred.shape != gt.shape:
        raise ValueError(f"prediction shape {pred.shape} != ground truth shape {gt.shape}")
    valid = (gt > min_depth) & (gt <= max_depth) & np.isfinite(gt)
    if not valid.any():
        return {}
    p = pred[valid].astype(np.float64)
    g = gt[valid].astype(np.float64)
    if median_scale:
        p = p * (np.median(g) / np.median(p))
    p = np.clip(p, 1e-6, None)
    ratio = np.maximum(p / g, g / p)
    return {"abs_rel": float(np.mean(np.abs(p - g) / g)),
            "rmse": float(np.sqrt(np.mean((p - g) ** 2))),
            "delta1": float(np.mean(ratio < 1.25)),
            "valid_fraction": float(valid.mean())}


def average(metric_list) -> Dict[str, float]:
    metric_list = [m for m in metric_list if m]
    if not metric_list:
        return {}
    return {k: float(np.mean([m[k] for m in metric_list])) for k in metric_list[0]}
