#!/usr/bin/python3
"""Writes the fuzz seed corpora into OUT/<target>/: small valid inputs in the formats of the test
fixtures (tests/io, tests/detect, tests/depth) plus the repo's own configs and model specs.
Multi-file targets (sequence_*) take their files joined by NUL bytes, in the order their
fuzz/<name>_fuzz.cpp lists. Usage: fuzz/make_seeds.py OUT"""
import glob
import os
import sys

import cv2
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
out = sys.argv[1]


def seed(target, name, data):
    d = os.path.join(out, target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def parts(*files):
    return b"\0".join(f.encode() if isinstance(f, str) else f for f in files)


tum = "# timestamp tx ty tz qx qy qz qw\n1.0 1 2 3 0 0 0 1\n1.1 1 2 3.1 0 0 0.0499792 0.99875\n"
kitti = "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.5 0 1 0 0 0 0 1 0.1\n"
euroc = ("#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z\n"
         "1403636579763555584,0,0,0,0.7071067811865476,0,0,0.7071067811865476\n"
         "1403636579813555584,0,0.05,0,0.7071067811865476,0,0,0.7071067811865476,0,0,0\n")
seed("trajectory_tum", "two_poses.txt", tum)
seed("trajectory_kitti", "two_poses.txt", kitti)
seed("trajectory_euroc", "two_poses.csv", euroc)

rgb = "# color images\n100.0 rgb/0.png\n100.033 rgb/1.png\n"
depth = "# depth maps\n100.001 depth/0.png\n100.034 depth/1.png\n"
camera = "width: 32\nheight: 24\nfx: 30\nfy: 31\ncx: 16\ncy: 12\n"
seed("sequence_tum", "full", parts(rgb, depth, tum.replace("1.0 ", "100.0 ").replace("1.1 ", "100.1 "), camera))
seed("sequence_tum", "rgb_only", parts(rgb))
seed("sequence_tum", "camera_node", parts(rgb, "", "", "camera:\n  " + camera.replace("\n", "\n  ")))

calib = "P0: 700 0 32 0 0 701 24 0 0 0 1 0\nP1: 700 0 32 -386 0 701 24 0 0 0 1 0\n"
seed("sequence_kitti", "full", parts(calib, "0.0\n0.1036\n", kitti))
seed("sequence_kitti", "calib_only", parts(calib))

data_csv = "#timestamp [ns],filename\n1403636579763555584,1403636579763555584.png\n" \
           "1403636579813555584,1403636579813555584.png\n"
sensor = ("%YAML:1.0\nsensor_type: camera\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0.1, "
          "0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\nrate_hz: 20\nresolution: [32, 24]\n"
          "camera_model: pinhole\nintrinsics: [458.654, 457.296, 16.0, 12.0]\n"
          "distortion_model: radial-tangential\n"
          "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n")
seed("sequence_euroc", "full", parts(data_csv, sensor, euroc))

pose = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
seed("sequence_7scenes", "full", parts(pose, pose.replace("1 0 0 0\n", "1 0 0 0.1\n", 1),
                                       "40 0 16\n0 41 12\n0 0 1\n"))

seed("camera_yaml", "plain.yaml", camera)
seed("camera_yaml", "node.yaml", "camera:\n  width: 640\n  height: 480\n  fx: 525\n  fy: 525\n"
     "  cx: 319.5\n  cy: 239.5\n  distortion: [0.1, -0.2, 0.001, 0.002, 0.05]\n")

for path in sorted(glob.glob(os.path.join(root, "configs", "*.yaml"))):
    seed("system_options_yaml", os.path.basename(path), open(path, "rb").read())
for path in sorted(glob.glob(os.path.join(root, "configs", "models", "*.yaml")) +
                   glob.glob(os.path.join(root, "tests", "data", "models", "*.yaml"))):
    seed("model_spec_yaml", os.path.basename(path), open(path, "rb").read())

seed("detections_jsonl", "two_frames.jsonl",
     '{"frame":0,"timestamp":0.0,"name":"0.000000","detections":[{"class_id":0,"class":"person",'
     '"score":1.0,"box_xywh":[253.0,32.0,67.0,151.0]}]}\n'
     '{"frame":1,"timestamp":0.033333,"name":"0.033333","detections":[]}\n')

# depth_image: first byte picks the extension (even: .png, odd: .tiff).
rng = np.random.default_rng(0)
mm = rng.integers(0, 8000, size=(6, 8), dtype=np.uint16)
mm[0, 0], mm[0, 1] = 0, 65535
ok, png = cv2.imencode(".png", mm)
seed("depth_image", "mm16.png", b"\0" + png.tobytes())
metres = rng.uniform(0.2, 9.0, size=(6, 8)).astype(np.float32)
metres[0, 0] = np.nan
ok, tiff = cv2.imencode(".tiff", metres)
seed("depth_image", "metres32.tiff", b"\1" + tiff.tobytes())

# Map files (map_file): a two-keyframe map in the layout of slam/map_io.h (cereal portable binary:
# a byte 1 for little-endian, then the fields; lengths as uint64), in format 2 as a whole file and
# as a bare payload (the target wraps inputs without the magic in a format-2 header), and in
# format 1 (no static probability or admission per point) as a whole file.
import struct
import zlib


def map_payload(version):
    b = bytearray(b"\x01")
    b += struct.pack("<ii4d5d", 640, 480, 585.0, 585.0, 320.0, 240.0, 0, 0, 0, 0, 0)
    options = b"orb:\n  num_features: 1000\n"
    b += struct.pack("<Q", len(options)) + options
    b += struct.pack("<QQ", 2, 1)  # next keyframe id, next point id
    b += struct.pack("<Q", 2)
    for k in range(2):
        b += struct.pack("<QQQd", k, k, k, k / 30.0)
        b += struct.pack("<12d", 1, 0, 0, 0.05 * k, 0, 1, 0, 0, 0, 0, 1, 0)
        b += struct.pack("<Q", 3)
        for i in range(3):
            b += struct.pack("<5fi", 100.0 + 50 * i, 120.0 + 10 * k, 31.0, 45.0, 0.001, 0)
        b += struct.pack("<Q", 96) + bytes((i * 7 + k) % 256 for i in range(96))
        b += struct.pack("<Q", 3) + struct.pack("<3f", 1.5, 2.0, -1.0)
        b += struct.pack("<dfdd?fq", 0.08 * 585, 3.2, 0.0, 0.0, True, 1.0, k - 1)
        b += struct.pack("<Q", 1) + struct.pack("<Qi", 1 - k, 15)
    b += struct.pack("<Q", 1)
    b += struct.pack("<Q3d3d", 0, 0.1, 0.2, 1.5, 0, 0, 1) + bytes(range(32))
    b += struct.pack("<ffQQQiii", 0.5, 3.0, 0, 0, 0, 2, 2, 0)
    b += struct.pack("<Q", 2) + struct.pack("<QI", 0, 0) + struct.pack("<QI", 1, 0)
    if version >= 2:
        b += struct.pack("<dB", 0.45, 0)  # static probability, not admitted
    return bytes(b)


for version, name in ((2, "two_keyframes.map"), (1, "two_keyframes_v1.map")):
    payload = map_payload(version)
    seed("map_file", name,
         b"ADEMAP\r\n" + struct.pack("<IQI", version, len(payload), zlib.crc32(payload)) + payload)
seed("map_file", "two_keyframes.payload", map_payload(2))
