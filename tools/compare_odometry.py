#!/usr/bin/python3
"""Peer comparison: frame-to-frame RGB-D odometry from Open3D and OpenCV on a 7-Scenes sequence,
scored with `ademono eval` (APE after SE(3) alignment, RPE over 1 frame and over 30 frames), side
by side with any extra trajectories (e.g. an ademono run) in one table.

Uses Debian's python3-open3d and python3-opencv (cv2.rgbd); run it with /usr/bin/python3.

  tools/compare_odometry.py --sequence ../shared/data/7scenes-seq-a --out /tmp/cmp \
      --ademono build/release/bin/ademono --extra ademono=/tmp/run/trajectory.txt

Every method sees the same frames: colour image (grey for the photometric terms) and depth in
metres (0 and 65535 -> no depth). Each writes a TUM trajectory (world_from_cam, timestamps =
frame number / 30 s, starting at the first ground-truth pose) to --out.
"""

import os

# One thread per library unless asked otherwise: fair per-frame timings, deterministic results and
# no OpenMP threads spinning on a shared machine. Must be set before Open3D is imported.
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import glob
import json
import re
import subprocess
import sys
import tempfile
import time

import cv2
import numpy as np

FPS = 30.0
METHODS = ["open3d_hybrid", "open3d_color", "cv_rgbd", "cv_icp", "cv_rgbdicp"]


def fail(message):
    print("compare_odometry: error: " + message, file=sys.stderr)
    sys.exit(2)


# ---- 7-Scenes input ----------------------------------------------------------------------------

def list_frames(directory, max_frames, stride):
    if not os.path.isdir(directory):
        fail(directory + ": no such directory")
    frames = []
    for path in glob.glob(os.path.join(directory, "frame-*.color.*")):
        m = re.match(r"frame-(\d+)\.color\.(png|jpg)$", os.path.basename(path))
        if m:
            frames.append((int(m.group(1)), path))
    frames.sort()
    frames = frames[::stride]
    if max_frames:
        frames = frames[:max_frames]
    if len(frames) < 2:
        fail(directory + ": sequence has fewer than 2 frames")
    return frames


def read_intrinsics(directory):
    path = os.path.join(directory, "camera-intrinsics.txt")
    if not os.path.exists(path):
        return 585.0, 585.0, 320.0, 240.0
    try:
        k = np.loadtxt(path)
    except ValueError as e:
        fail(path + ": " + str(e))
    if k.shape != (3, 3):
        fail(path + ": expected a 3x3 matrix")
    return k[0, 0], k[1, 1], k[0, 2], k[1, 2]


def read_pose(path):
    try:
        m = np.loadtxt(path)
    except (OSError, ValueError) as e:
        fail(path + ": " + str(e))
    if m.shape != (4, 4) or not np.all(np.isfinite(m)):
        fail(path + ": expected a finite 4x4 matrix")
    return m


# --depth-dir: depth maps from elsewhere (e.g. `ademono infer --depth-format png`'s network depth
# cache, 16-bit mm PNGs named after the colour image) fed to every method as if they were the
# sensor's.
DEPTH_DIR = None


def load_frame(directory, number, color_path):
    color = cv2.imread(color_path, cv2.IMREAD_COLOR)
    if color is None:
        fail(color_path + ": image does not decode")
    depth_path = os.path.join(directory, "frame-%06d.depth.png" % number)
    if DEPTH_DIR:
        depth_path = os.path.join(DEPTH_DIR, "frame-%06d.color.png" % number)
    depth = cv2.imread(depth_path, cv2.IMREAD_UNCHANGED)
    if depth is None or depth.dtype != np.uint16:
        fail(depth_path + ": missing or not a 16-bit depth image")
    depth = depth.copy()
    depth[depth == 65535] = 0
    return color, depth


# ---- trajectories ------------------------------------------------------------------------------

def rotation_to_quaternion(r):
    u, _, vt = np.linalg.svd(r)  # ground-truth rotations are ~1e-4 off orthonormal
    r = u @ vt
    if np.linalg.det(r) < 0:
        r = u @ np.diag([1, 1, -1]) @ vt
    q = np.empty(4)  # x y z w
    tr = np.trace(r)
    if tr > 0:
        s = np.sqrt(tr + 1.0) * 2
        q[3] = 0.25 * s
        q[0] = (r[2, 1] - r[1, 2]) / s
        q[1] = (r[0, 2] - r[2, 0]) / s
        q[2] = (r[1, 0] - r[0, 1]) / s
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = np.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k]) * 2
        q[i] = 0.25 * s
        q[3] = (r[k, j] - r[j, k]) / s
        q[j] = (r[j, i] + r[i, j]) / s
        q[k] = (r[k, i] + r[i, k]) / s
    return q / np.linalg.norm(q)


def write_tum(path, stamps, poses):
    tmp = path + ".tmp.%d" % os.getpid()
    with open(tmp, "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw (world_from_cam)\n")
        for t, m in zip(stamps, poses):
            q = rotation_to_quaternion(m[:3, :3])
            f.write("%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n" %
                    (t, m[0, 3], m[1, 3], m[2, 3], q[0], q[1], q[2], q[3]))
    os.replace(tmp, path)


# ---- odometry methods --------------------------------------------------------------------------

class Open3dOdometry:
    def __init__(self, intrinsics, size, hybrid):
        import open3d as o3d
        self.o3d = o3d
        fx, fy, cx, cy = intrinsics
        self.intrinsic = o3d.camera.PinholeCameraIntrinsic(size[0], size[1], fx, fy, cx, cy)
        self.jacobian = (o3d.pipelines.odometry.RGBDOdometryJacobianFromHybridTerm() if hybrid
                         else o3d.pipelines.odometry.RGBDOdometryJacobianFromColorTerm())
        self.option = o3d.pipelines.odometry.OdometryOption()

    def prepare(self, color, depth):
        o3d = self.o3d
        rgb = cv2.cvtColor(color, cv2.COLOR_BGR2RGB)
        return o3d.geometry.RGBDImage.create_from_color_and_depth(
            o3d.geometry.Image(rgb), o3d.geometry.Image(depth), depth_scale=1000.0,
            depth_trunc=4.0, convert_rgb_to_intensity=True)

    def prev_from_cur(self, prev, cur):
        ok, trans, _ = self.o3d.pipelines.odometry.compute_rgbd_odometry(
            cur, prev, self.intrinsic, np.identity(4), self.jacobian, self.option)
        return ok, trans


class OpenCvOdometry:
    def __init__(self, intrinsics, kind):
        fx, fy, cx, cy = intrinsics
        k = np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]], dtype=np.float64)
        create = {"cv_rgbd": cv2.rgbd.RgbdOdometry_create,
                  "cv_icp": cv2.rgbd.ICPOdometry_create,
                  "cv_rgbdicp": cv2.rgbd.RgbdICPOdometry_create}[kind]
        self.odometry = create(k)

    def prepare(self, color, depth):
        grey = cv2.cvtColor(color, cv2.COLOR_BGR2GRAY)
        metres = depth.astype(np.float32) / 1000.0
        mask = (depth > 0).astype(np.uint8) * 255
        return grey, metres, mask

    def prev_from_cur(self, prev, cur):
        # OpenCV: Rt maps points of the source frame into the destination frame.
        ok, rt = self.odometry.compute(cur[0], cur[1], cur[2], prev[0], prev[1], prev[2])
        return ok, rt


def make_method(name, intrinsics, size):
    if name == "open3d_hybrid":
        return Open3dOdometry(intrinsics, size, hybrid=True)
    if name == "open3d_color":
        return Open3dOdometry(intrinsics, size, hybrid=False)
    return OpenCvOdometry(intrinsics, name)


def run_method(name, frames, directory, intrinsics, first_pose):
    size = None
    method = None
    poses = [first_pose]
    failures = 0
    prev = None
    # CPU time, not wall time: the methods run on one thread, and on a shared machine wall time
    # mostly measures the other processes.
    start = time.process_time()
    for n, (number, path) in enumerate(frames):
        color, depth = load_frame(directory, number, path)
        if method is None:
            size = (color.shape[1], color.shape[0])
            method = make_method(name, intrinsics, size)
        cur = method.prepare(color, depth)
        if n > 0:
            ok, prev_from_cur = method.prev_from_cur(prev, cur)
            if not ok:
                failures += 1  # keep the previous pose: a zero-motion step
                prev_from_cur = np.identity(4)
            poses.append(poses[-1] @ prev_from_cur)
        prev = cur
    seconds = time.process_time() - start
    return poses, failures, seconds / max(1, len(frames) - 1) * 1000.0


# ---- scoring -----------------------------------------------------------------------------------

def find_cli(given):
    if given:
        if not os.path.exists(given):
            fail(given + ": no such file")
        return given
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    for candidate in sorted(glob.glob(os.path.join(root, "build", "*", "bin", "ademono"))):
        return candidate
    fail("cannot find the ademono CLI; pass --ademono")


def score(cli, gt_path, est_path):
    metrics = {}
    with tempfile.TemporaryDirectory() as tmp:
        for key, align, extra in (("1", "se3", []), ("30", "se3", ["--rpe-delta", "30"]),
                                  ("sim3", "sim3", [])):
            out = os.path.join(tmp, "m.json")
            cmd = [cli, "eval", "--gt", gt_path, "--est", est_path, "--format", "tum",
                   "--align", align, "--json", out] + extra
            proc = subprocess.run(cmd, capture_output=True, text=True)
            if proc.returncode != 0:
                fail(proc.stderr.strip() or "ademono eval failed on " + est_path)
            with open(out) as f:
                metrics[key] = json.load(f)
    return {
        "ate_rmse": metrics["1"]["ape"]["rmse"],
        "ate_max": metrics["1"]["ape"]["max"],
        "ate_sim3_rmse": metrics["sim3"]["ape"]["rmse"],
        "rpe1_trans_rmse": metrics["1"]["rpe_trans"]["rmse"],
        # None when the sequence is shorter than 30 frames (no pairs).
        "rpe30_trans_rmse": (metrics["30"]["rpe_trans"]["rmse"]
                             if metrics["30"]["rpe_trans"]["count"] else None),
        "rpe30_rot_rmse_deg": (metrics["30"]["rpe_rot_deg"]["rmse"]
                               if metrics["30"]["rpe_rot_deg"]["count"] else None),
        "matched": metrics["1"]["matched_poses"],
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sequence", required=True, help="7-Scenes folder (7scenes:DIR layout)")
    parser.add_argument("--out", required=True, help="folder for the TUM trajectories")
    parser.add_argument("--methods", default=",".join(METHODS),
                        help="comma-separated subset of " + ",".join(METHODS))
    parser.add_argument("--frames", type=int, default=0, help="use only the first N frames")
    parser.add_argument("--stride", type=int, default=1, help="use every Nth frame")
    parser.add_argument("--ademono", help="path of the ademono CLI (default: build/*/bin/ademono)")
    parser.add_argument("--extra", action="append", default=[], metavar="NAME=FILE",
                        help="an extra TUM trajectory to score in the same table (repeatable)")
    parser.add_argument("--json", help="also write the table as JSON here")
    parser.add_argument("--depth-dir", help="depth maps to use instead of the sensor's "
                        "(`ademono infer --depth-format png` cache: DIR/frame-XXXXXX.color.png, "
                        "16-bit mm)")
    parser.add_argument("--reuse", action="store_true",
                        help="re-score trajectories already in --out from an identical run "
                             "(same sequence, frames, stride) instead of recomputing them")
    args = parser.parse_args()
    global DEPTH_DIR
    if args.depth_dir:
        if not os.path.isdir(args.depth_dir):
            fail(args.depth_dir + ": --depth-dir is not a folder")
        DEPTH_DIR = args.depth_dir

    cv2.setNumThreads(int(os.environ["OMP_NUM_THREADS"]))
    methods = [m for m in args.methods.split(",") if m]
    for m in methods:
        if m not in METHODS:
            fail("unknown method '%s' (expected %s)" % (m, ", ".join(METHODS)))
    if args.stride < 1 or args.frames < 0:
        fail("--stride must be >= 1 and --frames >= 0")
    extras = []
    for item in args.extra:
        if "=" not in item:
            fail("--extra expects NAME=FILE, got '%s'" % item)
        name, path = item.split("=", 1)
        if not os.path.isfile(path):
            fail(path + ": no such file")
        extras.append((name, path))
    cli = find_cli(args.ademono)

    frames = list_frames(args.sequence, args.frames, args.stride)
    intrinsics = read_intrinsics(args.sequence)
    stamps = [number / FPS for number, _ in frames]
    gt = [read_pose(os.path.join(args.sequence, "frame-%06d.pose.txt" % number))
          for number, _ in frames]
    os.makedirs(args.out, exist_ok=True)
    gt_path = os.path.join(args.out, "groundtruth.txt")
    write_tum(gt_path, stamps, gt)

    rows = []
    for name in methods:
        path = os.path.join(args.out, name + ".txt")
        sidecar = os.path.join(args.out, name + ".run.json")
        run_key = {"sequence": os.path.abspath(args.sequence), "frames": len(frames),
                   "stride": args.stride, "depth_dir": os.path.abspath(args.depth_dir or "")}
        cached = None
        if args.reuse and os.path.exists(path) and os.path.exists(sidecar):
            with open(sidecar) as f:
                cached = json.load(f)
            if cached.get("key") != run_key:
                cached = None
        if cached:
            failures, ms = cached["failures"], cached["ms_per_frame"]
        else:
            poses, failures, ms = run_method(name, frames, args.sequence, intrinsics, gt[0])
            write_tum(path, stamps, poses)
            with open(sidecar, "w") as f:
                json.dump({"key": run_key, "failures": failures, "ms_per_frame": ms}, f)
        row = {"method": name, "failures": failures, "ms_per_frame": ms}
        row.update(score(cli, gt_path, path))
        rows.append(row)
        print("%-16s done: ATE %.4f m, %.1f CPU ms/frame, %d failed pairs" %
              (name, row["ate_rmse"], ms, failures), file=sys.stderr)
    for name, path in extras:
        row = {"method": name, "failures": None, "ms_per_frame": None}
        row.update(score(cli, gt_path, path))
        rows.append(row)

    print("sequence: %s, %d frames (stride %d), APE after SE(3) alignment" %
          (args.sequence, len(frames), args.stride))
    print()
    print("| method | ATE rmse (m) | ATE sim3 rmse (m) | ATE max (m) | RPE 1 frame rmse (m) "
          "| RPE 30 frames rmse (m) | RPE 30 frames rot rmse (deg) | matched | CPU ms/frame "
          "| failed pairs |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    def fmt(value, spec):
        return "-" if value is None else spec % value

    for r in rows:
        print("| %s | %.4f | %.4f | %.4f | %.4f | %s | %s | %d | %s | %s |" % (
            r["method"], r["ate_rmse"], r["ate_sim3_rmse"], r["ate_max"], r["rpe1_trans_rmse"],
            fmt(r["rpe30_trans_rmse"], "%.4f"), fmt(r["rpe30_rot_rmse_deg"], "%.3f"), r["matched"],
            "-" if r["ms_per_frame"] is None else "%.1f" % r["ms_per_frame"],
            "-" if r["failures"] is None else str(r["failures"])))
    if args.json:
        tmp = args.json + ".tmp.%d" % os.getpid()
        with open(tmp, "w") as f:
            json.dump({"sequence": args.sequence, "frames": len(frames), "stride": args.stride,
                       "rows": rows}, f, indent=2)
        os.replace(tmp, args.json)


if __name__ == "__main__":
    main()
