"""RGB-D folder loaders (TUM and 7-Scenes layouts) and training augmentation.

Every sample is (rgb, depth, K):
  rgb   : H x W x 3 uint8, RGB order
  depth : H x W float32 metres, 0 where the sensor has no depth
  K     : (fx, fy, cx, cy) of the colour image at that resolution; pixel (0, 0) is the centre of
          the top-left pixel, so a horizontal flip maps cx to W - 1 - cx.

Layouts
  7scenes:DIR  frame-XXXXXX.color.jpg + frame-XXXXXX.depth.png (uint16 mm, 0 and 65535 invalid),
               optional camera-intrinsics.txt (3x3 K; default fx = fy = 585, cx = 320, cy = 240).
               The depth is raw Kinect depth, not registered to colour: acceptable here.
  tum:DIR      rgb.txt / depth.txt (timestamp path), depth PNG uint16 / 5000 = metres; colour and
               depth matched by nearest timestamp within 0.02 s. Intrinsics from DIR/camera.yaml
               (fx, fy, cx, cy keys) if present, else the TUM ROS defaults 525, 525, 319.5, 239.5.
Frame ranges are half-open index ranges "A:B" over the sorted (7-Scenes) or associated (TUM)
frame list.
"""

from __future__ import annotations

import dataclasses
import os
import re
from typing import List, Optional, Sequence, Tuple

import cv2
import numpy as np


class DataError(Exception):
    """Bad input data: the message names the file and the problem."""


Intrinsics = Tuple[float, float, float, float]


@dataclasses.dataclass
class FrameRecord:
    rgb_path: str
    depth_path: str
    depth_scale: float  # metres per depth unit
    invalid_values: Tuple[int, ...]
    intrinsics: Intrinsics


def parse_frame_range(text: Optional[str]) -> Optional[Tuple[int, int]]:
    """'A:B' -> (A, B), half-open; None or '' -> None (all frames)."""
    if not text:
        return None
    m = re.fullmatch(r"\s*(\d+)\s*:\s*(\d+)\s*", text)
    if not m:
        raise DataError(f"frame range '{text}': expected A:B with integers A < B")
    a, b = int(m.group(1)), int(m.group(2))
    if a >= b:
        raise DataError(f"frame range '{text}': start must be below end")
    return a, b


def _select(records: List[FrameRecord], frame_range, where: str) -> List[FrameRecord]:
    if frame_range is None:
        return records
    a, b = frame_range
    if b > len(records):
        raise DataError(f"{where}: frame range {a}:{b} exceeds the {len(records)} frames present")
    return records[a:b]


def list_7scenes(root: str, frame_range=None) -> List[FrameRecord]:
    if not os.path.isdir(root):
        raise DataError(f"{root}: not a directory")
    intr = (585.0, 585.0, 320.0, 240.0)
    intr_path = os.path.join(root, "camera-intrinsics.txt")
    if os.path.exists(intr_path):
        try:
            k = np.loadtxt(intr_path, dtype=np.float64)
        except ValueError as e:
            raise DataError(f"{intr_path}: malformed intrinsics ({e})") from None
        if k.shape != (3, 3):
            raise DataError(f"{intr_path}: expected a 3x3 matrix, got shape {k.shape}")
        intr = (float(k[0, 0]), float(k[1, 1]), float(k[0, 2]), float(k[1, 2]))
    names = sorted(n for n in os.listdir(root) if re.fullmatch(r"frame-\d+\.color\.(jpg|png)", n))
    if not names:
        raise DataError(f"{root}: no frame-XXXXXX.color.jpg files (7-Scenes layout)")
    records = []
    for n in names:
        stem = n.split(".")[0]
        depth = os.path.join(root, stem + ".depth.png")
        if not os.path.exists(depth):
            raise DataError(f"{depth}: missing depth for {n}")
        records.append(FrameRecord(os.path.join(root, n), depth, 1e-3, (0, 65535), intr))
    return _select(records, frame_range, root)


def _read_list(path: str) -> List[Tuple[float, str]]:
    if not os.path.exists(path):
        raise DataError(f"{path}: file not found")
    entries = []
    with open(path) as f:
        for line_no, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split()
            if len(parts) < 2:
                raise DataError(f"{path}:{line_no}: expected 'timestamp filename'")
            try:
                entries.append((float(parts[0]), parts[1]))
            except ValueError:
                raise DataError(f"{path}:{line_no}: bad timestamp '{parts[0]}'") from None
    if not entries:
        raise DataError(f"{path}: no entries")
    return entries


def list_tum(root: str, frame_range=None, max_dt: float = 0.02) -> List[FrameRecord]:
    if not os.path.isdir(root):
        raise DataError(f"{root}: not a directory")
    rgb = _read_list(os.path.join(root, "rgb.txt"))
    depth = _read_list(os.path.join(root, "depth.txt"))
    intr = (525.0, 525.0, 319.5, 239.5)
    cam_path = os.path.join(root, "camera.yaml")
    if os.path.exists(cam_path):
        import yaml  # Debian python3-yaml; only needed for this optional file

        with open(cam_path) as f:
            node = yaml.safe_load(f) or {}
        node = node.get("camera", node)
        try:
            intr = tuple(float(node[k]) for k in ("fx", "fy", "cx", "cy"))
        except (KeyError, TypeError, ValueError):
            raise DataError(f"{cam_path}: needs numeric fx, fy, cx, cy") from None
    depth_t = np.array([t for t, _ in depth])
    records = []
    for t, name in rgb:
        j = int(np.argmin(np.abs(depth_t - t)))
        if abs(depth_t[j] - t) <= max_dt:
            records.append(FrameRecord(os.path.join(root, name), os.path.join(root, depth[j][1]),
                                       1.0 / 5000.0, (0,), intr))
    if not records:
        raise DataError(f"{root}: no colour frame has a depth frame within {max_dt} s")
    return _select(records, frame_range, root)


def list_frames(spec: str, frame_range=None) -> List[FrameRecord]:
    """spec is '7scenes:DIR' or 'tum:DIR'."""
    kind, sep, path = spec.partition(":")
    if not sep:
        raise DataError(f"dataset '{spec}': expected 7scenes:DIR or tum:DIR")
    if kind == "7scenes":
        return list_7scenes(path, frame_range)
    if kind == "tum":
        return list_tum(path, frame_range)
    raise DataError(f"dataset '{spec}': unknown kind '{kind}' (7scenes or tum)")


def load_frame(rec: FrameRecord) -> Tuple[np.ndarray, np.ndarray, Intrinsics]:
    bgr = cv2.imread(rec.rgb_path, cv2.IMREAD_COLOR)
    if bgr is None:
        raise DataError(f"{rec.rgb_path}: cannot read colour image")
    raw = cv2.imread(rec.depth_path, cv2.IMREAD_UNCHANGED)
    if raw is None:
        raise DataError(f"{rec.depth_path}: cannot read depth image")
    if raw.dtype != np.uint16 or raw.ndim != 2:
        raise DataError(f"{rec.depth_path}: expected a 16-bit single-channel PNG")
    valid = np.ones(raw.shape, bool)
    for v in rec.invalid_values:
        valid &= raw != v
    depth = np.where(valid, raw.astype(np.float32) * rec.depth_scale, 0.0).astype(np.float32)
    rgb = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
    if depth.shape != rgb.shape[:2]:
        # Resample depth onto the colour grid (nearest keeps invalid pixels invalid).
        depth = cv2.resize(depth, (rgb.shape[1], rgb.shape[0]), interpolation=cv2.INTER_NEAREST)
    return rgb, depth, rec.intrinsics


def resize_sample(rgb, depth, intr: Intrinsics, width: int, height: int):
    """Resize to width x height; fx, cx scale by width ratio, fy, cy by height ratio.

    With pixel centres at integer coordinates, c' = (c + 0.5) * s - 0.5.
    """
    h0, w0 = depth.shape
    sx, sy = width / w0, height / h0
    fx, fy, cx, cy = intr
    rgb = cv2.resize(rgb, (width, height), interpolation=cv2.INTER_AREA if sx < 1 else cv2.INTER_LINEAR)
    depth = cv2.resize(depth, (width, height), interpolation=cv2.INTER_NEAREST)
    return rgb, depth, (fx * sx, fy * sy, (cx + 0.5) * sx - 0.5, (cy + 0.5) * sy - 0.5)


def crop_sample(rgb, depth, intr: Intrinsics, x0: int, y0: int, w: int, h: int):
    """Crop [x0, x0 + w) x [y0, y0 + h): the principal point shifts, focal lengths stay."""
    fx, fy, cx, cy = intr
    return (rgb[y0:y0 + h, x0:x0 + w].copy(), depth[y0:y0 + h, x0:x0 + w].copy(),
            (fx, fy, cx - x0, cy - y0))


def flip_sample(rgb, depth, intr: Intrinsics):
    fx, fy, cx, cy = intr
    w = depth.shape[1]
    return rgb[:, ::-1].copy(), depth[:, ::-1].copy(), (fx, fy, w - 1 - cx, cy)


def colour_jitter(rgb: np.ndarray, rng: np.random.Generator, brightness=0.2, contrast=0.2,
                  saturation=0.2) -> np.ndarray:
    img = rgb.astype(np.float32)
    img *= rng.uniform(1 - brightness, 1 + brightness)
    mean = img.mean()
    img = (img - mean) * rng.uniform(1 - contrast, 1 + contrast) + mean
    grey = img.mean(axis=2, keepdims=True)
    img = (img - grey) * rng.uniform(1 - saturation, 1 + saturation) + grey
    return np.clip(img, 0, 255).astype(np.uint8)


@dataclasses.dataclass
class AugmentOptions:
    flip: bool = True
    jitter: bool = True
    min_crop: float = 0.75  # crop side as a fraction of the image side (same aspect)


def augment(rgb, depth, intr, rng: np.random.Generator, opts: AugmentOptions, width: int, height: int):
    """Random crop (aspect kept), resize to the network input, flip, colour jitter."""
    h0, w0 = depth.shape
    s = rng.uniform(opts.min_crop, 1.0)
    cw, ch = max(1, int(round(w0 * s))), max(1, int(round(h0 * s)))
    x0 = int(rng.integers(0, w0 - cw + 1))
    y0 = int(rng.integers(0, h0 - ch + 1))
    rgb, depth, intr = crop_sample(rgb, depth, intr, x0, y0, cw, ch)
    rgb, depth, intr = resize_sample(rgb, depth, intr, width, height)
    if opts.flip and rng.random() < 0.5:
        rgb, depth, intr = flip_sample(rgb, depth, intr)
    if opts.jitter:
        rgb = colour_jitter(rgb, rng)
    return rgb, depth, intr


class FrameSet:
    """Frames decoded once into memory at ``cache_width`` x ``cache_height`` (or native size).

    Caching at a reduced size keeps the per-step cost to a crop and a small resize.
    """

    def __init__(self, records: Sequence[FrameRecord], cache_width: int = 0, cache_height: int = 0):
        if not records:
            raise DataError("no frames selected")
        self.samples = []
        for rec in records:
            rgb, depth, intr = load_frame(rec)
            if cache_width and cache_height:
                rgb, depth, intr = resize_sample(rgb, depth, intr, cache_width, cache_height)
            self.samples.append((rgb, depth, intr))

    def __len__(self) -> int:
        return len(self.samples)

    def __getitem__(self, i):
        return self.samples[i]


def to_tensors(rgb_batch: Sequence[np.ndarray], depth_batch: Sequence[np.ndarray]):
    import torch

    rgb = torch.from_numpy(np.stack(rgb_batch).astype(np.float32) / 255.0).permute(0, 3, 1, 2)
    depth = torch.from_numpy(np.stack(depth_batch).astype(np.float32)).unsqueeze(1)
    return rgb.contiguous(), depth.contiguous()


def batches(frames: FrameSet, batch_size: int, rng: np.random.Generator, width: int, height: int,
            opts: Optional[AugmentOptions] = None):
    """One epoch of shuffled, augmented batches (drops the last incomplete batch)."""
    opts = opts or AugmentOptions()
    order = rng.permutation(len(frames))
    for start in range(0, len(order) - batch_size + 1, batch_size):
        rgbs, depths = [], []
        for i in order[start:start + batch_size]:
            rgb, depth, intr = frames[int(i)]
            rgb, depth, _ = augment(rgb, depth, intr, rng, opts, width, height)
            rgbs.append(rgb)
            depths.append(depth)
        yield to_tensors(rgbs, depths)
