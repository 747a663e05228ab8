"""End-to-end: train.py (with --resume), evaluate.py and export_onnx.py on a tiny synthetic set."""

import json
import os

import cv2
import numpy as np
import onnx
import torch
import yaml

import evaluate
import export_onnx
import train


def make_scene(root, n=8, w=64, h=48):
    """Frames whose depth (a tilted plane) is visible in the colour: learnable in a few steps."""
    os.makedirs(root, exist_ok=True)
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float32)
    for i in range(n):
        depth_m = 1.0 + 0.5 * i / n + 1.5 * ys / h
        bgr = np.stack([255 * (1 - ys / h), 128 + 0 * xs, 255 * ys / h], -1).astype(np.uint8)
        cv2.imwrite(os.path.join(root, f"frame-{i:06d}.color.png"), bgr)
        mm = (depth_m * 1000).astype(np.uint16)
        mm[::7, ::5] = 0
        cv2.imwrite(os.path.join(root, f"frame-{i:06d}.depth.png"), mm)


def train_args(data, out, *extra):
    return ["--data", "7scenes:" + data, "--frames", "0:8", "--out", out, "--variant", "tiny",
            "--epochs", "3", "--pretrain-epochs", "1", "--batch-size", "4", "--cache-size", "64x48",
            "--seed", "3", "--log-every", "100", *extra]


def weights(path):
    return torch.load(path, map_location="cpu")["model"]


def test_train_resume_evaluate_export(tmp_path, capsys):
    data = str(tmp_path / "scene")
    make_scene(data)
    straight = str(tmp_path / "straight")
    split = str(tmp_path / "split")
    assert train.main(train_args(data, straight, "--val-frames", "6:8")) == 0
    assert train.main(train_args(data, split, "--stop-after", "2")) == 0
    assert torch.load(os.path.join(split, "last.pt"))["epoch"] == 2
    assert train.main(train_args(data, split, "--resume")) == 0
    a, b = weights(os.path.join(straight, "last.pt")), weights(os.path.join(split, "last.pt"))
    for k in a:  # resuming reproduces the uninterrupted run exactly
        assert torch.equal(a[k], b[k]), k
    log = open(os.path.join(straight, "log.csv")).read().splitlines()
    assert log[0].startswith("epoch,stage,train_loss") and len(log) == 4
    assert "relative" in log[1] and "metric" in log[3]

    out_json = str(tmp_path / "metrics.json")
    assert evaluate.main(["--checkpoint", os.path.join(straight, "last.pt"), "--data", "7scenes:" + data,
                          "--frames", "4:8", "--json", out_json]) == 0
    result = json.load(open(out_json))
    assert result["num_frames"] == 4
    m = result["metric"]
    assert 0 <= m["abs_rel"] and 0 <= m["rmse"] and 0 <= m["delta1"] <= 1

    onnx_path = str(tmp_path / "tiny.onnx")
    spec_path = str(tmp_path / "tiny.yaml")
    assert export_onnx.main(["--checkpoint", os.path.join(straight, "last.pt"), "--out", onnx_path,
                             "--spec-out", spec_path]) == 0
    proto = onnx.load(onnx_path)
    assert proto.opset_import[0].version == 13
    assert [i.name for i in proto.graph.input] == ["image"]
    dims = [d.dim_value for d in proto.graph.output[0].type.tensor_type.shape.dim]
    assert dims == [1, 1, 32, 48]
    spec = yaml.safe_load(open(spec_path))
    assert (spec["input"]["width"], spec["input"]["height"]) == (48, 32)
    assert spec["output"]["kind"] == "metric" and spec["input"]["color"] == "rgb"


def test_committed_spec_matches_small_variant(tool_dir):
    """configs/models/ademono_depthnet.yaml is what export_onnx writes for the small variant."""
    from depthnet.model import SMALL, DepthNet

    committed = os.path.join(tool_dir, "..", "..", "configs", "models", "ademono_depthnet.yaml")
    assert open(committed).read() == export_onnx.spec_yaml(DepthNet(SMALL), "ademono_depthnet_small")


def test_width_and_depth_options(tmp_path):
    data = str(tmp_path / "scene")
    make_scene(data, n=4)
    out = str(tmp_path / "wide")
    assert train.main(["--data", "7scenes:" + data, "--out", out, "--variant", "tiny", "--epochs", "1",
                       "--pretrain-epochs", "0", "--batch-size", "2", "--cache-size", "64x48",
                       "--channels", "4,8,8,16", "--blocks-per-stage", "2", "--decoder-channels", "6",
                       "--seed-bins", "3", "--input-size", "64x48"]) == 0
    cfg = torch.load(os.path.join(out, "last.pt"))["config"]
    assert cfg["encoder_channels"] == [4, 8, 8, 16] and cfg["blocks_per_stage"] == 2
    assert cfg["decoder_channels"] == 6 and cfg["num_seed_bins"] == 3
    assert (cfg["input_width"], cfg["input_height"]) == (64, 48)


def test_train_rejects_bad_input(tmp_path, capsys):
    assert train.main(["--data", "7scenes:" + str(tmp_path / "missing"), "--out", str(tmp_path / "o")]) == 2
    assert "missing: not a directory" in capsys.readouterr().err
    assert train.main(["--data", "7scenes:" + str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    assert "no frame-XXXXXX.color.jpg files" in capsys.readouterr().err
    make_scene(str(tmp_path / "scene"), n=2)
    assert train.main(["--data", "7scenes:" + str(tmp_path / "scene"), "--out", str(tmp_path / "o"),
                       "--resume"]) == 2
    assert "no checkpoint to resume from" in capsys.readouterr().err
    assert train.main(["--data", "7scenes:" + str(tmp_path / "scene"), "--out", str(tmp_path / "o"),
                       "--input-size", "50x40"]) == 2
    assert "model configuration: input size must be divisible by 16" in capsys.readouterr().err
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"garbage")
    assert evaluate.main(["--checkpoint", str(bad), "--data", "7scenes:" + str(tmp_path)]) == 2
    assert "bad.pt: not a readable checkpoint" in capsys.readouterr().err
