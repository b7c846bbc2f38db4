"""Training throughput of the effect model: crops/s for forward + backward + Adam step.

Compares, in one run on the same batches, a plain float32 eager loop (NCHW) with the
toolkit's loop (channels-last, bfloat16 autocast) and optionally torch.compile. Writes JSON.

    python bench/train.py --preset paper --out bench/results/train.json
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import torch

from symlearn.learning.models import AttentiveDeepSym, ModelConfig, masked_mse
from symlearn.provenance import atomic_write_json, bench_context


def _onednn_bf16(on: bool) -> None:
    """Let oneDNN run float32 convolutions and matmuls in bfloat16 (AMX) without autocast."""
    for backend in (torch.backends.mkldnn.conv, torch.backends.mkldnn.matmul):
        backend.fp32_precision = "bf16" if on else "none"


def measure(cfg: ModelConfig, batch: int, steps: int, channels_last: bool, bf16: bool, compile_: bool,
            onednn_bf16: bool = False) -> float:
    """Crops per second of forward + backward + Adam step on random batches in one setting."""
    _onednn_bf16(onednn_bf16)
    torch.manual_seed(0)
    model = AttentiveDeepSym(cfg)
    model.encoder.channels_last = channels_last
    opt = torch.optim.Adam(model.parameters(), 5e-4)
    fn = torch.compile(model) if compile_ else model
    g = torch.Generator().manual_seed(0)
    x = torch.rand(batch, 3, 3, cfg.crop, cfg.crop, generator=g)
    mask = torch.ones(batch, 3, dtype=torch.bool)
    mask[: batch // 3, 2] = False  # a realistic mix of scene sizes (about 2.7 objects a scene)
    a = torch.randint(0, 36, (batch,), generator=g)
    y = torch.randn(batch, 3, 3, generator=g)

    def step():
        with torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
            out = fn(x, mask, a)
        loss = masked_mse(out.effect.float(), y, mask)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()

    for _ in range(2):  # warm-up (and compilation)
        step()
    t = time.perf_counter()
    for _ in range(steps):
        step()
    rate = steps * int(mask.sum()) / (time.perf_counter() - t)
    _onednn_bf16(False)
    return rate


def main() -> None:
    """Measure every setting and write the JSON report."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--preset", default="paper")
    ap.add_argument("--batch", type=int, default=128)
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--compile", action="store_true", help="also measure torch.compile")
    ap.add_argument("--onednn-bf16", action="store_true", help="also measure oneDNN's implicit bf16 for fp32")
    ap.add_argument("--out", default="bench/results/train.json")
    args = ap.parse_args()
    cfg = ModelConfig.from_preset(args.preset)
    rows = {"fp32_eager_nchw (baseline)": measure(cfg, args.batch, args.steps, False, False, False),
            "channels_last_fp32": measure(cfg, args.batch, args.steps, True, False, False),
            "channels_last_bf16 (toolkit default)": measure(cfg, args.batch, args.steps, True, True, False)}
    if args.onednn_bf16:
        rows["channels_last_fp32_onednn_bf16"] = measure(cfg, args.batch, args.steps, True, False, False, True)
    if args.compile:
        rows["channels_last_bf16_compiled"] = measure(cfg, args.batch, args.steps, True, True, True)
    base = rows["fp32_eager_nchw (baseline)"]
    result = {"benchmark": "train_throughput", **bench_context(), "preset": args.preset,
              "batch_scenes": args.batch, "threads": torch.get_num_threads(),
              "crops_per_s": {k: round(v, 1) for k, v in rows.items()},
              "speedup_vs_baseline": {k: round(v / base, 2) for k, v in rows.items()}}
    atomic_write_json(Path(args.out), result)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
