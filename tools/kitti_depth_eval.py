#!/usr/bin/python3
"""How a depth network reads a KITTI drive, without LiDAR: the error model of a model spec
(docs/models.md, configs/models/pydnet_kitti.yaml), measured two ways.

1. Against the road: in the middle of the lane (|u - cx| < --lane-px at the bottom, narrowing
   towards the horizon), the flat-road depth of a camera --height above the road, per pixel row,
   over the network's depth at that pixel. The flat-road depth assumes the camera's optical axis
   parallel to the road (KITTI's rig is within about a degree), so a row's ratio also carries the
   frame's pitch: rows near the horizon are the most sensitive (0.1 deg is 1 % at row 360,
   5 % at row 220).
2. Against the map: ORB keypoints of frame k matched in frame k + --gap and triangulated with
   the ground-truth poses (poses/NN.txt, the left grey camera, moved onto the colour camera with
   calib.txt's P2): metric depths made by geometry alone, kept where the two rays meet at more
   than --min-parallax degrees and reproject within 1 px in both frames. Their depth over the
   network's, per depth band, and after each frame's own median scale (what SLAM's per-frame
   scale correction removes).

The network's depth comes from an `ademono infer` cache (DIR/<frame name>.tiff, float32 m, or .png, uint16 mm):

  build/release/bin/ademono infer --dataset kitti:../shared/data/kitti-00/sequences/00 \\
      --depth-model model:../shared/models/pydnet_kitti.onnx,spec=configs/models/pydnet_kitti.yaml \\
      --out /tmp/pydnet00
  tools/kitti_depth_eval.py --sequence ../shared/data/kitti-00/sequences/00 --depth /tmp/pydnet00/depth

Prints the tables and, with --json, writes every figure. Uses Debian's python3-opencv: run it with
/usr/bin/python3.
"""

import argparse
import glob
import json
import os
import sys

import cv2
import numpy as np


def fail(message):
    print("kitti_depth_eval: error: " + message, file=sys.stderr)
    sys.exit(2)


def read_calib(path, key):
    with open(path) as f:
        for line in f:
            fields = line.split()
            if fields and fields[0] == key + ":":
                if len(fields) != 13:
                    fail(f"{path}: {key} needs 12 numbers")
                return np.array([float(x) for x in fields[1:]]).reshape(3, 4)
    fail(f"{path}: has no {key} line")


def read_poses(path):
    poses = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            fields = line.split()
            if not fields:
                continue
            if len(fields) != 12:
                fail(f"{path}:{number}: expected 12 numbers")
            m = np.eye(4)
            m[:3, :] = np.array([float(x) for x in fields]).reshape(3, 4)
            poses.append(m)
    return poses


def find_poses(sequence):
    name = os.path.basename(os.path.normpath(sequence))
    for base in [sequence, os.path.join(sequence, ".."), os.path.join(sequence, "..", "..")]:
        candidate = os.path.join(base, "poses", name + ".txt")
        if os.path.isfile(candidate):
            return candidate
    return None


def robust_sigma(x):
    x = np.asarray(x)
    return 1.4826 * np.median(np.abs(x - np.median(x)))


def percentiles(x, qs=(10, 50, 90)):
    return [float(np.percentile(x, q)) for q in qs]


def road_rows(images, depths, k, height, rows, lane_px):
    """Ratio flat-road depth / network depth for each lane pixel of `rows`."""
    fx, fy, cx, cy = k[0, 0], k[1, 1], k[0, 2], k[1, 2]
    per_row = {r: [] for r in rows}
    per_frame = []
    bottom = max(rows)
    for depth in depths:
        ratios = []
        for r in rows:
            if r <= cy + 1 or r >= depth.shape[0]:
                continue
            flat = fy * height / (r - cy)
            # The lane narrows with distance like the road does: lane_px at the bottom row.
            half = lane_px * (r - cy) / (bottom - cy)
            cols = np.arange(int(round(cx - half)), int(round(cx + half)) + 1)
            d = depth[r, cols]
            d = d[d > 0]
            if d.size == 0:
                continue
            ratio = flat / d
            per_row[r].extend(ratio.tolist())
            ratios.extend(ratio.tolist())
        if ratios:
            per_frame.append(float(np.median(ratios)))
    return per_row, per_frame


def triangulate_pairs(images, depths, poses, cam0_from_cam2, k, gap, min_parallax, max_frames):
    """(z_geometry, z_network, frame) for ORB matches of frame i and i + gap."""
    orb = cv2.ORB_create(nfeatures=3000, fastThreshold=12)
    matcher = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=True)
    out = []
    for i in range(0, len(images) - gap, max(1, max_frames)):
        j = i + gap
        ga = cv2.cvtColor(images[i], cv2.COLOR_BGR2GRAY)
        gb = cv2.cvtColor(images[j], cv2.COLOR_BGR2GRAY)
        ka, da = orb.detectAndCompute(ga, None)
        kb, db = orb.detectAndCompute(gb, None)
        if da is None or db is None:
            continue
        matches = [m for m in matcher.match(da, db) if m.distance <= 40]
        if len(matches) < 8:
            continue
        world_from_a = poses[i] @ cam0_from_cam2
        world_from_b = poses[j] @ cam0_from_cam2
        b_from_a = np.linalg.inv(world_from_b) @ world_from_a
        pa = k @ np.hstack([np.eye(3), np.zeros((3, 1))])
        pb = k @ b_from_a[:3, :]
        ua = np.array([ka[m.queryIdx].pt for m in matches]).T
        ub = np.array([kb[m.trainIdx].pt for m in matches]).T
        x = cv2.triangulatePoints(pa, pb, ua, ub)
        x = x[:3] / x[3]
        xb = b_from_a[:3, :3] @ x + b_from_a[:3, 3:4]
        centre_b_in_a = -b_from_a[:3, :3].T @ b_from_a[:3, 3]
        for n in range(x.shape[1]):
            za, zb = x[2, n], xb[2, n]
            if not (za > 0.5 and zb > 0.5):
                continue
            ra = (pa @ np.append(x[:, n], 1.0))
            rb = (pb @ np.append(x[:, n], 1.0))
            ea = np.linalg.norm(ra[:2] / ra[2] - ua[:, n])
            eb = np.linalg.norm(rb[:2] / rb[2] - ub[:, n])
            if ea > 1.0 or eb > 1.0:
                continue
            ray_a = x[:, n]
            ray_b = x[:, n] - centre_b_in_a
            cos = ray_a @ ray_b / (np.linalg.norm(ray_a) * np.linalg.norm(ray_b))
            if np.degrees(np.arccos(np.clip(cos, -1, 1))) < min_parallax:
                continue
            u, v = int(round(ua[0, n])), int(round(ua[1, n]))
            zn = depths[i][v, u]
            if zn <= 0:
                continue
            out.append((float(za), float(zn), i, float(v)))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sequence", required=True, help="KITTI sequence folder (image_2, calib.txt)")
    parser.add_argument("--depth", required=True, help="folder of depth PNGs (uint16 mm) by frame name")
    parser.add_argument("--poses", help="ground-truth poses (default: poses/NN.txt as the reader finds it)")
    parser.add_argument("--height", type=float, default=1.65, help="camera height above the road (m)")
    parser.add_argument("--rows", default="300:361:5", help="road rows START:END:STEP")
    parser.add_argument("--lane-px", type=float, default=60, help="half lane width at the bottom row (px)")
    parser.add_argument("--every", type=int, default=1, help="use every Nth frame for the road")
    parser.add_argument("--gap", type=int, default=3, help="frames between the triangulated views")
    parser.add_argument("--pair-every", type=int, default=5, help="triangulate every Nth frame")
    parser.add_argument("--min-parallax", type=float, default=2.0, help="degrees")
    parser.add_argument("--json", help="write every figure here")
    args = parser.parse_args()

    image_paths = sorted(glob.glob(os.path.join(args.sequence, "image_2", "*.*")))
    if not image_paths:
        fail(f"{args.sequence}: no image_2/ frames")
    p2 = read_calib(os.path.join(args.sequence, "calib.txt"), "P2")
    k = p2[:, :3]
    cam2_from_cam0 = np.eye(4)
    cam2_from_cam0[:3, 3] = np.linalg.solve(k, p2[:, 3])
    cam0_from_cam2 = np.linalg.inv(cam2_from_cam0)
    images, depths = [], []
    for path in image_paths:
        name = os.path.splitext(os.path.basename(path))[0]
        # `infer` writes float32 metres (.tiff) or, with --depth-format png, uint16 millimetres.
        dpath = next((os.path.join(args.depth, name + ext) for ext in (".tiff", ".png")
                      if os.path.isfile(os.path.join(args.depth, name + ext))), None)
        if dpath is None:
            fail(f"{os.path.join(args.depth, name)}.tiff: missing depth for frame {name}")
        images.append(cv2.imread(path, cv2.IMREAD_COLOR))
        d = cv2.imread(dpath, cv2.IMREAD_UNCHANGED)
        if d is not None and d.dtype == np.float32:
            d = np.where(np.isfinite(d) & (d > 0), d, 0.0).astype(np.float64)
        elif d is not None and d.dtype == np.uint16:
            d = d.astype(np.float64) / 1000.0
        else:
            fail(f"{dpath}: neither a float32 TIFF (m) nor a uint16 PNG (mm)")
        depths.append(d)

    report = {"frames": len(images), "height_m": args.height}
    start, end, step = (int(x) for x in args.rows.split(":"))
    rows = list(range(start, end, step))
    per_row, per_frame = road_rows(images[:: args.every], depths[:: args.every], k, args.height,
                                   rows, args.lane_px)
    print(f"Road: flat-road depth at {args.height} m / network depth, lane +-{args.lane_px:.0f} px at "
          f"row {max(rows)}, every {args.every} frame(s)")
    print("  row  flat depth m   p10    median  p90")
    report["road_rows"] = []
    for r in rows:
        if not per_row[r]:
            continue
        flat = k[1, 1] * args.height / (r - k[1, 2])
        p = percentiles(per_row[r])
        print(f"  {r:3d}  {flat:9.2f}   {p[0]:.3f}  {p[1]:.3f}  {p[2]:.3f}")
        report["road_rows"].append({"row": r, "flat_depth_m": flat, "ratio_p10_p50_p90": p})
    p = percentiles(per_frame)
    print(f"  per frame median ratio: p10 {p[0]:.3f}  median {p[1]:.3f}  p90 {p[2]:.3f} "
          f"({len(per_frame)} frames)")
    report["road_per_frame_ratio_p10_p50_p90"] = p

    poses_file = args.poses or find_poses(args.sequence)
    if poses_file is None:
        print("No ground-truth poses: no map comparison")
    else:
        poses = read_poses(poses_file)
        if len(poses) != len(images):
            fail(f"{poses_file}: {len(poses)} poses for {len(images)} images")
        pairs = triangulate_pairs(images, depths, poses, cam0_from_cam2, k, args.gap,
                                  args.min_parallax, args.pair_every)
        if not pairs:
            fail("no triangulated point passed the checks")
        zt = np.array([p[0] for p in pairs])
        zn = np.array([p[1] for p in pairs])
        frame = np.array([p[2] for p in pairs])
        log_ratio = np.log(zt / zn)
        # Each frame's own median scale removed (SLAM's per-frame scale correction).
        corrected = log_ratio.copy()
        frame_scales = []
        for f in np.unique(frame):
            sel = frame == f
            if sel.sum() >= 10:
                s = np.median(log_ratio[sel])
                frame_scales.append(float(np.exp(s)))
                corrected[sel] -= s
            else:
                corrected[sel] = np.nan
        print(f"Map: {len(pairs)} ORB points triangulated with the ground-truth poses "
              f"(frames k, k+{args.gap}; parallax > {args.min_parallax} deg; every "
              f"{args.pair_every}th frame)")
        print("  depth band m   points  geometry/network p10  median  p90   "
              "sigma log   after per-frame scale: sigma   error (bias included)")
        report["map_bands"] = []
        bands = [(1, 5), (5, 10), (10, 20), (20, 40), (40, 80)]
        for lo, hi in bands:
            sel = (zt >= lo) & (zt < hi)
            if sel.sum() < 20:
                continue
            ratio = np.exp(log_ratio[sel])
            p = percentiles(ratio)
            c = corrected[sel]
            c = c[np.isfinite(c)]
            s1 = robust_sigma(log_ratio[sel])
            s2 = robust_sigma(c) if c.size >= 20 else float("nan")
            # The error about the frame's scale, the band's own bias included (what a per-point
            # sigma has to cover after SLAM's per-frame scale correction).
            e2 = 1.4826 * float(np.median(np.abs(c))) if c.size >= 20 else float("nan")
            print(f"  {lo:3d}-{hi:<3d}      {sel.sum():6d}   {p[0]:.3f}   {p[1]:.3f}  {p[2]:.3f}"
                  f"    {s1:.3f}       {s2:.3f}                 {e2:.3f}")
            report["map_bands"].append({"band_m": [lo, hi], "points": int(sel.sum()),
                                        "ratio_p10_p50_p90": p, "sigma_log": s1,
                                        "sigma_log_after_frame_scale": s2,
                                        "error_log_after_frame_scale": e2,
                                        "mid_depth_m": float(np.median(zt[sel]))})
        fs = percentiles(frame_scales)
        print(f"  per-frame scale (geometry/network median): p10 {fs[0]:.3f}  median {fs[1]:.3f}  "
              f"p90 {fs[2]:.3f} ({len(frame_scales)} frames)")
        report["map_frame_scale_p10_p50_p90"] = fs
        # sigma_z / z = relative + per_metre * z, fitted to the bands' error after the per-frame
        # scale, bias included (least squares over the bands, weighted by their point counts).
        b = [x for x in report["map_bands"] if np.isfinite(x["error_log_after_frame_scale"])]
        if len(b) >= 2:
            a = np.array([[1.0, x["mid_depth_m"]] for x in b])
            y = np.array([x["error_log_after_frame_scale"] for x in b])
            w = np.sqrt(np.array([x["points"] for x in b], dtype=float))
            coef, *_ = np.linalg.lstsq(a * w[:, None], y * w, rcond=None)
            print(f"  error model fit: sigma_z / z = {coef[0]:.3f} + {coef[1]:.4f} * z")
            report["error_model_fit"] = {"relative": float(coef[0]), "per_metre": float(coef[1])}
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)


if __name__ == "__main__":
    main()
