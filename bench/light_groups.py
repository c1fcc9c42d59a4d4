#!/usr/bin/env python3
"""Light groups against LuxCore's radiance groups: scenes/exported/lightgroups.lxs rendered by
YAT (path and bidirectional; its EXR's layer `lightgroup.<name>` per group) and by LuxCore
2.11 PATHCPU through `yat export-luxcore` (each group's lights under their group's light id, a
RADIANCE_GROUP output per id), each group's mean radiance side by side.

    python3 bench/light_groups.py [--spp 256] [--luxcore-spp 256] [--resolution 96x72]

Runs in the benchmark's virtualenv (bench/setup-env.sh: pyluxcore, OpenEXR) with the release
build (cargo build --release -p yat). The groups' own light is compared, before the weighing
of their settings (LuxCore's temperature is not LuxRender's adaptation). LuxCore has no
Preetham sky: the export writes the sunsky's sky as Hosek-Wilkie's, so the daylight group
shows the two models' difference as well.
"""

import argparse
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "scenes", "exported", "lightgroups.lxs")
GROUPS = ["daylight", "ceiling", "fill"]


def exr_means(path, layer=None):
    """The mean R, G, B of an EXR (of its channels `layer.R/G/B` when a layer is named)."""
    import array
    import OpenEXR
    import Imath

    f = OpenEXR.InputFile(path)
    window = f.header()["dataWindow"]
    n = (window.max.x - window.min.x + 1) * (window.max.y - window.min.y + 1)
    pt = Imath.PixelType(Imath.PixelType.FLOAT)
    prefix = f"{layer}." if layer else ""
    means = []
    for c in "RGB":
        values = array.array("f", f.channel(prefix + c, pt))
        means.append(sum(values) / n)
    return means


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--luxcore-spp", type=int, default=256)
    ap.add_argument("--resolution", default="96x72")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    yat = os.path.join(ROOT, "target", "release", "yat")
    width, height = args.resolution.split("x")
    work = tempfile.mkdtemp(prefix="yat-light-groups-")
    rows = {}
    for transport in ["path", "bidirectional"]:
        out = os.path.join(work, f"yat-{transport}.png")
        subprocess.run([yat, "render", SCENE, "-o", out, "--spp", str(args.spp),
                        "--resolution", args.resolution, "--threads", str(args.threads),
                        "--integrator", transport, "--quiet"], check=True)
        exr = out[:-4] + ".exr"
        rows[f"YAT {transport}"] = [exr_means(exr, f"lightgroup.{g}") for g in GROUPS]
    export = os.path.join(work, "luxcore")
    subprocess.run([yat, "export-luxcore", SCENE, export], check=True, stdout=subprocess.DEVNULL)
    lux = os.path.join(work, "luxcore.exr")
    subprocess.run([sys.executable, os.path.join(ROOT, "bench", "luxcore.py"), export,
                    "--spp", str(args.luxcore_spp), "--depth", "5", "--threads", str(args.threads),
                    "--width", width, "--height", height, "--light-groups", str(len(GROUPS)),
                    "--out", lux, "--stats", os.path.join(work, "luxcore.json")], check=True)
    rows["LuxCore PATHCPU"] = [exr_means(f"{lux[:-4]}.group{g}.exr") for g in range(len(GROUPS))]

    luminance = lambda c: 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    reference = rows["LuxCore PATHCPU"]
    print(f"scenes/exported/lightgroups.lxs, {args.resolution}, YAT {args.spp} spp, "
          f"LuxCore {args.luxcore_spp} spp: each group's mean linear RGB")
    print(f"| group | renderer | mean R, G, B | luminance / LuxCore's |")
    print("|---|---|---|---|")
    for g, name in enumerate(GROUPS):
        for renderer, means in rows.items():
            m = means[g]
            ratio = luminance(m) / luminance(reference[g])
            print(f"| {name} | {renderer} | {m[0]:.4f}, {m[1]:.4f}, {m[2]:.4f} | {ratio:.3f} |")


if __name__ == "__main__":
    main()
