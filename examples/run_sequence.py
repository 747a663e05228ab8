#!/usr/bin/python3
"""Runs a sequence through ademono's Python API and plots the trajectory with matplotlib.

    PYTHONPATH=build/release/python examples/run_sequence.py \
        --dataset 7scenes:../shared/data/7scenes-seq-a --config configs/7scenes.yaml \
        --frames 0:100 --out out/run_sequence.png

Feeds each frame's image and sensor depth to ademono.System, as `ademono run --depth sensor`
does, prints the ATE against the dataset's ground truth, and saves a PNG: the top view (x-z) of
the estimate aligned to the ground truth, and the position error over time.
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ademono  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", required=True, help="KIND:PATH, e.g. 7scenes:DIR")
    parser.add_argument("--config", help="SLAM config YAML (default: built-in defaults)")
    parser.add_argument("--frames", default=":", help="START:END (END exclusive)")
    parser.add_argument("--out", required=True, help="PNG to write")
    parser.add_argument("--trajectory", help="also write the TUM trajectory here")
    args = parser.parse_args()

    sequence = ademono.open_sequence(args.dataset)
    start, _, end = args.frames.partition(":")
    start = int(start) if start else 0
    end = min(int(end), len(sequence)) if end else len(sequence)
    system = ademono.System(args.config, sequence.camera)

    gt_times, gt_poses = [], []
    for i in range(start, end):
        frame = sequence[i]
        result = system.track(frame.image, depth=frame.depth, timestamp=frame.timestamp)
        if frame.gt_pose is not None:
            gt_times.append(frame.timestamp)
            gt_poses.append(frame.gt_pose)
        if (i - start + 1) % 50 == 0 or i + 1 == end:
            print(f"frame {i + 1 - start}/{end - start}: {result.state}, "
                  f"{system.num_keyframes} keyframes", file=sys.stderr)
    system.shutdown()
    if args.trajectory:
        system.write_trajectory(args.trajectory)

    times, poses = system.trajectory()
    print(f"tracked {len(times)}/{end - start} frames, {system.num_map_points} map points")
    fig, (top, err) = plt.subplots(1, 2, figsize=(11, 5))
    if len(gt_times) >= 3 and len(times) >= 3:
        r = ademono.evaluate((np.array(gt_times), np.array(gt_poses)), (times, poses), align="se3")
        print(f"ATE se3 {r['ape']['rmse']:.4f} m over {r['matched_poses']} poses")
        gt_xyz = r["gt_matched"][1][:, :3, 3]
        est_xyz = r["est_aligned"][1][:, :3, 3]
        top.plot(gt_xyz[:, 0], gt_xyz[:, 2], color="0.4", label="ground truth")
        top.plot(est_xyz[:, 0], est_xyz[:, 2], color="tab:red", label="ademono (se3 aligned)")
        err.plot(r["gt_matched"][0] - r["gt_matched"][0][0], r["ape_errors"], color="tab:blue")
        err.set_title(f"APE, rmse {r['ape']['rmse']:.4f} m")
    else:
        xyz = poses[:, :3, 3]
        top.plot(xyz[:, 0], xyz[:, 2], color="tab:red", label="ademono")
        err.set_title("no ground truth")
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x (m)")
    top.set_ylabel("z (m)")
    top.legend()
    top.set_title(args.dataset)
    err.set_xlabel("time (s)")
    err.set_ylabel("APE (m)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    try:
        main()
    except ademono.InputError as e:
        sys.exit(f"run_sequence.py: error: {e}")
