"""Tests of the Python module `ademono` (run by CTest as pytest_python, with PYTHONPATH set to
build/<name>/python and ADEMONO_CLI to the command-line program). The tests on ../shared data
skip only when ../shared is missing."""
import json
import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

import ademono

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("ADEMONO_SHARED_DIR", REPO.parent / "shared"))
CLI = os.environ.get("ADEMONO_CLI", str(REPO / "build" / "release" / "bin" / "ademono"))
SEQ_A = SHARED / "data" / "7scenes-seq-a"
TRAJ = SHARED / "data" / "trajectories"
MODELS = REPO / "tests" / "data" / "models"

needs_shared = pytest.mark.skipif(not SHARED.exists(), reason="../shared is missing")


def run_cli(*args):
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return proc


@needs_shared
def test_sequence_frames_are_the_files():
    seq = ademono.open_sequence(f"7scenes:{SEQ_A}")
    assert len(seq) == 600
    assert seq.kind == "7scenes" and seq.has_depth and seq.has_ground_truth
    assert (seq.camera.width, seq.camera.height, seq.camera.fx) == (640, 480, 585.0)
    frame = seq[5]
    assert frame.index == 5
    assert frame.timestamp == pytest.approx(5 / 30)
    assert frame.image.dtype == np.uint8 and frame.image.shape == (480, 640, 3)
    np.testing.assert_array_equal(frame.image, cv2.imread(str(SEQ_A / "frame-000005.color.jpg")))
    raw = cv2.imread(str(SEQ_A / "frame-000005.depth.png"), cv2.IMREAD_UNCHANGED)
    assert frame.depth.dtype == np.float32 and frame.depth.shape == (480, 640)
    valid = (raw > 0) & (raw < 65535)
    np.testing.assert_allclose(frame.depth[valid], raw[valid] / 1000.0, rtol=1e-6)
    assert np.all(frame.depth[~valid] == 0)
    # The reader re-orthonormalises the rotation (the file's has 1e-4 of scale error).
    pose = np.loadtxt(SEQ_A / "frame-000005.pose.txt")
    np.testing.assert_allclose(frame.gt_pose[:3, 3], pose[:3, 3], atol=1e-12)
    np.testing.assert_allclose(frame.gt_pose[:3, :3], pose[:3, :3], atol=1e-4)
    assert seq[-1].index == 599
    with pytest.raises(IndexError):
        seq[600]
    # Iterable (stops at the end).
    assert sum(1 for _ in zip(range(3), seq)) == 3


@needs_shared
def test_tracking_through_python_is_byte_identical_to_the_cli(tmp_path):
    # The CLI: default config for 7-Scenes (configs/7scenes.yaml), sensor depth, no detector.
    run_cli("run", "--dataset", f"7scenes:{SEQ_A}", "--frames", "0:100", "--out", tmp_path / "cli")
    seq = ademono.open_sequence(f"7scenes:{SEQ_A}")
    system = ademono.System(str(REPO / "configs" / "7scenes.yaml"), seq.camera)
    states = []
    for i in range(100):
        frame = seq[i]
        r = system.track(frame.image, depth=frame.depth, timestamp=frame.timestamp)
        states.append(r.state)
        # Sensor depth: metric already, nothing corrected and no scale to be unsure of.
        assert r.depth_scale == 1.0 and r.scale_sigma is None
        if r.tracked:
            assert r.cam_from_world.shape == (4, 4)
            np.testing.assert_allclose(r.cam_from_world[3], [0, 0, 0, 1])
        else:
            assert r.cam_from_world is None
    system.shutdown()
    system.write_trajectory(tmp_path / "py.tum")
    cli = (tmp_path / "cli" / "trajectory.tum").read_bytes()
    assert (tmp_path / "py.tum").read_bytes() == cli
    assert states.count("ok") >= 95
    times, poses = system.trajectory()
    assert poses.shape == (len(times), 4, 4) and len(times) == states.count("ok")
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert system.num_keyframes == summary["keyframes"]
    assert system.num_map_points == summary["map_points"]
    kf_times, kf_poses = system.keyframes()
    assert len(kf_times) == summary["keyframes"] and kf_poses.shape[1:] == (4, 4)
    xyz, rgb = system.map_points()
    assert xyz.shape == (summary["map_points"], 3) and rgb.dtype == np.uint8


@needs_shared
def test_eval_agrees_with_the_cli(tmp_path):
    gt = TRAJ / "evo" / "freiburg1_xyz-groundtruth.txt"
    est = TRAJ / "evo" / "freiburg1_xyz-rgbdslam.txt"
    expected = json.loads((TRAJ / "expected.json").read_text())
    for align in ("none", "se3", "sim3", "origin"):
        run_cli("eval", "--gt", gt, "--est", est, "--align", align, "--json", tmp_path / "m.json")
        cli = json.loads((tmp_path / "m.json").read_text())
        py = ademono.evaluate(str(gt), str(est), align=align)
        for key in ("ape", "rpe_trans", "rpe_rot_deg"):
            assert py[key] == cli[key], (align, key)
        assert py["ape"]["rmse"] == pytest.approx(
            expected["evo"]["fr1_xyz_rgbdslam"][f"ape_{align}"]["rmse"], rel=1e-6)
        assert ademono.ate(str(gt), str(est), align=align) == cli["ape"]["rmse"]
    # On arrays: the same numbers.
    gt_t, gt_p, gt_format = ademono.read_trajectory(str(gt))
    est_t, est_p, _ = ademono.read_trajectory(str(est))
    assert gt_format == "tum" and gt_p.shape == (len(gt_t), 4, 4)
    py = ademono.evaluate((gt_t, gt_p), (est_t, est_p))
    assert py["ape"] == ademono.evaluate(str(gt), str(est))["ape"]
    rpe = ademono.rpe((gt_t, gt_p), (est_t, est_p), delta=1)
    assert rpe["trans"]["mean"] == pytest.approx(
        expected["evo"]["fr1_xyz_rgbdslam"]["rpe_trans_1frame"]["mean"], rel=1e-6)
    # kitti-odom-eval's metrics on (N, 4, 4) arrays matched by index, every alignment.
    for align, seqs in expected["kitti_odom_eval"]["example_1"].items():
        want = seqs["10"]
        _, g, _ = ademono.read_trajectory(str(TRAJ / "kitti-odom-eval" / "gt" / "10.txt"))
        _, e, fmt = ademono.read_trajectory(str(TRAJ / "kitti-odom-eval" / "example_1" / "10.txt"))
        assert fmt == "kitti"
        k = ademono.kitti_metrics(g, e, align=align)
        for key in ("t_rel_percent", "r_rel_deg_per_100m", "ate_m", "rpe_m", "rpe_deg"):
            assert abs(k[key] - want[key]) <= 5e-4 + 1e-9, (align, key)


def test_bad_inputs_raise(tmp_path):
    with pytest.raises(ademono.InputError, match="no such"):
        ademono.open_sequence(f"7scenes:{tmp_path / 'missing'}")
    bad = tmp_path / "est.txt"
    bad.write_text("1 0 0 0 0 0 0 1\n2 0 0 zero 0 0 0 1\n")
    with pytest.raises(ademono.InputError) as error:
        ademono.read_trajectory(str(bad))
    assert str(error.value) == f"{bad}:2: field 4 'zero' is not a finite number"
    assert issubclass(ademono.InputError, ValueError)
    with pytest.raises(ademono.InputError, match="missing.yaml: no such file"):
        ademono.System(str(tmp_path / "missing.yaml"), ademono.Camera(64, 48, 50, 50, 32, 24))
    camera = ademono.Camera(64, 48, 50, 50, 32, 24)
    # A dict config goes through the same strict reader as a file.
    with pytest.raises(ademono.InputError, match=r"<config dict>: unknown key 'tracking.nope'"):
        ademono.System({"tracking": {"nope": 2}}, camera)
    system = ademono.System({"orb": {"num_features": 500}}, camera)
    with pytest.raises(ademono.InputError, match="image size 32x48 differs"):
        system.track(np.zeros((48, 32, 3), np.uint8))
    with pytest.raises(ValueError, match="uint8"):
        system.track(np.zeros((48, 64, 3), np.float32))
    with pytest.raises(ValueError, match="depth"):
        system.track(np.zeros((48, 64, 3), np.uint8), depth=np.zeros((48, 64, 2), np.float32))
    with pytest.raises(ValueError):
        ademono.Camera(0, 48, 50, 50, 32, 24)
    with pytest.raises(ValueError, match=r"\(N, 4, 4\)"):
        ademono.ate(np.zeros((5, 3, 4)), np.zeros((5, 4, 4)))
    with pytest.raises(ademono.InputError, match="missing.onnx: no such file"):
        ademono.DepthModel(str(tmp_path / "missing.onnx"))
    with pytest.raises(ValueError, match="unknown alignment"):
        ademono.evaluate(np.tile(np.eye(4), (5, 1, 1)), np.tile(np.eye(4), (5, 1, 1)), align="x")


def test_depth_model_on_the_test_network():
    # depth_metric.onnx computes grey / 25.5 m on a 64x48 input (tests/data/models).
    model = ademono.DepthModel(str(MODELS / "depth_metric.onnx"),
                               str(MODELS / "depth_metric.yaml"))
    image = np.full((48, 64, 3), 51, np.uint8)
    depth = model.predict(image)
    assert depth.dtype == np.float32 and depth.shape == (48, 64)
    np.testing.assert_allclose(depth, 2.0, rtol=1e-5)


@needs_shared
def test_detector_finds_the_reference_boxes():
    expected = json.loads((SHARED / "images" / "expected_detections.json").read_text())
    detector = ademono.Detector(str(SHARED / "models" / "yolox_nano.onnx"), arch="yolox",
                                classes="all")
    boxes = detector.detect(cv2.imread(str(SHARED / "images" / "bus.jpg")))
    want = expected["images"]["bus.jpg"]["detections"]
    assert len(boxes) == len(want)
    for got, ref in zip(boxes, want):
        assert got.class_id == ref["class_id"]
        assert got.score == pytest.approx(ref["score"], abs=0.01)
        np.testing.assert_allclose(got.box, ref["box_xywh"], atol=1.5)


def test_synth_renders_a_sequence_that_opens(tmp_path):
    summary = ademono.synth(str(tmp_path / "office"), frames=4, seed=3, width=160, height=120)
    assert summary["frames"] == 4
    seq = ademono.open_sequence(f"tum:{tmp_path / 'office'}")
    assert len(seq) == 4 and seq.has_ground_truth
    frame = seq[0]
    assert frame.image.shape == (120, 160, 3) and frame.depth.shape == (120, 160)
    assert frame.image.std() > 5 and (frame.depth > 0).mean() > 0.9
    with pytest.raises(ademono.InputError):
        ademono.synth(str(tmp_path / "office"), frames=4)  # not empty


def test_tracking_with_detections_is_byte_identical_to_the_cli(tmp_path):
    # A synthetic office with walking persons; its ground-truth boxes as the detector, fed to
    # System.track the way `ademono run --detector cache:...` feeds them (matched by frame name).
    seq_dir = tmp_path / "office"
    ademono.synth(str(seq_dir), frames=30, seed=7, persons=2, width=320, height=240)
    config = REPO / "configs" / "tum_fr1.yaml"
    run_cli("run", "--dataset", f"tum:{seq_dir}", "--config", config, "--detector",
            f"cache:{seq_dir / 'detections.jsonl'}", "--out", tmp_path / "cli")
    boxes = {f["name"]: f["detections"] for f in ademono.read_detections(seq_dir / "detections.jsonl")}
    assert sum(len(b) for b in boxes.values()) > 0
    seq = ademono.open_sequence(f"tum:{seq_dir}")
    system = ademono.System(str(config), seq.camera)
    for frame in seq:
        system.track(frame.image, depth=frame.depth, timestamp=frame.timestamp,
                     detections=boxes[frame.name])
    system.shutdown()
    system.write_trajectory(tmp_path / "py.tum")
    assert (tmp_path / "py.tum").read_bytes() == (tmp_path / "cli" / "trajectory.tum").read_bytes()
    # Without the boxes the walking persons change the result.
    plain = ademono.System(str(config), seq.camera)
    for frame in seq:
        plain.track(frame.image, depth=frame.depth, timestamp=frame.timestamp)
    plain.shutdown()
    plain.write_trajectory(tmp_path / "plain.tum")
    assert (tmp_path / "plain.tum").read_bytes() != (tmp_path / "py.tum").read_bytes()


@needs_shared
def test_example_script_writes_a_plot(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run(
        [sys.executable, str(REPO / "examples" / "run_sequence.py"), "--dataset",
         f"7scenes:{SEQ_A}", "--config", str(REPO / "configs" / "7scenes.yaml"),
         "--frames", "0:12", "--out", str(tmp_path / "plot.png")],
        capture_output=True, text=True, env=env)
    assert proc.returncode == 0, proc.stderr
    assert "ATE se3" in proc.stdout
    image = cv2.imread(str(tmp_path / "plot.png"))
    assert image is not None and image.shape[0] > 300 and image.shape[1] > 600
    # Something was drawn: not a blank canvas.
    assert (image < 200).mean() > 0.01


@needs_shared
def test_save_map_then_localize_only_leaves_the_file(tmp_path):
    seq = ademono.open_sequence(f"7scenes:{SEQ_A}")
    config = str(REPO / "configs" / "7scenes.yaml")
    first = ademono.System(config, seq.camera)
    for i in range(40):
        first.track(seq[i].image, depth=seq[i].depth, timestamp=seq[i].timestamp)
    first.save_map(tmp_path / "a.map")
    saved = (tmp_path / "a.map").read_bytes()
    second = ademono.System(config, seq.camera)
    second.load_map(tmp_path / "a.map", localize_only=True)
    assert second.loaded_map_has_metric_scale()  # built with sensor depth
    states = [second.track(seq[i].image, depth=seq[i].depth, timestamp=seq[i].timestamp).state
              for i in range(40, 50)]
    assert states == ["ok"] * 10
    # 7scenes.yaml localises with a temporary local map: its keyframes count, but are never saved.
    assert second.num_keyframes >= first.num_keyframes
    second.save_map(tmp_path / "b.map")
    assert (tmp_path / "b.map").read_bytes() == saved
    (tmp_path / "bad.map").write_bytes(saved[:100])
    with pytest.raises(ademono.InputError, match="truncated"):
        ademono.System(config, seq.camera).load_map(tmp_path / "bad.map")


def _websocket_first_text(url):
    """The first text frame a Foxglove server sends (serverInfo), read over a plain socket: the
    upgrade request with the subprotocol, then one unmasked server frame (test-only reading)."""
    import base64
    import socket
    from urllib.parse import urlparse
    u = urlparse(url)
    with socket.create_connection((u.hostname, u.port), timeout=10) as s:
        key = base64.b64encode(os.urandom(16)).decode()
        s.sendall(("GET / HTTP/1.1\r\nHost: %s:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                   "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n"
                   "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n"
                   % (u.hostname, u.port, key)).encode())
        data = b""
        while b"\r\n\r\n" not in data:
            data += s.recv(4096)
        head, rest = data.split(b"\r\n\r\n", 1)
        assert head.startswith(b"HTTP/1.1 101"), head
        assert b"foxglove.websocket.v1" in head
        while len(rest) < 4:
            rest += s.recv(4096)
        assert rest[0] == 0x81  # FIN + text
        length, start = rest[1] & 0x7F, 2
        if length == 126:
            length, start = int.from_bytes(rest[2:4], "big"), 4
        while len(rest) < start + length:
            rest += s.recv(65536)
        return json.loads(rest[start:start + length])


@needs_shared
def test_system_serves_the_live_view(tmp_path):
    import urllib.request
    seq = ademono.open_sequence(f"7scenes:{SEQ_A}")
    system = ademono.System(str(REPO / "configs" / "7scenes.yaml"), seq.camera, live="127.0.0.1:0")
    url = system.live_url
    assert url.startswith("http://127.0.0.1:")
    page = urllib.request.urlopen(url, timeout=10).read().decode()
    assert "ademono live" in page and "foxglove.websocket.v1" in page
    assert _websocket_first_text(url) == {"op": "serverInfo", "name": "ademono", "capabilities": [],
                                          "supportedEncodings": [], "metadata": {}}
    for i in range(20):
        frame = seq[i]
        system.track(frame.image, depth=frame.depth, timestamp=frame.timestamp)
    system.shutdown()
    system.live_linger(0)
    stats = system.live_stats()
    assert stats["url"] == url and stats["clients"] == 1
    with pytest.raises(RuntimeError):
        ademono.System(None, seq.camera).live_url
    with pytest.raises(Exception, match=r"expected \[HOST:\]PORT"):
        ademono.System(None, seq.camera, live="nowhere:port")
