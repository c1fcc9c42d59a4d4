#!/usr/bin/env python3
"""How YAT's cost grows with the scene: generated meshes of 1, 4, 16 and 64 million triangles
(a rippled height field, written as binary PLY by this script), each rendered by YAT and loaded
and rendered by Mitsuba 3 (`llvm_ad_rgb`, the same mesh, camera, sky and spp), one process per
measurement. Prints, per size: YAT's parse and BVH-build seconds, peak memory (the process's
maximum resident set) and bytes per triangle, samples/s and rays/s; Mitsuba's load seconds
(PLY read and its BVH), peak memory and samples/s. Then one over-budget scene: YAT with a
memory budget below what the largest mesh needs, which must fail with a clear error before it
allocates.

    python3 bench/scale.py                       # 1, 4, 16, 64 M triangles
    python3 bench/scale.py --sizes 1,4 --spp 8   # fewer
    python3 bench/scale.py --plot bench/scale.png  # also the plot (matplotlib in bench/.venv)

Meshes are cached in target/scale (1.2 GB for 64 M triangles). Speed lives in benchmarks, not
in tests; run on a quiet machine.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
sys.dont_write_bytecode = True
import bench  # noqa: E402

CACHE = ROOT / "target/scale"
WIDTH, HEIGHT = 320, 180


def grid_side(triangles_m):
    """Vertices on a side of the grid of about `triangles_m` million triangles."""
    return int(round((triangles_m * 1e6 / 2) ** 0.5)) + 1


def mesh(triangles_m):
    """target/scale/grid-<N>m.ply: a square grid of about N million triangles over [-1, 1]^2,
    heights a sum of ripples, written in chunks (the 64 M mesh's arrays stay under 1 GB)."""
    import numpy as np

    path = CACHE / f"grid-{triangles_m}m.ply"
    if path.exists():
        return path
    CACHE.mkdir(parents=True, exist_ok=True)
    side = grid_side(triangles_m)
    vertices, faces = side * side, 2 * (side - 1) ** 2
    tmp = path.with_suffix(".tmp")
    with open(tmp, "wb") as f:
        f.write((
            "ply\nformat binary_little_endian 1.0\n"
            f"element vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
        ).encode())
        u = np.linspace(-1.0, 1.0, side, dtype=np.float32)
        for r in range(0, side, 1024):
            y = u[r:r + 1024, None]
            x = u[None, :]
            z = 0.05 * np.sin(17 * x) * np.cos(13 * y) + 0.02 * np.sin(61 * (x + y))
            xyz = np.stack(np.broadcast_arrays(x, y, z), -1).astype("<f4")
            f.write(xyz.tobytes())
        face = np.dtype([("n", "u1"), ("i", "<i4", 3)])
        for r in range(0, side - 1, 512):
            rows = np.arange(r, min(r + 512, side - 1), dtype=np.int64)
            c = np.arange(side - 1, dtype=np.int64)
            a = (rows[:, None] * side + c[None, :]).ravel()
            quads = np.empty(2 * a.size, dtype=face)
            quads["n"] = 3
            quads["i"][0::2] = np.stack([a, a + 1, a + side + 1], -1)
            quads["i"][1::2] = np.stack([a, a + side + 1, a + side], -1)
            f.write(quads.tobytes())
    tmp.rename(path)
    return path


def yat_scene(ply, directory):
    scene = directory / "scale.lxs"
    scene.write_text(
        f'Film "fleximage" "integer xresolution" [{WIDTH}] "integer yresolution" [{HEIGHT}]\n'
        'LookAt 0 -2.2 1.6  0 0 0  0 0 1\n'
        'Camera "perspective" "float fov" [40]\n'
        'WorldBegin\n'
        'LightSource "infinite" "color L" [1 1 1]\n'
        'Material "matte" "color Kd" [0.6 0.6 0.6]\n'
        f'Shape "plymesh" "string filename" ["{ply}"]\n'
        'WorldEnd\n')
    return scene


def mitsuba_scene(ply, directory, spp):
    scene = directory / "scale.xml"
    scene.write_text(f"""<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="10"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/><string name="fov_axis" value="smaller"/>
    <transform name="to_world"><lookat origin="0,-2.2,1.6" target="0,0,0" up="0,0,1"/></transform>
    <sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
    <film type="hdrfilm"><integer name="width" value="{WIDTH}"/><integer name="height" value="{HEIGHT}"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="ply"><string name="filename" value="{ply}"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
</scene>
""")
    return scene


MITSUBA_CHILD = r"""
import json, os, resource, sys, time
sys.path.insert(0, sys.argv[3])
import mitsuba3
os.environ.setdefault("DRJIT_LIBLLVM_PATH", mitsuba3.libllvm() or "")
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
import drjit as dr
dr.set_thread_count(int(sys.argv[2]))
t0 = time.perf_counter()
scene = mi.load_file(sys.argv[1])
load = time.perf_counter() - t0
# An untimed render of the same size first: the JIT's kernels compiled and cached.
warm = mi.render(scene, seed=1)
dr.eval(warm)
dr.sync_thread()
t1 = time.perf_counter()
image = mi.render(scene, seed=0)
dr.eval(image)
dr.sync_thread()
render = time.perf_counter() - t1
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"load_seconds": load, "render_seconds": render, "peak_bytes": peak}))
"""


def run_mitsuba(xml, threads):
    out = subprocess.run(
        [str(bench.VENV_PYTHON), "-c", MITSUBA_CHILD, str(xml), str(threads), str(ROOT / "bench")],
        capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def run_yat(scene, spp, threads):
    """One YAT render; its figures, peak_rss_mb the process's own (bench.run_measured)."""
    with tempfile.TemporaryDirectory() as d:
        return bench.render(scene, spp, None, threads, Path(d))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1,4,16,64", help="millions of triangles")
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--plot", type=Path, help="write a PNG plot here (needs matplotlib)")
    parser.add_argument("--no-mitsuba", action="store_true")
    args = parser.parse_args()
    if not args.no_mitsuba:
        bench.ensure_venv()
    # Errors as their message, not a backtrace (anyhow prints one when RUST_BACKTRACE is set).
    os.environ["RUST_BACKTRACE"] = "0"
    sizes = [int(s) for s in args.sizes.split(",")]
    rows = []
    with tempfile.TemporaryDirectory() as d:
        directory = Path(d)
        for size in sizes:
            ply = mesh(size)
            scene = yat_scene(ply, directory)
            row = {"size_m": size, "triangles": 2 * (grid_side(size) - 1) ** 2}
            try:
                y = run_yat(scene, args.spp, args.threads)
                row.update({
                    "yat_parse_s": y["parse_seconds"],
                    "yat_build_s": y["build_seconds"],
                    "yat_peak_bytes": y["peak_rss_mb"] * 2**20,
                    "yat_samples_per_s": y["samples_per_second"],
                    "yat_rays_per_s": y["rays_per_second"],
                })
            except RuntimeError as e:
                row["yat_error"] = " ".join(str(e).split())[-400:]
            if not args.no_mitsuba:
                try:
                    m = run_mitsuba(mitsuba_scene(ply, directory, args.spp), args.threads)
                    row.update({
                        "mitsuba_load_s": m["load_seconds"],
                        "mitsuba_peak_bytes": m["peak_bytes"],
                        "mitsuba_samples_per_s": WIDTH * HEIGHT * args.spp / m["render_seconds"],
                    })
                except subprocess.CalledProcessError as e:
                    row["mitsuba_error"] = " ".join(e.stderr.split())[-300:]
            rows.append(row)
            print(json.dumps(row), flush=True)
        # A budget below what the largest mesh YAT rendered needed: refused before the build
        # allocates, with the reason.
        rendered = [r for r in rows if "yat_peak_bytes" in r]
        if rendered:
            budget_mib = max(64, int(rendered[-1]["yat_peak_bytes"] / 2**20 / 4))
            largest = yat_scene(mesh(rendered[-1]["size_m"]), directory)
            t0 = time.perf_counter()
            refused = subprocess.run(
                [str(bench.YAT), "render", str(largest), "-o", str(directory / "x.png"),
                 "--quiet", "--spp", "1", "--max-memory-mib", str(budget_mib)],
                capture_output=True, text=True)
            refused_s = time.perf_counter() - t0
    print()
    header = ["M triangles", "YAT parse s", "YAT build s", "YAT peak MB", "YAT B/triangle",
              "YAT M samples/s", "YAT M rays/s"]
    if not args.no_mitsuba:
        header += ["Mitsuba load s", "Mitsuba peak MB", "Mitsuba B/triangle",
                   "Mitsuba M samples/s"]
    table = []
    for r in rows:
        t = r["triangles"]
        line = [f"{t / 1e6:.1f}"]
        if "yat_error" in r:
            line += ["refused"] * 6
        else:
            line += [f"{r['yat_parse_s']:.2f}", f"{r['yat_build_s']:.2f}",
                     f"{r['yat_peak_bytes'] / 1e6:.0f}", f"{r['yat_peak_bytes'] / t:.0f}",
                     f"{r['yat_samples_per_s'] / 1e6:.3f}", f"{r['yat_rays_per_s'] / 1e6:.2f}"]
        if not args.no_mitsuba:
            if "mitsuba_error" in r:
                line += ["failed"] * 4
            else:
                line += [f"{r['mitsuba_load_s']:.2f}", f"{r['mitsuba_peak_bytes'] / 1e6:.0f}",
                         f"{r['mitsuba_peak_bytes'] / t:.0f}",
                         f"{r['mitsuba_samples_per_s'] / 1e6:.3f}"]
        table.append(line)
    print(bench.table(header, table))
    print(f"\nmachine: {bench.machine()}; {args.threads} threads; {WIDTH}x{HEIGHT}, "
          f"{args.spp} spp; peak memory is each process's maximum resident set")
    for r in rows:
        for who in ("yat", "mitsuba"):
            if f"{who}_error" in r:
                print(f"{r['size_m']} M triangles, {who}: {r[who + '_error']}")
    if rendered:
        message = " ".join(refused.stderr.split())
        print(f"over budget (--max-memory-mib {budget_mib}, {rendered[-1]['size_m']} M "
              f"triangles): exit {refused.returncode} after {refused_s:.2f} s: {message}")
    if args.plot:
        plot(rows, args.plot, not args.no_mitsuba)


def plot(rows, path, mitsuba):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    yat = [r for r in rows if "yat_peak_bytes" in r]
    tris = [r["triangles"] / 1e6 for r in yat]
    left.plot(tris, [r["yat_parse_s"] + r["yat_build_s"] for r in yat], "o-",
              label="YAT parse + build")
    right.plot(tris, [r["yat_peak_bytes"] / 1e9 for r in yat], "o-", label="YAT")
    if mitsuba:
        mi = [r for r in rows if "mitsuba_peak_bytes" in r]
        tris = [r["triangles"] / 1e6 for r in mi]
        left.plot(tris, [r["mitsuba_load_s"] for r in mi], "s-", label="Mitsuba 3 load")
        right.plot(tris, [r["mitsuba_peak_bytes"] / 1e9 for r in mi], "s-", label="Mitsuba 3")
    for ax, label in ((left, "seconds"), (right, "peak memory, GB")):
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel("million triangles")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle(f"Scene size: {bench.machine()}")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
