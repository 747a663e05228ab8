import os

import cv2
import numpy as np
import pytest

from depthnet import data as D

SHARED = os.environ.get("ADEMONO_SHARED_DIR",
                        os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "shared"))
SEVEN = os.path.join(SHARED, "data", "7scenes-seq-a")


def write_7scenes(root, n=3, w=32, h=24, with_intrinsics=True):
    os.makedirs(root, exist_ok=True)
    rng = np.random.default_rng(0)
    for i in range(n):
        cv2.imwrite(os.path.join(root, f"frame-{i:06d}.color.png"),
                    rng.integers(0, 255, (h, w, 3), dtype=np.uint8))
        depth = np.full((h, w), 1000 + 100 * i, np.uint16)
        depth[0, 0] = 0
        depth[0, 1] = 65535
        cv2.imwrite(os.path.join(root, f"frame-{i:06d}.depth.png"), depth)
    if with_intrinsics:
        np.savetxt(os.path.join(root, "camera-intrinsics.txt"),
                   np.array([[30.0, 0, 16], [0, 31.0, 12], [0, 0, 1]]))


def test_7scenes_loader(tmp_path):
    root = str(tmp_path / "seq")
    write_7scenes(root, n=4)
    recs = D.list_frames("7scenes:" + root, D.parse_frame_range("1:3"))
    assert [os.path.basename(r.rgb_path) for r in recs] == ["frame-000001.color.png",
                                                            "frame-000002.color.png"]
    rgb, depth, intr = D.load_frame(recs[0])
    assert rgb.shape == (24, 32, 3) and rgb.dtype == np.uint8
    assert depth.dtype == np.float32 and depth[0, 0] == 0 and depth[0, 1] == 0  # 0, 65535 invalid
    assert depth[5, 5] == pytest.approx(1.1)
    assert intr == (30.0, 31.0, 16.0, 12.0)


def test_7scenes_errors(tmp_path):
    root = str(tmp_path / "seq")
    write_7scenes(root, n=2)
    with pytest.raises(D.DataError, match="exceeds the 2 frames"):
        D.list_frames("7scenes:" + root, (0, 5))
    os.remove(os.path.join(root, "frame-000001.depth.png"))
    with pytest.raises(D.DataError, match="frame-000001.depth.png: missing depth"):
        D.list_frames("7scenes:" + root)
    with pytest.raises(D.DataError, match="no frame-XXXXXX"):
        D.list_frames("7scenes:" + str(tmp_path))
    with open(os.path.join(root, "camera-intrinsics.txt"), "w") as f:
        f.write("1 2\n3 4\n")
    with pytest.raises(D.DataError, match="camera-intrinsics.txt: expected a 3x3"):
        D.list_7scenes(root)
    with pytest.raises(D.DataError, match="unknown kind"):
        D.list_frames("kitti:" + root)
    for bad in ("5", "3:1", "a:b"):
        with pytest.raises(D.DataError, match="frame range"):
            D.parse_frame_range(bad)


def test_unreadable_images_are_named(tmp_path):
    root = str(tmp_path / "seq")
    write_7scenes(root, n=1)
    with open(os.path.join(root, "frame-000000.depth.png"), "wb") as f:
        f.write(b"not a png")
    rec = D.list_frames("7scenes:" + root)[0]
    with pytest.raises(D.DataError, match="frame-000000.depth.png: cannot read depth"):
        D.load_frame(rec)


def test_tum_loader(tmp_path):
    root = tmp_path / "tum"
    (root / "rgb").mkdir(parents=True)
    (root / "depth").mkdir()
    rgb_lines, depth_lines = ["# colour"], ["# depth"]
    for i in range(3):
        t = 100.0 + i * 0.1
        cv2.imwrite(str(root / "rgb" / f"{t:.6f}.png"), np.zeros((8, 8, 3), np.uint8))
        cv2.imwrite(str(root / "depth" / f"{t:.6f}.png"), np.full((8, 8), 5000 * (i + 1), np.uint16))
        rgb_lines.append(f"{t:.6f} rgb/{t:.6f}.png")
        depth_lines.append(f"{t + 0.01:.6f} depth/{t:.6f}.png")
    rgb_lines.append("200.0 rgb/none.png")  # no depth within 0.02 s: dropped
    (root / "rgb.txt").write_text("\n".join(rgb_lines) + "\n")
    (root / "depth.txt").write_text("\n".join(depth_lines) + "\n")
    recs = D.list_frames(f"tum:{root}")
    assert len(recs) == 3
    _, depth, intr = D.load_frame(recs[2])
    assert depth[3, 3] == pytest.approx(3.0)
    assert intr == (525.0, 525.0, 319.5, 239.5)
    (root / "camera.yaml").write_text("camera:\n  fx: 500\n  fy: 501\n  cx: 3.5\n  cy: 4.5\n")
    assert D.list_frames(f"tum:{root}", (1, 2))[0].intrinsics == (500.0, 501.0, 3.5, 4.5)
    (root / "depth.txt").write_text("abc depth/x.png\n")
    with pytest.raises(D.DataError, match="depth.txt:1: bad timestamp"):
        D.list_frames(f"tum:{root}")


def marker_sample(w=64, h=48, u=40, v=10):
    """A depth map with one valid pixel at (u, v) holding the depth 2 m."""
    depth = np.zeros((h, w), np.float32)
    depth[v, u] = 2.0
    rgb = np.zeros((h, w, 3), np.uint8)
    return rgb, depth, (50.0, 55.0, 31.5, 23.5)


def where(depth):
    v, u = np.argwhere(depth > 0)[0]
    return u, v


def pixel_of_ray(intr, x, y):
    fx, fy, cx, cy = intr
    return fx * x + cx, fy * y + cy


def test_crop_and_flip_keep_rays_consistent():
    rgb, depth, intr = marker_sample()
    fx, fy, cx, cy = intr
    u, v = where(depth)
    ray = ((u - cx) / fx, (v - cy) / fy)
    _, d2, intr2 = D.crop_sample(rgb, depth, intr, 10, 5, 40, 30)
    assert intr2 == (fx, fy, cx - 10, cy - 5)
    assert where(d2) == pytest.approx(pixel_of_ray(intr2, *ray))
    _, d3, intr3 = D.flip_sample(rgb, d2, intr2)
    assert intr3[2] == pytest.approx(40 - 1 - intr2[2])
    # The flipped marker sits on the mirrored ray (x -> -x).
    assert where(d3) == pytest.approx(pixel_of_ray(intr3, -ray[0], ray[1]))


def test_resize_scales_focal_and_principal_point():
    rgb, depth, intr = marker_sample(w=64, h=48, u=41, v=11)
    r2, d2, intr2 = D.resize_sample(rgb, depth, intr, 32, 24)
    assert r2.shape == (24, 32, 3) and d2.shape == (24, 32)
    assert intr2 == pytest.approx((25.0, 27.5, 15.5, 11.5))
    # Pixel (41, 11) covers [40.5, 41.5] -> its centre maps to (41 + 0.5) / 2 - 0.5 = 20.25.
    fx, fy, cx, cy = intr
    ray = ((41 - cx) / fx, (11 - cy) / fy)
    assert pixel_of_ray(intr2, *ray) == pytest.approx((20.25, 5.25))


def test_augment_is_deterministic_and_sized():
    rgb, depth, intr = marker_sample()
    rgb = np.random.default_rng(3).integers(0, 255, rgb.shape, dtype=np.uint8)
    a = D.augment(rgb, depth, intr, np.random.default_rng(7), D.AugmentOptions(), 32, 24)
    b = D.augment(rgb, depth, intr, np.random.default_rng(7), D.AugmentOptions(), 32, 24)
    assert a[0].shape == (24, 32, 3) and a[1].shape == (24, 32)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and a[2] == b[2]
    # Nearest resampling never invents depth values.
    assert set(np.unique(a[1])) <= {0.0, 2.0}


@pytest.mark.skipif(not os.path.isdir(SEVEN), reason="shared 7-Scenes data not present")
def test_real_7scenes_frame():
    recs = D.list_frames("7scenes:" + SEVEN, (0, 2))
    rgb, depth, intr = D.load_frame(recs[0])
    assert rgb.shape == (480, 640, 3) and depth.shape == (480, 640)
    assert intr == (585.0, 585.0, 320.0, 240.0)
    valid = depth[depth > 0]
    assert 0.7 < valid.size / depth.size < 0.99  # 5-20 % of pixels have no depth
    assert 0.5 < np.median(valid) < 4.0
