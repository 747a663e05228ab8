#!/usr/bin/env python3
"""Exports ZoeDepth (ZoeD_NK by default) to ONNX for `--depth model:`.

Loads the model through torch.hub from a local checkout of isl-org/ZoeDepth (which itself pulls
the MiDaS BEiT backbone and the ZoeD_NK checkpoint; timm 0.6.x as ZoeDepth requires). No weights
are shipped with ademono; this script cannot run without them.

  python3 tools/export_zoedepth.py --repo ~/ZoeDepth --model ZoeD_NK --out zoedepth_nk.onnx \
      --example-image some_frame_of_your_domain.png

Use configs/models/zoedepth_nk.yaml as the spec: fixed 512x384 input, RGB with mean/std 0.5,
metric depth output (at a lower resolution; ademono resizes it to the image).

ZoeD_NK routes each image to its NYU (indoor) or KITTI (outdoor) head with a Python-level
argmax, which tracing freezes: the exported graph always uses the head chosen for the example
image. Pass a representative frame of your data with --example-image (or export ZoeD_N / ZoeD_K).
"""
import argparse

import numpy as np
import torch


class MetricDepthOnly(torch.nn.Module):
    def __init__(self, model):
        super().__init__()
        self.model = model

    def forward(self, image):
        # ZoeDepth's forward takes RGB in 0..1 and normalises inside (PrepForMidas); ademono's
        # spec normalises outside, so undo it here: x = (rgb - 0.5) / 0.5 -> rgb = x * 0.5 + 0.5.
        return self.model(image * 0.5 + 0.5)["metric_depth"]


def load_example(path):
    if path is None:
        return torch.rand(1, 3, 384, 512)
    import cv2  # only needed with --example-image
    bgr = cv2.imread(path, cv2.IMREAD_COLOR)
    if bgr is None:
        raise SystemExit(f"{path}: cannot read image")
    rgb = cv2.resize(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), (512, 384)).astype(np.float32) / 255
    return (torch.from_numpy(rgb).permute(2, 0, 1)[None] - 0.5) / 0.5


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repo", required=True, help="ZoeDepth checkout (with hubconf.py)")
    parser.add_argument("--model", default="ZoeD_NK", choices=["ZoeD_N", "ZoeD_K", "ZoeD_NK"])
    parser.add_argument("--example-image", help="frame used for tracing (selects the NK head)")
    parser.add_argument("--out", required=True)
    parser.add_argument("--opset", type=int, default=17)
    args = parser.parse_args()

    model = torch.hub.load(args.repo, args.model, source="local", pretrained=True)
    wrapper = MetricDepthOnly(model).eval()
    with torch.no_grad():
        torch.onnx.export(wrapper, load_example(args.example_image), args.out,
                          opset_version=args.opset, input_names=["image"],
                          output_names=["depth"])
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
