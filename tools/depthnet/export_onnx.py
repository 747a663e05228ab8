#!/usr/bin/env python3
"""Export a checkpoint to ONNX for ademono's `--depth model:FILE.onnx,spec=Y.yaml` provider.

ONNX contract (what configs/models/ademono_depthnet.yaml describes):
  input  "image": 1 x 3 x H x W float32, RGB, pixel / 255 (0..1); H x W fixed (the model's input
                  size, 144 x 192 for the small variant); the whole frame resized to it
                  (cv2.INTER_AREA, as in training).
  output "depth": 1 x 1 x H x W float32, metric depth in metres.
The ImageNet normalisation is inside the graph. Opset 13 by default.

  python3 tools/depthnet/export_onnx.py --checkpoint tools/depthnet/runs/small/last.pt \
      --out tools/depthnet/runs/small/depthnet_small.onnx
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import torch  # noqa: E402

from depthnet.checkpoint import load_model  # noqa: E402
from depthnet.model import DepthNet  # noqa: E402


def export(model: DepthNet, path: str, opset: int = 13) -> None:
    """Writes the ONNX atomically and checks it with onnx.checker."""
    import onnx

    cfg = model.config
    model.eval()
    dummy = torch.rand(1, 3, cfg.input_height, cfg.input_width)
    tmp = path + ".tmp.onnx"
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with torch.no_grad(), warnings.catch_warnings():
        # torch 1.13 warns about prim::Constant shape inference for the constant buffers; the
        # exported shapes are checked below and by the tests.
        warnings.filterwarnings("ignore", message="The shape inference of prim::Constant")
        torch.onnx.export(model, dummy, tmp, opset_version=opset, input_names=["image"],
                          output_names=["depth"], do_constant_folding=True)
    proto = onnx.load(tmp)
    onnx.checker.check_model(proto)
    os.replace(tmp, path)


def spec_yaml(model: DepthNet, name: str = "ademono_depthnet") -> str:
    cfg = model.config
    return SPEC_TEMPLATE.format(name=name, width=cfg.input_width, height=cfg.input_height,
                                min_depth=cfg.min_depth, max_depth=cfg.max_depth)


SPEC_TEMPLATE = """\
# ademono's own depth network (tools/depthnet, docs/depthnet.md), exported by
# tools/depthnet/export_onnx.py. Format: src/ademono/depth/model_spec.h.
#   ademono ... --depth model:FILE.onnx,spec=configs/models/ademono_depthnet.yaml
# ONNX: input "image" 1x3xHxW RGB in 0..1 (ImageNet normalisation is inside the graph),
# output "depth" 1x1xHxW metric depth in metres at the input resolution.
name: {name}
input:
  resize: fixed          # whole frame stretched to the training input (4:3 frames keep aspect)
  width: {width}
  height: {height}
  interpolation: area    # as in training (cv2.INTER_AREA when shrinking)
  color: rgb
  units: unit            # x = (p / 255 - mean) / std
  mean: [0.0, 0.0, 0.0]
  std: [1.0, 1.0, 1.0]
output:
  kind: metric
  scale: 1.0
  min_depth: 0.0         # the metric bins span [{min_depth}, {max_depth}] m
  max_depth: {max_depth}
"""


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--checkpoint", required=True)
    p.add_argument("--out", required=True, help="output .onnx path")
    p.add_argument("--opset", type=int, default=13)
    p.add_argument("--spec-out", default="", help="also write a model spec YAML here")
    args = p.parse_args(argv)
    try:
        model, _ = load_model(args.checkpoint)
    except (FileNotFoundError, ValueError) as e:
        print(f"export_onnx.py: error: {e}", file=sys.stderr)
        return 2
    export(model, args.out, args.opset)
    print(f"wrote {args.out} (input 1x3x{model.config.input_height}x{model.config.input_width})")
    if args.spec_out:
        with open(args.spec_out + ".tmp", "w") as f:
            f.write(spec_yaml(model))
        os.replace(args.spec_out + ".tmp", args.spec_out)
        print(f"wrote {args.spec_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
