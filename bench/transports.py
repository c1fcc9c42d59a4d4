#!/usr/bin/env python3
"""Bidirectional path tracing against path tracing on every complete seed scene and every scene
in scenes/: both converge to the same image wherever path tracing can carry the light (issue 50,
item 3). Per scene, at a small resolution of the Film's aspect and a fixed spp:

- path tracing twice (seeds 1 and 2) at max depth eyedepth + lightdepth, the longest path the
  bidirectional integrator makes (every length up to it has a strategy);
- bidirectional once (seed 1) with the scene's own eyedepth and lightdepth;

and prints the ratio of the image means (bidirectional over the two path renders' mean), the
16x16 block correlation of bidirectional against path seed 1, and that of the two path renders
(the noise floor: where it is below 0.999, so is any comparison at this spp), with each render's
seconds and samples/s. The agreement targets: ratio within 0.5%, block correlation >= 0.999.

    python3 bench/transports.py                      # every scene, prints the table
    python3 bench/transports.py --scenes caustics,CornellBox/cornell-box.lxs --spp 1024
    python3 bench/transports.py --write-results      # also writes its bench/RESULTS.md section

Each scene's figures are cached in target/bench-transports.json by the binary's digest and the
settings, so a run that stops goes on where it stopped.
"""

import argparse
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench  # noqa: E402  (the shared helpers: venv, measured runs, EXR, block correlation)

CACHE = bench.TARGET / "bench-transports.json"
SECTION = "## Bidirectional against path tracing, every scene"

# The seed scenes whose files are all there (Dragon, Sponza and the bunnies are not; the
# Benchmarks folder's Lights.lxs is the others' include, not a scene).
SEED_SCENES = [
    "Benchmarks/GlassHighIOR.lxs", "Benchmarks/GlassHighTransparency.lxs",
    "Benchmarks/GlassLowTransparency.lxs", "Benchmarks/GlassMediumTransparency.lxs",
    "Benchmarks/MatteBlue.lxs", "Benchmarks/MatteGreen.lxs",
    "Benchmarks/MatteRed.lxs", "Benchmarks/MetalHighRoughness.lxs",
    "Benchmarks/MetalLowRoughness.lxs", "Benchmarks/MetalMediumRoughness.lxs",
    "Benchmarks/MirrorHighReflectivity.lxs", "Benchmarks/MirrorLowReflectivity.lxs",
    "Benchmarks/MirrorMediumReflectivity.lxs", "Benchmarks/Spheres.lxs",
    "Benchmarks/TexturedChannels.lxs",
    "CaptainFalcon/captainfalcon.lxs", "CornellBox/cornell-box.lxs",
    "CornellBoxFisheye/cornell-box-fisheye-high-fov.lxs",
    "CornellBoxFisheye/cornell-box-fisheye-low-fov.lxs",
    "CornellBoxFisheye/cornell-box-fisheye.lxs",
    "DepthOfField/depth-of-field-control.lxs", "DepthOfField/depth-of-field-high.lxs",
    "DepthOfField/depth-of-field-low.lxs", "Goku/goku.lxs", "GokuSelfie/goku-selfie.lxs",
    "MetalMario/metal-mario-bg1.lxs", "MetalMario/metal-mario-bg2.lxs",
    "MetalMario/metal-mario-bg3.lxs", "MetalMario/metal-mario-bg4.lxs",
    "MetalMario/metal-mario-wall.lxs", "Ornstein/ornstein.lxs", "Pillar/pillar-point.lxs",
    "Pillar/pillar-reinhard.lxs", "Pillar/pillar-sphere-large.lxs",
    "Pillar/pillar-sphere-small.lxs", "Pillar/pillar-square-large.lxs",
    "Pillar/pillar-square-small.lxs", "Yart.lxs",
]


def own_scenes():
    return sorted(str(p.relative_to(bench.ROOT)) for p in (bench.ROOT / "scenes").glob("*/*.lxs"))


def scene_path(name):
    """A scene by the name the table gives it: scenes/... (ours) or relative to the seed's."""
    return bench.ROOT / name if name.startswith("scenes/") else bench.SEED / name


def what_runs(binary, scene):
    """The Film's resolution and the bidirectional depths `yat check` reports for `scene`."""
    out = subprocess.run([str(binary), "check", str(scene)], capture_output=True, text=True,
                         check=True).stdout
    w, h = map(int, re.search(r"^resolution\s+(\d+)x(\d+)", out, re.M).groups())
    eye, light = map(int, re.search(r"eye depth (\d+), light depth (\d+)", out).groups())
    return (w, h), eye, light


def compare(binary, name, width, spp, threads):
    import numpy as np

    scene = scene_path(name)
    (fw, fh), eye, light = what_runs(binary, scene)
    size = (width, max(1, round(width * fh / fw)))
    runs = {
        "path1": (1, "path", eye + light),
        "path2": (2, "path", eye + light),
        "bidir": (1, "bidirectional", None),
    }
    images, figures = {}, {}
    for key, (seed, transport, depth) in runs.items():
        with tempfile.TemporaryDirectory() as tmp:
            f = bench.render(scene, spp, depth, threads, Path(tmp), seed, size, binary,
                             ["--integrator", transport])
            images[key] = bench.read_exr(Path(tmp) / "out.exr")
        figures[key] = {"seconds": f["render_seconds"], "samples_per_second":
                        f["samples_per_second"]}
    path = (images["path1"] + images["path2"]) / 2
    return {
        "size": size, "spp": spp, "eye": eye, "light": light,
        "ratio": float(images["bidir"].mean() / path.mean()) if path.mean() > 0 else None,
        "channel_ratios": [float(images["bidir"][..., c].mean() / path[..., c].mean())
                           if path[..., c].mean() > 0 else None for c in range(3)],
        "correlation": bench.block_correlation(images["bidir"], images["path1"]),
        "noise_floor": bench.block_correlation(images["path2"], images["path1"]),
        "finite": bool(np.isfinite(images["bidir"]).all()),
        **figures,
    }


def table(results):
    rows = []
    for name, r in results.items():
        ratio = "-" if r["ratio"] is None else f"{r['ratio']:.4f}"
        ok = (r["ratio"] is not None and abs(r["ratio"] - 1) < 0.005
              and r["correlation"] >= 0.999)
        rows.append([
            name, f"{r['size'][0]}x{r['size'][1]}", str(r["spp"]), f"{r['eye']}/{r['light']}",
            ratio, f"{r['correlation']:.4f}", f"{r['noise_floor']:.4f}",
            f"{r['path1']['seconds']:.1f}", f"{r['bidir']['seconds']:.1f}",
            f"{r['path1']['samples_per_second'] / 1e6:.2f}",
            f"{r['bidir']['samples_per_second'] / 1e6:.2f}", "yes" if ok else "no",
        ])
    return bench.table(["scene", "size", "spp", "eye/light", "mean ratio", "block corr",
                        "path vs path", "path s", "bidir s", "path M samples/s",
                        "bidir M samples/s", "agrees"], rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--scenes", help="comma-separated names (a seed scene relative to the seed's "
                    "scenes/, ours as scenes/...; a bare word picks the names containing it); "
                    "default: every one")
    ap.add_argument("--width", type=int, default=160, help="image width (160; the Film's aspect)")
    ap.add_argument("--spp", type=int, default=256, help="samples per pixel (256)")
    ap.add_argument("--threads", type=int, default=2, help="render threads (2)")
    ap.add_argument("--binary", default=str(bench.YAT), help="the yat binary (default: release)")
    ap.add_argument("--write-results", action="store_true", help="write this section of "
                    "bench/RESULTS.md")
    args = ap.parse_args()
    bench.ensure_venv()

    names = own_scenes() + ([s for s in SEED_SCENES if (bench.SEED / s).exists()]
                            if bench.SEED.exists() else [])
    if args.scenes:
        wanted = args.scenes.split(",")
        names = [n for n in names if any(w == n or w in n for w in wanted)]
    binary = Path(args.binary)
    digest = bench.file_digest(binary)
    cache = json.loads(CACHE.read_text()) if CACHE.exists() else {}
    results = {}
    for name in names:
        key = f"{name}|{args.width}|{args.spp}|{digest}"
        if key not in cache:
            bench.log(f"{name}: path x2, bidirectional at {args.spp} spp")
            try:
                cache[key] = compare(binary, name, args.width, args.spp, args.threads)
            except (RuntimeError, subprocess.CalledProcessError) as e:
                bench.log(f"{name}: {e}")
                continue
            CACHE.parent.mkdir(parents=True, exist_ok=True)
            CACHE.write_text(json.dumps(cache, indent=1))
        results[name] = cache[key]
        r = results[name]
        bench.log(f"  ratio {r['ratio']}, correlation {r['correlation']:.4f} "
                  f"(path vs path {r['noise_floor']:.4f})")
    text = table(results)
    print(text)
    if args.write_results:
        section = (f"{SECTION}\n\n{bench.machine()}; `python3 bench/transports.py --width "
                   f"{args.width} --spp {args.spp}`. Path tracing at max depth eyedepth + "
                   "lightdepth (two seeds), bidirectional at the scene's depths; \"path vs "
                   "path\" is the block correlation of the two path renders, the noise floor of "
                   "any comparison at this spp.\n\n" + text + "\n")
        results_md = bench.ROOT / "bench/RESULTS.md"
        results_md.write_text(bench.replace_section(results_md.read_text(), SECTION, section))


if __name__ == "__main__":
    main()
