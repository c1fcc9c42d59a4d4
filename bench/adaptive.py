#!/usr/bin/env python3
"""Time to a clean image, uniform against adaptive YAT (issue #21, points 3 and 4, YAT's side).

For each compared seed scene at a reduced resolution: a converged reference (uniform, another
seed, cached in target/bench-refs), the MSE of a uniform render at --target-spp (1000) against
it, and the samples and CPU time uniform and adaptive YAT need to reach that MSE. The adaptive
side bisects --noise-threshold (on a log scale) toward the threshold whose image is as close to
the reference; the samples and CPU seconds adaptive needs for the target MSE are interpolated
(log-log, in MSE) between the two renders around it, or are the best render's when none is on
the far side. MSE is per channel over all pixels of the linear EXR, as in bench.py.

--write-results fills the seed table's column "core-s to 1000-spp error, adaptive" of
bench/RESULTS.md for the scenes measured: the row's "ours core-s" (uniform 1000 spp at the
seed's resolution) over the CPU-seconds speed-up measured here, labelled with this resolution.

    python3 bench/adaptive.py                       # the four scenes at 480x270, release binary
    python3 bench/adaptive.py --resolution 160x90 --reference-spp 2048 --binary target/debug/yat
    python3 bench/adaptive.py --only Cornell
    python3 bench/adaptive.py --binary target/fuzz/yat --reference-binary /tmp/ref-yat

Prints a Markdown table. CPU seconds are the render processes' (user + system, parse and build
included, which is under a second here); samples are the renders' own count, which the
machine's load cannot change. The machine may be shared: CPU seconds still move with it.
"""

import argparse
import math
import os
import re
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
    """(linear image, CPU seconds, mean samples per pixel) of one render."""
    with tempfile.TemporaryDirectory() as tmp:
        figures = yat(binary, scene, args, Path(tmp), extra)
        image = bench.read_exr(Path(tmp) / "out.exr")
    w, h = (int(v) for v in args.resolution.split("x"))
    return image, figures["cpu_seconds"], figures["samples"] / (w * h)


def at_target(lo, hi, target):
    """Samples and CPU seconds at MSE `target`, interpolated log-log between the renders lo
    (MSE at most target) and hi (above it), each (error, seconds, spp); lo's own without hi."""
    if hi is None or hi[0] <= lo[0]:
        return lo[2], lo[1]
    t = math.log(hi[0] / target) / math.log(hi[0] / lo[0])
    return tuple(math.exp(math.log(h) + t * (math.log(l) - math.log(h)))
                 for l, h in ((lo[2], hi[2]), (lo[1], hi[1])))


def write_results(path, measured, resolution):
    """Fills the seed table's adaptive column: per measured scene (file name to CPU speed-up),
    the row's "ours core-s" over the speed-up."""
    lines = path.read_text().split("\n")
    in_table = False
    for i, line in enumerate(lines):
        in_table = line.startswith("|") and (in_table or "core-s to 1000-spp error" in line)
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if in_table and cells[0] in measured and re.fullmatch(r"[0-9]+", cells[2]):
            speedup = measured[cells[0]]
            cells[8] = f"{float(cells[2]) / speedup:.0f} ({speedup:.2f}x at {resolution})"
            lines[i] = "| " + " | ".join(cells) + " |"
    path.write_text("\n".join(lines))


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
    ap.add_argument("--start-threshold", type=float, default=0.02,
                    help="the first threshold tried (0.02)")
    ap.add_argument("--binary", default=str(bench.YAT), help="the yat binary (default: release)")
    ap.add_argument("--reference-binary", help="the yat binary the references are rendered "
                    "with (default: --binary); a uniform render does not depend on the adaptive "
                    "code, so a copy kept aside spares re-rendering them after each rebuild")
    ap.add_argument("--write-results", action="store_true", help="fill the seed table's "
                    "adaptive column of bench/RESULTS.md with the measured speed-ups")
    ap.add_argument("--only", help="only scenes whose path contains this text")
    args = ap.parse_args()
    bench.ensure_venv()
    binary = Path(args.binary)
    if binary == bench.YAT:
        bench.build()
    ref_binary = Path(args.reference_binary or binary)
    max_spp = args.max_spp or 4 * args.target_spp
    scenes = [s for s in SCENES if not args.only or args.only in s]

    rows = []
    measured = {}
    for name in scenes:
        scene = bench.SEED / name
        if not scene.exists():
            print(f"{scene} not found: skipped", file=sys.stderr)
            continue

        def make(d):
            yat(ref_binary, scene, args, d, ["--spp", str(args.reference_spp), "--seed",
                                             str(REFERENCE_SEED)])
            (d / "out.exr").rename(d / "ref.exr")

        setting = f"adaptive-{Path(name).stem}-{args.resolution}-{args.reference_spp}"
        ref = bench.reference("yat", setting, bench.file_digest(ref_binary, scene), make)
        image, uniform_s, _ = measure(binary, scene, args, ["--spp", str(args.target_spp)])
        target = bench.mse(image, ref)
        print(f"{name}: uniform {args.target_spp} spp MSE {target:.4g} in {uniform_s:.1f} "
              "CPU s", file=sys.stderr, flush=True)

        # Bisect log(threshold): `lo` reaches the target (or is the smallest tried), `hi` not.
        def adaptive(threshold):
            image, seconds, spp = measure(binary, scene, args, [
                "--spp", str(max_spp), "--min-spp", str(args.min_spp),
                "--noise-threshold", f"{threshold:.5g}",
            ])
            error = bench.mse(image, ref)
            print(f"  threshold {threshold:.4g}: MSE {error:.4g}, {seconds:.1f} CPU s, "
                  f"{spp:.0f} spp", file=sys.stderr, flush=True)
            return error, seconds, spp

        # lo: the last render at or under the target MSE (its threshold t_lo), hi above it.
        lo = hi = t_lo = t_hi = None
        threshold = args.start_threshold
        for _ in range(args.steps):
            result = adaptive(threshold)
            if result[0] <= target:
                lo, t_lo = result, threshold
            else:
                hi, t_hi = result, threshold
            if t_lo is None:
                threshold /= 2
            elif t_hi is None:
                threshold *= 2
            else:
                threshold = math.sqrt(t_lo * t_hi)
        if lo is None:
            rows.append([name, args.resolution, f"{target:.3g}", f"{args.target_spp}",
                         f"{uniform_s:.1f}", "not reached", "", "", "", "", ""])
            continue
        spp, seconds = at_target(lo, hi, target)
        speedup = uniform_s / seconds
        measured[Path(name).name] = speedup
        rows.append([name, args.resolution, f"{target:.3g}", f"{args.target_spp}",
                     f"{uniform_s:.1f}", f"{t_lo:.3g}", f"{lo[0]:.3g}", f"{spp:.0f}",
                     f"{seconds:.1f}", f"{args.target_spp / spp:.2f}x", f"{speedup:.2f}x"])

    header = [f"scene ({args.threads} threads)", "resolution", f"MSE of uniform {args.target_spp}",
              "uniform spp", "uniform CPU s", "threshold", "its MSE", "adaptive spp to it",
              "adaptive CPU s to it", "speed-up in samples", "speed-up in CPU s"]
    print(f"\nReference: uniform {args.reference_spp} spp, seed {REFERENCE_SEED}; adaptive: "
          f"--min-spp {args.min_spp} --spp {max_spp}; {args.steps} renders per scene bisecting "
          "the threshold; 'to it' is interpolated log-log to the uniform render's MSE between "
          "the renders on either side (the threshold and MSE shown are the one at or under "
          "it).\n")
    print(bench.table(header, rows))
    if args.write_results and measured:
        write_results(bench.ROOT / "bench/RESULTS.md", measured, args.resolution)
        print("wrote the adaptive column of bench/RESULTS.md", file=sys.stderr)


if __name__ == "__main__":
    main()
