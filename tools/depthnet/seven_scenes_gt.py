#!/usr/bin/env python3
"""Write 7-Scenes ground truth (frame-XXXXXX.pose.txt, 4x4 world_from_cam) as a TUM trajectory
(timestamp = frame index / 30 s, the timestamps `ademono run` gives 7-Scenes frames), for
`ademono eval --gt`.

  python3 tools/depthnet/seven_scenes_gt.py ../shared/data/7scenes-seq-a --frames 400:600 --out gt.tum
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from depthnet.data import DataError, parse_frame_range  # noqa: E402


def quaternion_xyzw(r: np.ndarray) -> np.ndarray:
    """Unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method), w >= 0."""
    m = r
    tr = np.trace(m)
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i] = 0.25 * s
        q[j] = (m[j, i] + m[i, j]) / s
        q[k] = (m[k, i] + m[i, k]) / s
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[3] < 0 else q


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir")
    p.add_argument("--frames", default="")
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    try:
        rng = parse_frame_range(args.frames)
        names = sorted(n for n in os.listdir(args.dir) if n.endswith(".pose.txt"))
        if not names:
            raise DataError(f"{args.dir}: no frame-XXXXXX.pose.txt files")
        if rng:
            if rng[1] > len(names):
                raise DataError(f"{args.dir}: frame range exceeds the {len(names)} poses present")
            names = names[rng[0]:rng[1]]
        lines = ["# timestamp tx ty tz qx qy qz qw (world_from_cam)"]
        for n in names:
            path = os.path.join(args.dir, n)
            m = np.loadtxt(path)
            if m.shape != (4, 4):
                raise DataError(f"{path}: expected a 4x4 matrix")
            index = int(n.split("-")[1].split(".")[0])
            q = quaternion_xyzw(m[:3, :3])
            lines.append(f"{index / 30.0:.9f} " + " ".join(f"{v:.9f}" for v in (*m[:3, 3], *q)))
    except (DataError, OSError, ValueError) as e:
        print(f"seven_scenes_gt.py: error: {e}", file=sys.stderr)
        return 2
    with open(args.out + ".tmp", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(args.out + ".tmp", args.out)
    print(f"wrote {len(lines) - 1} poses to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
