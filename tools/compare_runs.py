#!/usr/bin/env python3
"""Compares run folders written by two ademono builds (tools/check_byte_identical.sh).

    compare_runs.py OLD_ROOT NEW_ROOT RUN... [--ablation DIR]

For each RUN (a folder below both roots): trajectory.tum, trajectory.kitti, keyframes.tum and
map.ply must be byte-identical (a file the old build did not write is reported as added), and
summary.json must agree field by field apart from timing (wall_seconds, fps, timing, per-frame
ms). The new summary must follow schema "ademono.run/1" (docs/slam.md); the old schemas map onto
it as documented there:
  - run's filter_counts_per_frame[i]          -> per_frame[i].filter (+ frame, keypoints)
  - ablate's per_frame[i] (filter stats, frame, keypoints, tracked) -> per_frame[i]
  - ablate's ate_se3_rmse_m / ate_sim3_rmse_m / sim3_scale -> accuracy.* (null: no accuracy)
  - ablate's variant / tracking_rate / note / truth -> only in ablation.json (checked there)
With --ablation DIR, DIR/ablation.md must be byte-identical and DIR/ablation.json agree apart
from wall_seconds. Exit code 1 on any difference.
"""
import argparse
import filecmp
import json
import os
import sys

BYTE_FILES = ["trajectory.tum", "trajectory.kitti", "keyframes.tum", "map.ply"]
TIMING_KEYS = {"wall_seconds", "fps", "timing"}
SCHEMA_KEYS = {"schema", "dataset", "config", "depth", "detector", "seed", "deterministic",
               "filters", "frames", "tracked", "untracked", "lost", "keyframes", "map_points",
               "wall_seconds", "fps", "timing", "filter_counts", "per_frame"}
FRAME_KEYS = {"frame", "timestamp", "tracked", "state", "relocalised", "keyframe", "keypoints",
              "kept", "with_depth", "inliers", "dynamic_points_culled", "filter", "ms"}
ACCURACY_KEYS = {"ate_se3_rmse_m", "ate_sim3_rmse_m", "sim3_scale"}
ABLATION_ONLY_KEYS = {"variant", "tracking_rate", "note", "truth"}


def load(path):
    with open(path) as f:
        return json.load(f)


def check_schema(new, where, problems):
    keys = set(new)
    missing = SCHEMA_KEYS - keys
    extra = keys - SCHEMA_KEYS - {"accuracy"}
    if missing or extra:
        problems.append(f"{where}: schema keys missing {sorted(missing)} extra {sorted(extra)}")
    if new.get("schema") != "ademono.run/1":
        problems.append(f"{where}: schema is {new.get('schema')!r}")
    for i, f in enumerate(new.get("per_frame", [])):
        if set(f) - {"depth_scale"} != FRAME_KEYS:
            problems.append(f"{where}: per_frame[{i}] keys {sorted(f)}")
            break


def compare_frames(old_frames, new_frames, where, problems):
    if len(old_frames) != len(new_frames):
        problems.append(f"{where}: {len(old_frames)} frames before, {len(new_frames)} after")
        return
    for i, (o, n) in enumerate(zip(old_frames, new_frames)):
        for key, value in o.items():
            got = n[key] if key in ("frame", "keypoints", "tracked") else n["filter"].get(key)
            if got != value:
                problems.append(f"{where}[{i}].{key}: {value!r} before, {got!r} after")
                return


def compare_summary(old, new, where, ablation_entry, problems):
    check_schema(new, where, problems)
    for key, value in old.items():
        if key in TIMING_KEYS:
            continue
        if key in ("filter_counts_per_frame", "per_frame"):
            compare_frames(value, new.get("per_frame", []), f"{where}: {key}", problems)
        elif key in ACCURACY_KEYS:
            got = new.get("accuracy", {}).get(key) if "accuracy" in new else None
            if got != value:
                problems.append(f"{where}: {key} {value!r} before, accuracy.{key} {got!r} after")
        elif key in ABLATION_ONLY_KEYS:
            got = ablation_entry.get(key) if ablation_entry is not None else None
            if got != value:
                problems.append(f"{where}: {key} {value!r} before, {got!r} in ablation.json")
        elif key not in new:
            problems.append(f"{where}: {key} no longer written")
        elif new[key] != value:
            problems.append(f"{where}: {key} {value!r} before, {new[key]!r} after")
    added = sorted(set(new) - set(old))
    return added


def strip(value, key):
    if isinstance(value, dict):
        return {k: strip(v, key) for k, v in value.items() if k != key}
    if isinstance(value, list):
        return [strip(v, key) for v in value]
    return value


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old_root")
    parser.add_argument("new_root")
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--ablation")
    args = parser.parse_args()
    problems = []
    ablation_entries = {}
    if args.ablation:
        old_dir = os.path.join(args.old_root, args.ablation)
        new_dir = os.path.join(args.new_root, args.ablation)
        if filecmp.cmp(os.path.join(old_dir, "ablation.md"), os.path.join(new_dir, "ablation.md"),
                       shallow=False):
            print(f"same     {args.ablation}/ablation.md")
        else:
            problems.append(f"{args.ablation}/ablation.md differs")
        old_json = load(os.path.join(old_dir, "ablation.json"))
        new_json = load(os.path.join(new_dir, "ablation.json"))
        if strip(old_json, "wall_seconds") == strip(new_json, "wall_seconds"):
            print(f"same     {args.ablation}/ablation.json (apart from wall_seconds)")
        else:
            problems.append(f"{args.ablation}/ablation.json differs beyond wall_seconds")
        for entry in new_json["variants"]:
            ablation_entries[os.path.join(args.ablation, entry["variant"])] = entry
    for run in args.runs:
        old_dir = os.path.join(args.old_root, run)
        new_dir = os.path.join(args.new_root, run)
        for name in BYTE_FILES + ["groundtruth.tum"]:
            old_file, new_file = os.path.join(old_dir, name), os.path.join(new_dir, name)
            if not os.path.exists(old_file):
                state = "added   " if os.path.exists(new_file) else "absent  "
                print(f"{state} {run}/{name}")
            elif not os.path.exists(new_file):
                problems.append(f"{run}/{name} no longer written")
            elif filecmp.cmp(old_file, new_file, shallow=False):
                print(f"same     {run}/{name}")
            else:
                problems.append(f"{run}/{name} differs")
        before = len(problems)
        added = compare_summary(load(os.path.join(old_dir, "summary.json")),
                                load(os.path.join(new_dir, "summary.json")), f"{run}/summary.json",
                                ablation_entries.get(run) if args.ablation else None, problems)
        if len(problems) == before:
            print(f"same     {run}/summary.json (field by field; schema keys added: "
                  f"{', '.join(added) or 'none'})")
    for p in problems:
        print("DIFFERS  " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
