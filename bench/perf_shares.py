#!/usr/bin/env python3
"""Where a render's time goes: renders a scene once under `perf record` (one thread) and prints
perf's self-time shares by category (traversal, lights, materials and textures, film and
camera, the path loop with what is inlined in it), as shares and as seconds of the render.

    python3 bench/perf_shares.py SCENE.lxs [--yat target/release/yat] [--spp 16]
        [--resolution 480x270]

Inlined code counts where it was inlined: the path loop holds the sampler and the shading done
in lanes. Scene loading is left out. Needs `perf` (linux-perf)."""
import argparse
import collections
import json
import re
import subprocess
import sys
import tempfile

CATEGORIES = [
    ("traversal and hit data",
     r"wide_bvh|SceneGeometry::(closest|surface|occluded|intersect)|analytic|[Tt]riangle"),
    ("lights (choice, lamp points, images, environment)",
     r"lights::|Lights::|distribution|MirrorImages|direct_light|LatLong|AreaLight|acos|atan"),
    ("materials and textures",
     r"bilinear|bsdf_at|bxdf|Bxdf|texture|Textures|[Ii]mage[Mm]ap|[Mm]apping|Materials|"
     r"microfacet|Trowbridge|[Cc]onductor|fresnel|[Dd]ielectric|matte"),
    ("film and camera", r"filter|AxisWeights|splat|[Cc]amera|outliers"),
    ("path loop, sampler, packets (inlined)",
     r"render_unit|integrator|sampler|split_bsdf_light|walk|trace_|lanes::run"),
]
LOADING = r"decode|Environment::new|::build|parse|png|jpeg|zune|inflate|obvhs|WideBvh::(new|from)"


def shares(report: str) -> tuple[dict, float]:
    total = collections.Counter()
    loading = 0.0
    for line in report.splitlines():
        m = re.match(r"\s+([\d.]+)%\s+\[\.\]\s+(.*)", line)
        if not m:
            continue
        pct, sym = float(m.group(1)), m.group(2)
        if re.search(LOADING, sym):
            loading += pct
            continue
        name = next((n for n, rx in CATEGORIES if re.search(rx, sym)), "other")
        total[name] += pct
    return total, loading


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--yat", default="target/release/yat")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--resolution", default="480x270")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        render = [args.yat, "render", args.scene, "-q", "--spp", str(args.spp), "--seed",
                  str(args.seed), "--resolution", args.resolution, "--maxdepth", "10",
                  "--threads", "1", "-o", f"{d}/out.png", "--stats-json", f"{d}/stats.json",
                  "--preview-every", "0", "--checkpoint-every", "0"]
        subprocess.run(["perf", "record", "-q", "-o", f"{d}/perf.data", *render], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        seconds = json.load(open(f"{d}/stats.json"))["render_seconds"]
        report = subprocess.run(["perf", "report", "-i", f"{d}/perf.data", "--no-children",
                                 "--sort", "sym", "--stdio", "--percent-limit", "0"],
                                capture_output=True, text=True, check=True).stdout
    total, loading = shares(report)
    rendering = sum(total.values())
    if rendering <= 0:
        print("no samples", file=sys.stderr)
        return 1
    print(f"{args.scene}: render {seconds:.3f} s ({args.resolution}, {args.spp} spp, 1 thread)")
    for name in [n for n, _ in CATEGORIES] + ["other"]:
        share = total[name] / rendering
        print(f"  {name:52s} {100 * share:5.1f}%  {share * seconds:6.3f} s")
    print(f"  (scene loading: {loading:.1f}% of the samples, left out)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
