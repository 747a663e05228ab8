#!/usr/bin/env python3
"""Train the depth network: relative-depth pre-training (global consistency loss, Eq. 5-6), then
metric fine-tuning (SILog). The learning-rate schedule runs over epochs (deterministic for a seed);
--time-budget only stops early, after saving a checkpoint. The budget is CPU time of the training
process (time.process_time, batch preparation and steps, validation excluded), so it means the
same on an idle machine and on one shared with compilers; wall time is logged as well.

Example (the small variant on 7-Scenes frames 0-399, see docs/depthnet.md):
  nice -n 10 python3 tools/depthnet/train.py --data 7scenes:../shared/data/7scenes-seq-a \
      --frames 0:400 --val-frames 400:600 --out tools/depthnet/runs/small --epochs 20 \
      --pretrain-epochs 3 --time-budget 29
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402
import torch  # noqa: E402

from depthnet import data as D  # noqa: E402
from depthnet.checkpoint import save_checkpoint  # noqa: E402
from depthnet.losses import global_consistency_loss, silog_loss  # noqa: E402
from depthnet.metrics import average, depth_metrics  # noqa: E402
from depthnet.model import SMALL, TINY, DepthNet, ModelConfig, count_parameters  # noqa: E402

VARIANTS = {"small": SMALL, "tiny": TINY}


def parse_size(text: str):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size '{text}': expected WxH, e.g. 192x144") from None
    return w, h


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", required=True, help="7scenes:DIR or tum:DIR")
    p.add_argument("--frames", default="", help="half-open frame range A:B (default all)")
    p.add_argument("--val-data", default="", help="validation dataset (default: --data)")
    p.add_argument("--val-frames", default="", help="validation frame range, evaluated each epoch")
    p.add_argument("--val-every", type=int, default=1, help="epochs between validations")
    p.add_argument("--out", required=True, help="run directory (checkpoints, log.csv)")
    p.add_argument("--variant", choices=sorted(VARIANTS), default="small")
    p.add_argument("--input-size", type=parse_size, default=None, help="WxH (default: variant's)")
    p.add_argument("--channels", default="", help="encoder channels, e.g. 16,32,64,128 (width/depth)")
    p.add_argument("--blocks-per-stage", type=int, default=-1, help="extra convs per encoder stage")
    p.add_argument("--decoder-channels", type=int, default=0, help="decoder base width")
    p.add_argument("--seed-bins", type=int, default=0, help="Ns (default: variant's)")
    p.add_argument("--max-depth", type=float, default=0.0, help="metric range top (default: variant's)")
    p.add_argument("--epochs", type=int, default=20)
    p.add_argument("--pretrain-epochs", type=int, default=4, help="epochs of relative pre-training")
    p.add_argument("--batch-size", type=int, default=8)
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--weight-decay", type=float, default=1e-4)
    p.add_argument("--cache-size", type=parse_size, default=(256, 192),
                   help="frames are decoded once at this WxH before crop/resize augmentation")
    p.add_argument("--no-augment", action="store_true")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=1, choices=[1, 2])
    p.add_argument("--time-budget", type=float, default=0.0, help="CPU minutes of training (0 = none)")
    p.add_argument("--stop-after", type=int, default=0,
                   help="stop after this many epochs in total (schedule still uses --epochs)")
    p.add_argument("--resume", action="store_true", help="continue from OUT/last.pt")
    p.add_argument("--log-every", type=int, default=10, help="steps between progress lines")
    return p


def make_config(args) -> ModelConfig:
    cfg = ModelConfig.from_dict(VARIANTS[args.variant].to_dict())
    if args.input_size:
        cfg.input_width, cfg.input_height = args.input_size
    if args.channels:
        cfg.encoder_channels = tuple(int(c) for c in args.channels.split(","))
    if args.blocks_per_stage >= 0:
        cfg.blocks_per_stage = args.blocks_per_stage
    if args.decoder_channels:
        cfg.decoder_channels = args.decoder_channels
    if args.seed_bins:
        cfg.num_seed_bins = args.seed_bins
    if args.max_depth:
        cfg.max_depth = args.max_depth
    cfg.check()
    return cfg


@torch.no_grad()
def evaluate_frames(model: DepthNet, frames: D.FrameSet) -> dict:
    """Whole image resized to the network input; prediction upsampled to the cached GT size."""
    cfg = model.config
    model.eval()
    results = []
    for rgb, depth, _ in frames.samples:
        small = D.resize_sample(rgb, depth, (1, 1, 0, 0), cfg.input_width, cfg.input_height)[0]
        x, _ = D.to_tensors([small], [np.zeros(small.shape[:2], np.float32)])
        pred = model(x)
        pred = torch.nn.functional.interpolate(pred, size=depth.shape, mode="bilinear",
                                               align_corners=False)[0, 0].numpy()
        results.append(depth_metrics(pred, depth, cfg.min_depth, cfg.max_depth))
    return average(results)


def lr_at(epoch: int, step_fraction: float, args) -> float:
    """Cosine decay per stage, with a one-epoch linear warm-up at the start of training."""
    if epoch < args.pretrain_epochs:
        start, length = 0, args.pretrain_epochs
    else:
        start, length = args.pretrain_epochs, max(1, args.epochs - args.pretrain_epochs)
    progress = (epoch - start + step_fraction) / length
    lr = args.lr * 0.5 * (1 + math.cos(math.pi * min(1.0, progress)))
    if epoch == 0:
        lr *= max(0.05, step_fraction)
    return max(lr, args.lr * 0.01)


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    os.makedirs(args.out, exist_ok=True)
    last_path = os.path.join(args.out, "last.pt")

    try:
        records = D.list_frames(args.data, D.parse_frame_range(args.frames))
        val_records = []
        if args.val_frames:
            val_records = D.list_frames(args.val_data or args.data, D.parse_frame_range(args.val_frames))
    except D.DataError as e:
        print(f"train.py: error: {e}", file=sys.stderr)
        return 2

    try:
        cfg = make_config(args)
    except ValueError as e:
        print(f"train.py: error: model configuration: {e}", file=sys.stderr)
        return 2
    model = DepthNet(cfg)
    optimiser = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=args.weight_decay)
    start_epoch, elapsed = 0, 0.0
    if args.resume:
        if not os.path.exists(last_path):
            print(f"train.py: error: {last_path}: no checkpoint to resume from", file=sys.stderr)
            return 2
        state = torch.load(last_path, map_location="cpu")
        cfg = ModelConfig.from_dict(state["config"])
        model = DepthNet(cfg)
        model.load_state_dict(state["model"])
        optimiser = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=args.weight_decay)
        optimiser.load_state_dict(state["optimiser"])
        start_epoch, elapsed = state["epoch"], state["elapsed"]
        torch.set_rng_state(state["torch_rng"])
        print(f"resumed from {last_path}: epoch {start_epoch}, {elapsed / 60:.1f} min trained")

    t_load = time.time()
    try:
        frames = D.FrameSet(records, *args.cache_size)
        val_frames = D.FrameSet(val_records, *args.cache_size) if val_records else None
    except D.DataError as e:
        print(f"train.py: error: {e}", file=sys.stderr)
        return 2
    print(f"model: {count_parameters(model)} parameters, {cfg.num_bins} bins "
          f"({cfg.num_seed_bins} seed x 2^{cfg.num_decoder_layers}), input {cfg.input_width}x{cfg.input_height}")
    print(f"data: {len(frames)} training frames, {len(val_frames) if val_frames else 0} validation "
          f"frames (decoded in {time.time() - t_load:.1f} s)")
    with open(os.path.join(args.out, "args.json"), "w") as f:
        json.dump({k: v for k, v in vars(args).items()}, f, indent=1, default=str)

    log_path = os.path.join(args.out, "log.csv")
    new_log = not (args.resume and os.path.exists(log_path))
    log_file = open(log_path, "w" if new_log else "a", newline="")
    log = csv.writer(log_file)
    if new_log:
        log.writerow(["epoch", "stage", "train_loss", "lr", "cpu_min", "val_abs_rel", "val_rmse",
                      "val_delta1"])
    augment = D.AugmentOptions(flip=not args.no_augment, jitter=not args.no_augment,
                               min_crop=1.0 if args.no_augment else 0.75)
    budget = args.time_budget * 60.0
    t_start = time.time()
    steps_per_epoch = max(1, len(frames) // args.batch_size)
    stopped = False
    for epoch in range(start_epoch, args.epochs):
        stage = "relative" if epoch < args.pretrain_epochs else "metric"
        rng = np.random.default_rng([args.seed, epoch])  # per-epoch stream: resume is exact
        model.train()
        losses = []
        t_epoch = time.time()
        t0 = time.process_time()  # CPU time of batch preparation and steps, not validation
        for step, (rgb, gt) in enumerate(D.batches(frames, args.batch_size, rng, cfg.input_width,
                                                   cfg.input_height, augment)):
            lr = lr_at(epoch, step / steps_per_epoch, args)
            for group in optimiser.param_groups:
                group["lr"] = lr
            mask = (gt > cfg.min_depth) & (gt <= cfg.max_depth)
            pred = model(rgb)
            if stage == "relative":
                loss = global_consistency_loss(gt, pred, mask)
            else:
                loss = silog_loss(pred, gt, mask)
            optimiser.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
            optimiser.step()
            losses.append(loss.item())
            elapsed += time.process_time() - t0
            t0 = time.process_time()
            if (step + 1) % args.log_every == 0:
                rate = (step + 1) * args.batch_size / (time.time() - t_epoch)
                print(f"epoch {epoch + 1}/{args.epochs} [{stage}] step {step + 1}/{steps_per_epoch} "
                      f"loss {np.mean(losses[-args.log_every:]):.4f} lr {lr:.2e} {rate:.1f} img/s "
                      f"{elapsed / 60:.1f} CPU min", flush=True)
            if budget and elapsed >= budget:
                stopped = True
                break
        last_epoch = stopped or epoch + 1 == args.epochs
        want_val = val_frames and (last_epoch or (epoch + 1) % max(1, args.val_every) == 0)
        val = evaluate_frames(model, val_frames) if want_val else {}
        done_epochs = epoch + 1 if not stopped else epoch
        state = {"config": cfg.to_dict(), "model": model.state_dict(),
                 "optimiser": optimiser.state_dict(), "epoch": done_epochs, "elapsed": elapsed,
                 "torch_rng": torch.get_rng_state(), "args": vars(args), "val": val}
        save_checkpoint(last_path, state)
        log.writerow([epoch + 1, stage, f"{np.mean(losses):.5f}" if losses else "", f"{lr:.3e}",
                      f"{elapsed / 60:.2f}", val.get("abs_rel", ""), val.get("rmse", ""),
                      val.get("delta1", "")])
        log_file.flush()
        msg = f"epoch {epoch + 1} done: {stage} loss {np.mean(losses) if losses else float('nan'):.4f}"
        if val:
            msg += f", val AbsRel {val['abs_rel']:.4f} RMSE {val['rmse']:.4f} delta1 {val['delta1']:.4f}"
        print(msg + f", {elapsed / 60:.1f} CPU min, {(time.time() - t_start) / 60:.1f} wall min this run, "
              f"saved {last_path}", flush=True)
        if args.stop_after and epoch + 1 >= args.stop_after and not stopped:
            print(f"stopping after epoch {epoch + 1} (--stop-after); --resume continues")
            break
        if stopped:
            print(f"time budget of {args.time_budget} min reached during epoch {epoch + 1}; "
                  f"--resume continues from the start of that epoch")
            break
    log_file.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
