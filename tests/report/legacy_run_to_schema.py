#!/usr/bin/env python3
"""Converts a run folder written by the current `ademono run` (summary.json without "schema",
filter counts in "filter_counts_per_frame") to the unified run-output schema "ademono.run/1",
so the report's browser test runs on a real run before `run` writes that schema itself.

What the old summary does not record is derived from the files next to it, never invented:
  tracked / state / relocalised   trajectory.tum (a frame has a pose or not; untracked before
                                  the first pose = not_initialized, after it = lost; the first
                                  pose after a lost frame = relocalised)
  keyframe                        keyframes.tum
  timestamp                       the sequence's rgb.txt (TUM layout), line = frame index
  groundtruth.tum                 the sequence's groundtruth.txt at the frames' timestamps
Per-frame "ms", "inliers", "with_depth" and "dynamic_points_culled" are not in the old output:
"ms" is left out (the report then says it has no per-frame timing), the counts are -1.

Usage: legacy_run_to_schema.py RUN_DIR TUM_SEQUENCE_DIR  (rewrites RUN_DIR/summary.json)
"""
import json
import os
import sys


def read_tum(path):
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                rows.append(line.split())
    return rows


def main():
    run_dir, seq_dir = sys.argv[1], sys.argv[2]
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    if summary.get("schema") == "ademono.run/1":
        return 0
    stamps = [float(r[0]) for r in read_tum(os.path.join(seq_dir, "rgb.txt"))]
    tracked = {round(float(r[0]), 6) for r in read_tum(os.path.join(run_dir, "trajectory.tum"))}
    keyframes = {round(float(r[0]), 6) for r in read_tum(os.path.join(run_dir, "keyframes.tum"))}
    per_frame = []
    seen_pose = False
    previous_lost = False
    for counts in summary.pop("filter_counts_per_frame"):
        frame = counts.pop("frame")
        keypoints = counts.pop("keypoints")
        t = stamps[frame]
        is_tracked = round(t, 6) in tracked
        state = "ok" if is_tracked else ("lost" if seen_pose else "not_initialized")
        per_frame.append({
            "frame": frame, "timestamp": t, "tracked": is_tracked, "state": state,
            "relocalised": is_tracked and previous_lost, "keyframe": round(t, 6) in keyframes,
            "keypoints": keypoints, "kept": counts.get("kept", 0), "with_depth": -1,
            "inliers": -1, "dynamic_points_culled": -1, "filter": counts,
        })
        previous_lost = state == "lost"
        seen_pose = seen_pose or is_tracked
    summary["schema"] = "ademono.run/1"
    summary["per_frame"] = per_frame
    gt_rows = read_tum(os.path.join(seq_dir, "groundtruth.txt"))
    gt = {round(float(r[0]), 6): r for r in gt_rows}
    with open(os.path.join(run_dir, "groundtruth.tum"), "w") as f:
        for p in per_frame:
            row = gt.get(round(p["timestamp"], 6))
            if row:
                f.write(" ".join(row) + "\n")
    with open(os.path.join(run_dir, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
