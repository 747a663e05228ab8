#!/usr/bin/env python3
"""Evaluate a checkpoint on a frame range: AbsRel, RMSE (m), delta<1.25.

Each image is resized whole to the network input, the prediction is bilinearly upsampled to the
ground-truth resolution (native 640x480 unless --gt-size), and metrics use the pixels whose
sensor depth lies in (min_depth, max_depth]; they are averaged over images. --median-scale also
reports the metrics after per-image median scaling (how good the shape is, scale aside).

  python3 tools/depthnet/evaluate.py --checkpoint tools/depthnet/runs/small/last.pt \
      --data 7scenes:../shared/data/7scenes-seq-a --frames 400:600
"""

from __future__ import annotations

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402
import torch  # noqa: E402

from depthnet import data as D  # noqa: E402
from depthnet.checkpoint import load_model  # noqa: E402
from depthnet.metrics import average, depth_metrics  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--checkpoint", required=True)
    p.add_argument("--data", required=True, help="7scenes:DIR or tum:DIR")
    p.add_argument("--frames", default="", help="half-open frame range A:B (default all)")
    p.add_argument("--median-scale", action="store_true", help="also report median-scaled metrics")
    p.add_argument("--json", default="", help="write the metrics to this JSON file")
    p.add_argument("--threads", type=int, default=1, choices=[1, 2])
    args = p.parse_args(argv)
    torch.set_num_threads(args.threads)
    try:
        model, state = load_model(args.checkpoint)
        records = D.list_frames(args.data, D.parse_frame_range(args.frames))
    except (D.DataError, FileNotFoundError, ValueError) as e:
        print(f"evaluate.py: error: {e}", file=sys.stderr)
        return 2
    cfg = model.config
    metric, scaled, ratios = [], [], []
    with torch.no_grad():
        for rec in records:
            try:
                rgb, gt, intr = D.load_frame(rec)
            except D.DataError as e:
                print(f"evaluate.py: error: {e}", file=sys.stderr)
                return 2
            small = D.resize_sample(rgb, gt, intr, cfg.input_width, cfg.input_height)[0]
            x, _ = D.to_tensors([small], [np.zeros(small.shape[:2], np.float32)])
            pred = torch.nn.functional.interpolate(model(x), size=gt.shape, mode="bilinear",
                                                   align_corners=False)[0, 0].numpy()
            metric.append(depth_metrics(pred, gt, cfg.min_depth, cfg.max_depth))
            valid = (gt > cfg.min_depth) & (gt <= cfg.max_depth)
            if valid.any():
                ratios.append(float(np.median(gt[valid]) / np.median(pred[valid])))
            if args.median_scale:
                scaled.append(depth_metrics(pred, gt, cfg.min_depth, cfg.max_depth, median_scale=True))
    result = {"checkpoint": args.checkpoint, "data": args.data, "frames": args.frames,
              "num_frames": len(records), "metric": average(metric),
              "median_gt_over_pred": float(np.median(ratios)) if ratios else None}
    if args.median_scale:
        result["median_scaled"] = average(scaled)
    m = result["metric"]
    print(f"{len(records)} frames: AbsRel {m['abs_rel']:.4f}  RMSE {m['rmse']:.4f} m  "
          f"delta1 {m['delta1']:.4f}  (median gt/pred scale {result['median_gt_over_pred']:.3f})")
    if args.median_scale:
        s = result["median_scaled"]
        print(f"median-scaled: AbsRel {s['abs_rel']:.4f}  RMSE {s['rmse']:.4f} m  delta1 {s['delta1']:.4f}")
    if args.json:
        tmp = args.json + ".tmp"
        with open(tmp, "w") as f:
            json.dump(result, f, indent=1)
        os.replace(tmp, args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
