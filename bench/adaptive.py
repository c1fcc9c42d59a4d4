#!/usr/bin/env python3
"""Time to a clean image, uniform against adaptive YAT (issue #21, points 3 and 4, YAT's side).

For each compared seed scene at a reduced resolution: a converged reference (uniform, another
seed, cached in bench/out/refs), the MSE of a uniform render at --target-spp (1000) against
it, and the render time uniform and adaptive YAT need to reach that MSE. The adaptive side
bisects --noise-threshold (on a log scale) for the largest threshold whose image is at least as
close to the reference, and reports that render's time and its mean samples per pixel. MSE is
per channel over all pixels of the linear EXR, as in bench.py.

    python3 bench/adaptive.py                       # the four scenes at 480x270, release binary
    python3 bench/adaptive.py --resolution 160x90 --reference-spp 2048 --binary target/debug/yat
    python3 bench/adaptive.py --only Cornell

Prints a Markdown table. Times are the renders' own (parse and build excluded) on --threads
threads; the machine may be shared: rerun when figures look noisy.
"""

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench  # noqa: E402  (the shared helpers: venv, measured runs, EXR, references)

SCENES = [
    "CornellBox/cornell-box.lxs",
    "DepthOfField/depth-of-field-high.lxs",
    "MetalMario/metal-mario-bg1.lxs",
    "CaptainFalcon/captainfalcon.lxs",
]
REFERENCE_SEED = 7


def yat(binary, scene, args, out_dir, extra):
    """One in-process YAT render into out_dir/out.exr; returns its figures."""
    stats = out_dir / "stats.json"
    cmd = [
        str(binary), "render", str(scene), "--quiet", "--resolution", args.resolution,
        "--maxdepth", str(args.depth), "--threads", str(args.threads), "--stats-json", str(stats),
        "-o", str(out_dir / "out.png"), "--exr", "--preview-every", "0", "--checkpoint-every", "0",
        *extra,
    ]
    return bench.run_measured(cmd, f"yat on {scene}", stats)


def measure(binary, scene, args, extra):
    """(linear image, render seconds, mean samples per pixel) of one render."""
    with tempfile.TemporaryDirectory() as tmp:
        figures = yat(binary, scene, args, Path(tmp), extra)
        image = bench.read_exr(Path(tmp) / "out.exr")
    w, h = (int(v) for v in args.resolution.split("x"))
    return image, figures["render_seconds"], figures["samples"] / (w * h)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--resolution", default="480x270", help="WxH of every render (default 480x270)")
    ap.add_argument("--reference-spp", type=int, default=4096, help="the reference's spp (4096)")
    ap.add_argument("--target-spp", type=int, default=1000, help="the uniform render whose MSE "
                    "both must reach (1000)")
    ap.add_argument("--max-spp", type=int, default=None,
                    help="adaptive --spp, the most a pixel gets (default 4 x --target-spp)")
    ap.add_argument("--min-spp", type=int, default=16, help="adaptive --min-spp (16)")
    ap.add_argument("--depth", type=int, default=10, help="path depth (10, the seed's)")
    ap.add_argument("--threads", type=int, default=os.cpu_count(), help="render threads")
    ap.add_argument("--steps", type=int, default=5, help="bisection steps on the threshold (5)")
    ap.add_argument("--binary", default=str(bench.YAT), help="the yat binary (default: release)")
    ap.add_argument("--only", help="only scenes whose path contains this text")
    args = ap.parse_args()
    bench.ensure_venv()
    binary = Path(args.binary)
    if binary == bench.YAT:
        bench.build()
    max_spp = args.max_spp or 4 * args.target_spp
    scenes = [s for s in SCENES if not args.only or args.only in s]

    rows = []
    for name in scenes:
        scene = bench.SEED / name
        if not scene.exists():
            print(f"{scene} not found: skipped", file=sys.stderr)
            continue

        def make(d):
            yat(binary, scene, args, d, ["--spp", str(args.reference_spp), "--seed",
                                         str(REFERENCE_SEED)])
            (d / "out.exr").rename(d / "ref.exr")

        setting = f"adaptive-{Path(name).stem}-{args.resolution}-{args.reference_spp}"
        ref = bench.reference("yat", setting, bench.file_digest(binary, scene), make)
        image, uniform_s, _ = measure(binary, scene, args, ["--spp", str(args.target_spp)])
        target = bench.mse(image, ref)
        print(f"{name}: uniform {args.target_spp} spp MSE {target:.4g} in {uniform_s:.1f} s",
              file=sys.stderr, flush=True)

        # Bisect log(threshold): `lo` reaches the target (or is the smallest tried), `hi` not.
        def adaptive(threshold):
            image, seconds, spp = measure(binary, scene, args, [
                "--spp", str(max_spp), "--min-spp", str(args.min_spp),
                "--noise-threshold", f"{threshold:.5g}",
            ])
            error = bench.mse(image, ref)
            print(f"  threshold {threshold:.4g}: MSE {error:.4g}, {seconds:.1f} s, {spp:.0f} spp",
                  file=sys.stderr, flush=True)
            return error, seconds, spp

        lo, hi, best = None, None, None
        threshold = 0.02  # about a uniform 1000-spp render's relative RMS error
        for _ in range(args.steps):
            error, seconds, spp = adaptive(threshold)
            if error <= target:
                lo, best = threshold, (threshold, error, seconds, spp)
            else:
                hi = threshold
            if lo is None:
                threshold /= 4
            elif hi is None:
                threshold *= 4
            else:
                threshold = math.sqrt(lo * hi)
        if best is None:
            rows.append([name, args.resolution, f"{target:.3g}", f"{uniform_s:.1f}", "not reached",
                         "", "", "", ""])
            continue
        t, error, seconds, spp = best
        rows.append([name, args.resolution, f"{target:.3g}", f"{uniform_s:.1f}", f"{t:.3g}",
                     f"{error:.3g}", f"{seconds:.1f}", f"{spp:.0f}", f"{uniform_s / seconds:.2f}x"])

    header = [f"scene ({args.threads} threads)", "resolution", f"MSE of uniform {args.target_spp}",
              "uniform s", "threshold", "adaptive MSE", "adaptive s", "adaptive mean spp",
              "speed-up"]
    print(f"\nReference: uniform {args.reference_spp} spp, seed {REFERENCE_SEED}; adaptive: "
          f"--min-spp {args.min_spp} --spp {max_spp}, the largest threshold found in "
          f"{args.steps} steps whose MSE is at most the uniform render's.\n")
    print(bench.table(header, rows))


if __name__ == "__main__":
    main()
