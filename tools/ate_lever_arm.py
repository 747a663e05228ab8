#!/usr/bin/python3
"""How much of a run's ATE is a fixed offset between the ground truth's body frame and the camera.

  tools/ate_lever_arm.py RUN_DIR [RUN_DIR...]

Reads RUN_DIR/trajectory.tum and RUN_DIR/groundtruth.tum (what `ademono run --out` writes with
ground truth: the same timestamps, world_from_cam) and prints, per run, the ATE after a sim3
alignment (as `ademono eval`) and after a sim3 alignment plus a lever arm: a constant offset l in
the ground truth's body frame, g_i = s A p_i + t + R_i l (R_i the ground truth's rotation),
fitted by alternating Umeyama and linear least squares. A ground truth that tracks another point
of the rig than the camera's centre (a depth camera, a marker body) leaves an error that turns
with the camera, which no sim3 alignment removes. On an exact ground truth (the synthetic rows)
the fitted offset is 0. Three free parameters always fit some noise:
read the offset's size and whether it repeats across runs, not the smaller ATE alone.
"""
import os
import sys

import numpy as np


def fail(path, problem):
    print("ate_lever_arm: %s: %s" % (path, problem), file=sys.stderr)
    sys.exit(2)


def load_tum(path):
    poses = {}
    try:
        with open(path) as f:
            for n, line in enumerate(f, 1):
                if not line.strip() or line.startswith("#"):
                    continue
                v = line.split()
                if len(v) != 8:
                    fail(path, "line %d: expected 8 columns (t x y z qx qy qz qw), found %d" % (n, len(v)))
                try:
                    poses[v[0]] = np.array([float(x) for x in v[1:]])
                except ValueError:
                    fail(path, "line %d: not a number" % n)
    except OSError as e:
        fail(path, e.strerror)
    return poses


def rotation(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def umeyama(p, g):
    mp, mg = p.mean(0), g.mean(0)
    x, y = p - mp, g - mg
    u, s, vt = np.linalg.svd(y.T @ x / len(p))
    d = np.eye(3)
    if np.linalg.det(u @ vt) < 0:
        d[2, 2] = -1
    a = u @ d @ vt
    scale = np.trace(np.diag(s) @ d) * len(p) / (x ** 2).sum()
    return scale, a, mg - scale * a @ mp


def rms(r):
    return float(np.sqrt((r ** 2).sum(1).mean()))


def main():
    if len(sys.argv) < 2:
        print("ate_lever_arm: no run folder given (usage: tools/ate_lever_arm.py RUN_DIR...)",
              file=sys.stderr)
        sys.exit(2)
    if sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        sys.exit(0)
    rows = []  # printed once every run is read: a bad run leaves no half table
    for run in sys.argv[1:]:
        est = load_tum(os.path.join(run, "trajectory.tum"))
        gt = load_tum(os.path.join(run, "groundtruth.tum"))
        keys = [k for k in est if k in gt]
        if len(keys) < 10:
            fail(run, "%d poses with ground truth at the same timestamp (need 10)" % len(keys))
        p = np.array([est[k][:3] for k in keys])
        g = np.array([gt[k][:3] for k in keys])
        rotations = np.array([rotation(gt[k][3:]) for k in keys])
        s, a, t = umeyama(p, g)
        plain = rms(s * p @ a.T + t - g)
        lever = np.zeros(3)
        for _ in range(100):  # alternate: sim3 with the offset removed, then the offset
            s, a, t = umeyama(p, g - rotations @ lever)
            lever = np.linalg.lstsq(rotations.reshape(-1, 3), (g - (s * p @ a.T + t)).reshape(-1),
                                    rcond=None)[0]
        fitted = rms(s * p @ a.T + t + rotations @ lever - g)
        rows.append("| %s | %d | %.4f | %.4f | (%.3f, %.3f, %.3f), %.3f |" %
                    (run, len(keys), plain, fitted, *lever, np.linalg.norm(lever)))
    print("| run | poses | ATE sim3 (m) | with lever arm (m) | lever arm in the body frame (m) |")
    print("|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
