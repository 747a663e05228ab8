#!/usr/bin/env python3
"""Exports Metric3D v2 (ViT-Small by default) to ONNX for `--depth model:`.

Loads the model through torch.hub from a local checkout of YvanYin/Metric3D (its hubconf.py and
a downloaded checkpoint; mmcv/mmengine installed as Metric3D requires). No weights are shipped
with ademono; this script cannot run without them.

  python3 tools/export_metric3d.py --repo ~/Metric3D --model metric3d_vit_small \
      --out metric3d_v2_small.onnx

Use configs/models/metric3d_v2_small.yaml as the spec: fixed 1064x616 input (letterboxed with
the mean colour), output = depth for a canonical camera of focal 1000 px, which ademono rescales
by the focal at the network input resolution.
"""
import argparse

import torch


class DepthOnly(torch.nn.Module):
    """Metric3D's inference() returns depth, confidence and a dict; keep the canonical depth."""

    def __init__(self, model):
        super().__init__()
        self.model = model

    def forward(self, image):
        depth, _, _ = self.model.inference({"input": image})
        return depth


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repo", required=True, help="Metric3D checkout (with hubconf.py)")
    parser.add_argument("--model", default="metric3d_vit_small",
                        choices=["metric3d_vit_small", "metric3d_vit_large", "metric3d_vit_giant2"])
    parser.add_argument("--out", required=True)
    parser.add_argument("--opset", type=int, default=17)
    args = parser.parse_args()

    model = torch.hub.load(args.repo, args.model, source="local", pretrain=True)
    wrapper = DepthOnly(model).eval()
    example = torch.randn(1, 3, 616, 1064)  # ViT input size (height, width)
    with torch.no_grad():
        torch.onnx.export(wrapper, example, args.out, opset_version=args.opset,
                          input_names=["image"], output_names=["depth"])
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
