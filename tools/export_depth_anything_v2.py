#!/usr/bin/env python3
"""Exports a Depth Anything V2 metric-depth checkpoint to ONNX for `--depth model:`.

Needs a checkout of DepthAnything/Depth-Anything-V2 (for metric_depth/depth_anything_v2) and a
metric checkpoint (depth_anything_v2_metric_{hypersim,vkitti}_{vits,vitb,vitl}.pth). No weights
are shipped with ademono; this script cannot run without them.

  python3 tools/export_depth_anything_v2.py --repo ~/Depth-Anything-V2 \
      --checkpoint depth_anything_v2_metric_hypersim_vits.pth --encoder vits --max-depth 20 \
      --out depth_anything_v2_metric_indoor_vits.onnx

Use configs/models/depth_anything_v2_metric_indoor.yaml (max-depth 20, Hypersim) or
..._outdoor.yaml (max-depth 80, Virtual KITTI 2) as the spec. The graph has dynamic height and
width (multiples of 14); the network's forward already multiplies by max_depth, so the output
1xHxW is metric depth in metres.
"""
import argparse
import os
import sys

import torch

ENCODERS = {
    "vits": {"encoder": "vits", "features": 64, "out_channels": [48, 96, 192, 384]},
    "vitb": {"encoder": "vitb", "features": 128, "out_channels": [96, 192, 384, 768]},
    "vitl": {"encoder": "vitl", "features": 256, "out_channels": [256, 512, 1024, 1024]},
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repo", required=True, help="Depth-Anything-V2 checkout")
    parser.add_argument("--checkpoint", required=True)
    parser.add_argument("--encoder", choices=sorted(ENCODERS), default="vits")
    parser.add_argument("--max-depth", type=float, required=True, help="20 indoor, 80 outdoor")
    parser.add_argument("--out", required=True)
    parser.add_argument("--opset", type=int, default=17)
    args = parser.parse_args()

    sys.path.insert(0, os.path.join(args.repo, "metric_depth"))
    from depth_anything_v2.dpt import DepthAnythingV2  # noqa: E402

    model = DepthAnythingV2(**ENCODERS[args.encoder], max_depth=args.max_depth)
    model.load_state_dict(torch.load(args.checkpoint, map_location="cpu"))
    model.eval()
    # 640x480 becomes 686x518 under the spec's resize; any multiple of 14 works at run time.
    example = torch.randn(1, 3, 518, 686)
    torch.onnx.export(
        model, example, args.out, opset_version=args.opset,
        input_names=["image"], output_names=["depth"],
        dynamic_axes={"image": {2: "height", 3: "width"}, "depth": {1: "height", 2: "width"}})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
