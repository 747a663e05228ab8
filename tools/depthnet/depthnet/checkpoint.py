"""Checkpoints: model config + weights (+ optimiser/schedule/progress for --resume).

Written atomically (temporary file + rename) so an interrupted save never leaves a broken file.
"""

from __future__ import annotations

import os
from typing import Dict, Tuple

import torch

from .model import DepthNet, ModelConfig


def save_checkpoint(path: str, state: Dict) -> None:
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    torch.save(state, tmp)
    os.replace(tmp, path)


def load_model(path: str) -> Tuple[DepthNet, Dict]:
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: checkpoint not found")
    try:
        state = torch.load(path, map_location="cpu")
    except Exception as e:  # torch raises several types for corrupt files
        raise ValueError(f"{path}: not a readable checkpoint ({e})") from None
    if not isinstance(state, dict) or "model" not in state or "config" not in state:
        raise ValueError(f"{path}: not a depthnet checkpoint (missing 'model'/'config')")
    model = DepthNet(ModelConfig.from_dict(state["config"]))
    model.load_state_dict(state["model"])
    model.eval()
    return model, state
