#!/usr/bin/env python3
"""Light transports side by side (issue 50, item 4): the time each renderer and engine takes to
reach one error against a converged reference, on scenes that stand for what LuxRender users
render. Per scene, at a small resolution of the Film's aspect, 2 threads:

- YAT path tracing (at max depth eyedepth + lightdepth, the longest path bidirectional makes)
  and YAT bidirectional (the scene's eyedepth and lightdepth);
- LuxCore 2.11 through `yat export-luxcore`: PATHCPU with SOBOL and with METROPOLIS, BIDIRCPU
  with SOBOL, RANDOM and METROPOLIS (the same depths);
- Mitsuba 3's path tracer (llvm_ad_rgb, its independent sampler) where bench/mitsuba3.py can
  convert the export (it has no bidirectional integrator).

Each engine renders two seeds at a sample count picked from a short calibration render so that
a render takes about --seconds. Its error is the per-pixel relative MSE (bench.clean_relmse:
each pixel's squared error over its squared value, so that the lamps seen directly and their
highlights, thousands of times the image mean, do not decide the figure) against its renderer's
most complete engine's converged reference (YAT bidirectional, LuxCore BIDIRCPU SOBOL, Mitsuba
path: a path tracer that misses light, delta-light caustics, pays for it), less the reference's
own noise (bench.reference_pair). Efficiency = 1 / (relMSE x render seconds); the time to a
relMSE of 1e-3 (about 3% RMS error in every pixel) follows from it, since for these estimators
the error falls as 1 / time. The plain MSE is printed too. "converged mean / YAT's" compares
each renderer's reference with YAT's over the lit scene (the brightest 0.5% of pixels, lamps seen
directly, left out): a renderer converging to another image is not timed against YAT's.

    python3 bench/efficiency.py                    # every scene, prints the tables
    python3 bench/efficiency.py --scenes lamps --seconds 4
    python3 bench/efficiency.py --write-results    # also writes its bench/RESULTS.md section

Renders are cached in target/bench-efficiency.json (by binary digest, scene and settings) and
references in target/bench-refs, so a run that stops goes on where it stopped.
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench  # noqa: E402  (the shared helpers: venv, measured runs, EXR, references)
import transports  # noqa: E402  (scene names and what `yat check` says will run)

CACHE = bench.TARGET / "bench-efficiency.json"
SECTION = "## Time to an error: path and bidirectional transports side by side"
SCENES = [
    "scenes/sunroom/sunroom.lxs", "scenes/lamps/lamps.lxs", "scenes/caustics/caustics.lxs",
    "CornellBox/cornell-box.lxs", "Benchmarks/GlassMediumTransparency.lxs",
    "MetalMario/metal-mario-bg1.lxs",
]
# The per-pixel relative MSE a time is quoted for.
TARGET_RELMSE = 1e-3
SEEDS = (1, 2)
CALIBRATION_SPP = 4
# (label, renderer, engine, sampler); the first of each renderer is its reference engine.
ENGINES = [
    ("YAT bidirectional", "yat", "bidirectional", "Owen-scrambled Sobol"),
    ("YAT path", "yat", "path", "Owen-scrambled Sobol"),
    ("LuxCore BIDIRCPU", "luxcore", "BIDIRCPU", "SOBOL"),
    ("LuxCore BIDIRCPU", "luxcore", "BIDIRCPU", "RANDOM"),
    ("LuxCore BIDIRCPU", "luxcore", "BIDIRCPU", "METROPOLIS"),
    ("LuxCore PATHCPU", "luxcore", "PATHCPU", "SOBOL"),
    ("LuxCore PATHCPU", "luxcore", "PATHCPU", "METROPOLIS"),
    ("Mitsuba 3 path", "mitsuba", "path", "independent"),
]


class Scene:
    """One scene as every renderer gets it: YAT's file, the LuxCore export, the Mitsuba XML."""

    def __init__(self, binary, name, width, tmp):
        self.binary, self.name = binary, name
        self.path = transports.scene_path(name)
        (fw, fh), self.eye, self.light = transports.what_runs(binary, self.path)
        self.size = (width, max(1, round(width * fh / fw)))
        self.notes = []
        self.export = tmp / "export"
        proc = subprocess.run([str(binary), "export-luxcore", str(self.path), str(self.export)],
                              capture_output=True, text=True)
        self.lux_ok = proc.returncode == 0
        if not self.lux_ok:
            self.notes.append(f"not exported to LuxCore: {proc.stderr.strip().splitlines()[-1]}")
            self.mi_ok = False
            return
        meshes = sorted((self.export / "meshes").glob("*.ply"))
        self.lux_key = bench.file_digest(self.export / "scene.scn", *meshes,
                                         bench.ROOT / "bench/luxcore.py")
        proc = subprocess.run([str(bench.VENV_PYTHON), str(bench.ROOT / "bench/mitsuba3.py"),
                               "convert", str(self.export), str(self.export)],
                              capture_output=True, text=True)
        self.mi_ok = proc.returncode == 0
        if self.mi_ok:
            self.xml = self.export / "scene.xml"
            self.mi_key = bench.file_digest(
                self.xml, *meshes, *sorted((self.export / "textures").glob("*")),
                bench.ROOT / "bench/mitsuba3.py")
        else:
            self.notes.append(f"not converted to Mitsuba: {proc.stderr.strip().splitlines()[-1]}")

    def available(self, renderer):
        return {"yat": True, "luxcore": self.lux_ok, "mitsuba": self.mi_ok}[renderer]

    def render(self, renderer, engine, sampler, spp, seed, out_dir, timed=True):
        """One render into out_dir (a timed one: Mitsuba compiles its kernels untimed first);
        returns (its figures, the path of its EXR)."""
        depth = self.eye + self.light
        if renderer == "yat":
            f = bench.render(self.path, spp, depth if engine == "path" else None, 2, out_dir,
                             seed, self.size, self.binary, ["--integrator", engine])
            return f, out_dir / "out.exr"
        if renderer == "luxcore":
            bidir = engine == "BIDIRCPU"
            f = bench.render_luxcore(self.export, spp, self.eye if bidir else depth, 2, out_dir,
                                     seed, self.size, engine=engine, sampler=sampler,
                                     light_depth=self.light if bidir else None)
            return f, out_dir / "lux.exr"
        f = bench.render_mitsuba(self.xml, "llvm_ad_rgb", sampler, spp, depth, 2, self.size,
                                 out_dir, seed, timed)
        return f, out_dir / "mitsuba.exr"

    def key(self, renderer):
        return {"yat": bench.file_digest(self.binary), "luxcore": getattr(self, "lux_key", ""),
                "mitsuba": getattr(self, "mi_key", "")}[renderer]

    def reference(self, renderer, engine, sampler, spp):
        """The renderer's reference pair (bench.reference_pair) at `spp` in all."""
        half = max(spp // 2, 1)

        def make(d, seed):
            bench.log(f"  {renderer} reference {self.name} ({engine}) at {half} spp, seed {seed}")
            _, image = self.render(renderer, engine, sampler, half, seed, d, timed=False)
            image.rename(d / "ref.exr")

        setting = (f"eff-{Path(self.name).stem}-{self.size[0]}x{self.size[1]}-{engine}-"
                   f"{half}spp")
        return bench.reference_pair(renderer, setting, self.key(renderer), make,
                                    seeds=(bench.REFERENCE_SEED, bench.REFERENCE_SEED + 1))


def measure(scene, label, renderer, engine, sampler, seconds, reference):
    """Calibrates the spp for `seconds`, renders SEEDS, returns the figures."""
    with tempfile.TemporaryDirectory() as tmp:
        f, _ = scene.render(renderer, engine, sampler, CALIBRATION_SPP, SEEDS[0], Path(tmp))
    per_spp = f["render_seconds"] / CALIBRATION_SPP
    spp = int(min(max(round(seconds / per_spp), 1), 1 << 16))
    runs = []
    for seed in SEEDS:
        with tempfile.TemporaryDirectory() as tmp:
            f, image = scene.render(renderer, engine, sampler, spp, seed, Path(tmp))
            pixels = bench.read_exr(image)
            runs.append((f["render_seconds"], bench.clean_mse(pixels, reference),
                         bench.clean_relmse(pixels, reference), f["samples_per_second"],
                         f.get("rays_per_second")))
    mean = [sum(r[i] for r in runs) / len(runs) for i in range(4)]
    bench.log(f"  {label} {sampler}: {spp} spp, {mean[0]:.2f} s, MSE {mean[1]:.3g}, "
              f"relMSE {mean[2]:.3g}")
    return {"label": label, "sampler": sampler, "spp": spp, "seconds": mean[0], "mse": mean[1],
            "relmse": mean[2], "samples_per_second": mean[3], "rays_per_second": runs[0][4]}


def compare(binary, name, width, seconds, ref_factor):
    import numpy as np

    with tempfile.TemporaryDirectory() as tmp:
        scene = Scene(binary, name, width, Path(tmp))
        refs, results = {}, []
        for label, renderer, engine, sampler in ENGINES:
            if not scene.available(renderer):
                continue
            if renderer not in refs:
                # The reference: ref_factor timed renders' worth of samples of this engine.
                with tempfile.TemporaryDirectory() as cal:
                    f, _ = scene.render(renderer, engine, sampler, CALIBRATION_SPP, SEEDS[0],
                                        Path(cal))
                per_spp = f["render_seconds"] / CALIBRATION_SPP
                spp = 2 * int(min(max(round(seconds * ref_factor / per_spp / 2), 1), 1 << 16))
                refs[renderer] = scene.reference(renderer, engine, sampler, spp)
            results.append(measure(scene, label, renderer, engine, sampler, seconds,
                                   refs[renderer]))
        # The lit scene's mean, not the lamps': the brightest 0.5% of YAT's pixels (lamps seen
        # directly and in mirrors, where a filter's or a film's edge handling decides) left out.
        yat = refs["yat"][0]
        lit = yat.mean(-1) <= np.quantile(yat.mean(-1), 0.995)
        return {
            "size": scene.size, "eye": scene.eye, "light": scene.light, "notes": scene.notes,
            "converged_vs_yat": {r: float(ref[0][lit].mean() / yat[lit].mean())
                                 for r, ref in refs.items()},
            "correlation_vs_yat": {r: bench.block_correlation(ref[0], refs["yat"][0])
                                   for r, ref in refs.items()},
            "results": results,
        }


def tables(all_results):
    rows, summary = [], []
    for name, r in all_results.items():
        eff = {(x["label"], x["sampler"]): 1 / (x["relmse"] * x["seconds"]) if x["relmse"] > 0
               else float("inf") for x in r["results"]}
        yat_bidir = eff[("YAT bidirectional", "Owen-scrambled Sobol")]
        for x in r["results"]:
            e = eff[(x["label"], x["sampler"])]
            renderer = x["label"].split()[0].lower()
            to_target = max(x["relmse"], 0) * x["seconds"] / TARGET_RELMSE
            rays = x["rays_per_second"]
            rows.append([
                name, f"{x['label']} {x['sampler']}", str(x["spp"]), f"{x['seconds']:.2f}",
                f"{x['samples_per_second'] / 1e6:.3f}",
                f"{rays / 1e6:.2f}" if rays else "-", f"{x['mse']:.3g}", f"{x['relmse']:.3g}",
                f"{to_target:.0f}", f"{yat_bidir / e:.2f}x",
                f"{r['converged_vs_yat'][renderer]:.3f}",
            ])

        def best(pred):
            keys = [k for k in eff if pred(k)]
            if not keys:
                return "-"
            k = max(keys, key=lambda k: eff[k])
            return f"{yat_bidir / eff[k]:.2f}x ({k[0]} {k[1]})"

        summary.append([
            name, f"{r['size'][0]}x{r['size'][1]}", f"{r['eye']}/{r['light']}",
            f"{yat_bidir / eff[('YAT path', 'Owen-scrambled Sobol')]:.2f}x",
            best(lambda k: k == ("LuxCore BIDIRCPU", "SOBOL")),
            best(lambda k: k[0].startswith("LuxCore")),
            best(lambda k: k[0].startswith("Mitsuba")),
        ])
    head = ["scene", "renderer, engine, sampler", "spp", "render s", "M samples/s", "M rays/s",
            "MSE", "relMSE", f"s to relMSE {TARGET_RELMSE:g}",
            "YAT bidirectional efficiency / this", "converged mean / YAT's (lit pixels)"]
    sum_head = ["scene", "size", "eye/light", "YAT bidir / YAT path", "YAT bidir / LuxCore "
                "BIDIRCPU SOBOL", "YAT bidir / LuxCore best", "YAT bidir / Mitsuba path"]
    return bench.table(sum_head, summary), bench.table(head, rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--scenes", help="comma-separated names or parts of names (default: "
                    + ", ".join(SCENES) + ")")
    ap.add_argument("--width", type=int, default=160, help="image width (160; the Film's aspect)")
    ap.add_argument("--seconds", type=float, default=8, help="seconds a timed render takes (8)")
    ap.add_argument("--ref-factor", type=float, default=12,
                    help="a reference's samples in timed renders' worth (12)")
    ap.add_argument("--binary", default=str(bench.YAT), help="the yat binary (default: release)")
    ap.add_argument("--write-results", action="store_true",
                    help="write this section of bench/RESULTS.md")
    args = ap.parse_args()
    bench.ensure_venv()
    names = [n for n in SCENES if n.startswith("scenes/") or (bench.SEED / n).exists()]
    if args.scenes:
        wanted = args.scenes.split(",")
        names = [n for n in names if any(w in n for w in wanted)]
    binary = Path(args.binary)
    digest = bench.file_digest(binary)
    cache = json.loads(CACHE.read_text()) if CACHE.exists() else {}
    results = {}
    for name in names:
        key = f"{name}|{args.width}|{args.seconds}|{args.ref_factor}|{digest}"
        if key not in cache:
            bench.log(f"{name}:")
            cache[key] = compare(binary, name, args.width, args.seconds, args.ref_factor)
            CACHE.parent.mkdir(parents=True, exist_ok=True)
            CACHE.write_text(json.dumps(cache, indent=1))
        results[name] = cache[key]
    summary, runs = tables(results)
    notes = [f"- {name}: {n}" for name, r in results.items() for n in r["notes"]]
    print(summary + "\n\n" + runs + ("\n\n" + "\n".join(notes) if notes else ""))
    if args.write_results:
        section = (f"{SECTION}\n\n{bench.machine()}; `python3 bench/efficiency.py --width "
                   f"{args.width} --seconds {args.seconds:g}`, 2 threads, two seeds a render. "
                   "Efficiency = 1 / (per-pixel relative MSE against the renderer's own most "
                   "complete engine's converged reference, less that reference's noise, x render "
                   "seconds); see the script's docstring.\n\n"
                   + summary + "\n\n" + runs + "\n" + ("\n" + "\n".join(notes) + "\n"
                                                      if notes else ""))
        results_md = bench.ROOT / "bench/RESULTS.md"
        results_md.write_text(bench.replace_section(results_md.read_text(), SECTION, section))


if __name__ == "__main__":
    main()
