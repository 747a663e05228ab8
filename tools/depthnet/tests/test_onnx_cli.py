"""The exported ONNX gives the PyTorch depth through ademono's ONNX Runtime provider (within 1e-4).

Runs `$ADEMONO_CLI depth --depth model:X.onnx,spec=Y.yaml --camera C.yaml IMG --out D.tiff` on an
image at exactly the network input size, so no resampling happens on either side.
"""

import os
import subprocess

import cv2
import numpy as np
import pytest
import torch

import export_onnx
from depthnet.model import TINY, DepthNet

CLI = os.environ.get("ADEMONO_CLI", "")


@pytest.mark.skipif(not CLI, reason="ADEMONO_CLI is not set (CTest sets it to the built ademono)")
def test_onnx_runtime_matches_pytorch(tmp_path):
    torch.manual_seed(5)
    model = DepthNet(TINY)
    # Non-trivial BatchNorm statistics so the exported graph folds real values.
    model.train()
    with torch.no_grad():
        for _ in range(3):
            model(torch.rand(2, 3, TINY.input_height, TINY.input_width))
    model.eval()
    onnx_path = str(tmp_path / "tiny.onnx")
    spec_path = str(tmp_path / "tiny.yaml")
    export_onnx.export(model, onnx_path)
    with open(spec_path, "w") as f:
        f.write(export_onnx.spec_yaml(model, "tiny_test"))
    h, w = TINY.input_height, TINY.input_width
    with open(tmp_path / "camera.yaml", "w") as f:
        f.write(f"width: {w}\nheight: {h}\nfx: 40.0\nfy: 40.0\ncx: {(w - 1) / 2}\ncy: {(h - 1) / 2}\n")
    bgr = np.random.default_rng(1).integers(0, 256, (h, w, 3), dtype=np.uint8)
    cv2.imwrite(str(tmp_path / "img.png"), bgr)

    out = tmp_path / "depth.tiff"
    cmd = [CLI, "depth", "--depth", f"model:{onnx_path},spec={spec_path}",
           "--camera", str(tmp_path / "camera.yaml"), str(tmp_path / "img.png"), "--out", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    ort_depth = cv2.imread(str(out), cv2.IMREAD_UNCHANGED)
    assert ort_depth is not None and ort_depth.dtype == np.float32 and ort_depth.shape == (h, w)

    rgb = torch.from_numpy(bgr[:, :, ::-1].astype(np.float32) / 255.0).permute(2, 0, 1)[None]
    with torch.no_grad():
        torch_depth = model(rgb)[0, 0].numpy()
    diff = float(np.abs(ort_depth - torch_depth).max())
    print(f"max |ONNX Runtime - PyTorch| = {diff:.2e} m")
    assert diff < 1e-4
    assert torch_depth.std() > 1e-3  # the comparison is not between two constants
