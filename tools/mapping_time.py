#!/usr/bin/env python3
"""Where a run's mapping time goes, from its `ademono --log-level debug run ...` log.

Sums, over the keyframes, the mapping work that runs on the tracking thread (structure, fusion,
gathering the local BA, applying it and culling, loop closing), the local BA solves on the
mapping thread, and the time tracking waited at a hand-off for a solve to finish. Prints one
table; give several logs to compare runs side by side (e.g. sensor depth against --depth none):

  B=build/release/bin/ademono; S=7scenes:../shared/data/7scenes-seq-a
  $B --log-level debug run --dataset $S --depth sensor --out /tmp/s > /tmp/s.log 2>&1
  $B --log-level debug run --dataset $S --depth none --out /tmp/n > /tmp/n.log 2>&1
  python3 tools/mapping_time.py /tmp/s.log /tmp/n.log
"""
import argparse
import re
import sys

PATTERNS = {
    "structure": r"keyframe \d+: structure ([0-9.]+) ms",
    "fuse": r"keyframe \d+: structure [0-9.]+ ms, fuse ([0-9.]+) ms",
    "gather": r"gather ([0-9.]+) ms, cpu",
    "BA solve (mapping thread)": r"observations: ([0-9.]+) ms, cpu",
    "BA solve CPU": r"observations: [0-9.]+ ms, cpu ([0-9.]+) ms",
    "waited at hand-off": r"keyframe \d+: waited ([0-9.]+) ms",
    "apply + cull": r"apply \+ cull ([0-9.]+) ms",
    "loop closing": r"loop ([0-9.]+) ms, cpu",
}
TRACKING_THREAD = ("structure", "fuse", "gather", "waited at hand-off", "apply + cull",
                   "loop closing")


def measure(path):
    with open(path) as f:
        text = f.read()
    row = {name: sum(float(x) for x in re.findall(p, text)) for name, p in PATTERNS.items()}
    row["keyframes"] = len(re.findall(r"keyframe \d+: structure", text))
    obs = [int(x) for x in re.findall(r"(\d+) observations:", text)]
    row["BA observations (mean)"] = sum(obs) / len(obs) if obs else 0.0
    row["tracking thread in all"] = sum(row[k] for k in TRACKING_THREAD)
    return row


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("logs", nargs="+", help="logs of `ademono --log-level debug run`")
    a = p.parse_args()
    rows = []
    for path in a.logs:
        try:
            rows.append(measure(path))
        except OSError as e:
            print("mapping_time.py: %s: %s" % (path, e.strerror), file=sys.stderr)
            return 1
        if rows[-1]["keyframes"] == 0:
            print("mapping_time.py: %s: no keyframe lines (not a --log-level debug log?)" % path,
                  file=sys.stderr)
            return 1
    print("| ms | " + " | ".join(a.logs) + " |")
    print("|---|" + "---|" * len(a.logs))
    for name in ["keyframes", "BA observations (mean)"] + list(PATTERNS) + ["tracking thread in all"]:
        fmt = "%d" if name == "keyframes" else "%.0f"
        print("| %s | %s |" % (name, " | ".join(fmt % r[name] for r in rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
