#!/usr/bin/env python3
"""YAT's benchmark: renders a fixed list of scenes at a fixed spp and depth with the release
binary and prints, per scene, resolution, spp, parse/build time, render time, samples/s, rays/s,
peak memory and core-seconds per sample, then sets our time for the seed scenes (scaled to
1000 spp) beside the original tracer's published table.

    python3 bench/bench.py            # full list, writes bench/RESULTS.md
    python3 bench/bench.py --quick    # fewer samples, prints only

Speed lives here, never in timed tests.
"""

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SEED = Path(os.environ.get("YAT_SEED_SCENES", ROOT.parent / "shared/seed-project/scenes"))
YAT = ROOT / "target/release/yat"

# (scene relative to its root, the original tracer's published time at 1000 spp on 8 cores in
# seconds, or None when it published none). From the seed project's README.
SEED_TABLE = [
    ("DepthOfField/depth-of-field-control.lxs", 9 * 60 + 45),
    ("DepthOfField/depth-of-field-low.lxs", 9 * 60 + 36),
    ("DepthOfField/depth-of-field-high.lxs", 9 * 60 + 25),
    ("CornellBoxFisheye/cornell-box-fisheye-low-fov.lxs", 17 * 60 + 36),
    ("CornellBoxFisheye/cornell-box-fisheye.lxs", 14 * 60 + 14),
    ("CornellBoxFisheye/cornell-box-fisheye-high-fov.lxs", 8 * 60 + 11),
    ("CornellBox/cornell-box.lxs", 19 * 60 + 19),
    ("MetalMario/metal-mario-wall.lxs", 54 * 60 + 29),
    ("MetalMario/metal-mario-bg1.lxs", 10 * 60 + 26),
    ("MetalMario/metal-mario-bg2.lxs", 10 * 60 + 18),
    ("MetalMario/metal-mario-bg3.lxs", 10 * 60 + 29),
    ("MetalMario/metal-mario-bg4.lxs", 10 * 60 + 23),
    ("CaptainFalcon/captainfalcon.lxs", 2 * 3600 + 47 * 60 + 55),
    ("GokuSelfie/goku-selfie.lxs", 18 * 60 + 18),
    ("Ornstein/ornstein.lxs", 30 * 60 + 29),
]
ORIGINAL_CORES = 8

OWN_SCENES = [
    "cornell/cornell-box.lxs",
    "cornell/cornell-fisheye-60.lxs",
    "dof/dof-0.1.lxs",
    "envmap/envmap-hdr.lxs",
    "materials/materials.lxs",
    "heavy/heavy.lxs",
]


def build():
    subprocess.run(["cargo", "build", "--release", "-p", "yat"], cwd=ROOT, check=True)
    if not (ROOT / "scenes/heavy/heavy.ply").exists():
        subprocess.run(
            ["cargo", "run", "--release", "-p", "yat-tracer", "--example", "make_scene_assets"],
            cwd=ROOT,
            check=True,
        )


def render(scene, spp, depth, threads, out_dir):
    """Runs one render; returns its --stats-json figures plus wall time and child peak RSS."""
    stats = out_dir / "stats.json"
    cmd = [
        str(YAT), "render", str(scene), "--quiet", "--spp", str(spp), "--maxdepth", str(depth),
        "--threads", str(threads), "--stats-json", str(stats), "-o", str(out_dir / "out.png"),
    ]
    start = datetime.datetime.now()
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = (datetime.datetime.now() - start).total_seconds()
    err = proc.stderr.read().decode(errors="replace")
    if status != 0:
        raise RuntimeError(f"{scene}: yat failed ({status}): {err.strip()[-500:]}")
    figures = json.loads(stats.read_text())
    figures["wall_seconds"] = wall
    figures["cpu_seconds"] = usage.ru_utime + usage.ru_stime
    figures["peak_rss_mb"] = usage.ru_maxrss / 1024
    return figures


def fmt_row(cols, widths):
    return "| " + " | ".join(str(c).ljust(w) for c, w in zip(cols, widths)) + " |"


def table(header, rows):
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    lines = [fmt_row(header, widths), "|" + "|".join("-" * (w + 2) for w in widths) + "|"]
    lines += [fmt_row(r, widths) for r in rows]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel (default 16)")
    ap.add_argument("--depth", type=int, default=10, help="path depth (default 10, the seed's)")
    ap.add_argument("--threads", type=int, default=os.cpu_count(), help="render threads")
    ap.add_argument("--quick", action="store_true", help="4 spp, and do not write RESULTS.md")
    ap.add_argument("--only", help="render only scenes whose path contains this text")
    args = ap.parse_args()
    spp = 4 if args.quick else args.spp

    build()
    scenes = [("seed", SEED / s, t) for s, t in SEED_TABLE] + [
        ("own", ROOT / "scenes" / s, None) for s in OWN_SCENES
    ]
    if args.only:
        scenes = [s for s in scenes if args.only in str(s[1])]
    if not SEED.exists():
        print(f"seed scenes not found at {SEED}: benchmarking our own scenes only", file=sys.stderr)
        scenes = [s for s in scenes if s[0] == "own"]

    rows, seed_rows = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for kind, scene, original in scenes:
            print(f"rendering {scene.name} at {spp} spp ...", file=sys.stderr, flush=True)
            f = render(scene, spp, args.depth, args.threads, Path(tmp))
            core_s_per_sample = f["render_seconds"] * args.threads / max(f["samples"], 1)
            rows.append([
                scene.name, f"{f['width']}x{f['height']}", f["spp"],
                f"{f['parse_seconds']:.2f} / {f['build_seconds'] or 0:.2f}",
                f"{f['render_seconds']:.2f}", f"{f['samples_per_second'] / 1e6:.3f}",
                f"{f['rays_per_second'] / 1e6:.2f}", f"{f['peak_rss_mb']:.0f}",
                f"{core_s_per_sample * 1e6:.2f}",
            ])
            if original is not None:
                # Linear in spp: the seed's table is at 1000 spp.
                ours_1000 = f["render_seconds"] * 1000 / f["spp"]
                ours_core = ours_1000 * args.threads
                theirs_core = original * ORIGINAL_CORES
                seed_rows.append([
                    scene.name, f"{ours_1000:.0f}", f"{ours_core:.0f}", f"{original}",
                    f"{theirs_core}", f"{theirs_core / ours_core:.1f}x",
                ])

    main_table = table(
        ["scene", "resolution", "spp", "parse / build s", "render s", "M samples/s",
         "M rays/s", "peak MB", "core-us/sample"],
        rows,
    )
    seed_table = table(
        ["scene", "ours s @1000spp", "ours core-s", "original s (8 cores)", "original core-s",
         "core-s ratio"],
        seed_rows,
    )
    cpu = platform.processor() or platform.machine()
    try:
        cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if "model name" in l)
    except (OSError, StopIteration):
        pass
    report = f"""# YAT benchmark results

- machine: {cpu}, {os.cpu_count()} cores; {args.threads} render threads
- date: {datetime.date.today().isoformat()}
- command: `python3 bench/bench.py{' --spp ' + str(args.spp) if args.spp != 16 else ''}`
- settings: {spp} spp, path depth {args.depth}, release build

## Every scene

{main_table}

core-us/sample = render seconds x threads / samples (CPU time per camera sample).

## The original tracer's table, re-created

Our time at {spp} spp scaled linearly to 1000 spp; the original's published time at 1000 spp,
depth 10 on an 8-core AMD FX-8150 (OpenJDK 8), converted to core-seconds (x 8).

{seed_table}
"""
    print(report)
    if not args.quick and not args.only:
        (ROOT / "bench/RESULTS.md").write_text(report)
        print("wrote bench/RESULTS.md", file=sys.stderr)


if __name__ == "__main__":
    main()
