#!/usr/bin/env python3
"""Time to a clean image: uniform and adaptive YAT against LuxCore and Mitsuba 3 (issue #21,
points 3 and 4).

For each compared seed scene at a reduced resolution (--resolution, 160x90 by default), path
depth 10, every renderer on the same --threads:

- References. Each renderer's converged reference is the mean of two uniform renders of
  --reference-spp / 2 samples with different seeds (7 and 8): YAT's, LuxCore's (PATHCPU, SOBOL
  at adaptive strength 0) and Mitsuba's (llvm_ad_rgb, independent sampler), cached in
  target/bench-refs. Every MSE below is taken against the renderer's OWN reference, minus that
  reference's own noise MSE(a, b) / 4 (a and b the two halves; see bench.reference_pair): what
  is left estimates the MSE against the true image, whichever reference it was measured
  against. MSE is per channel over all pixels of the linear EXR, as in bench.py.
- The target: that MSE of a uniform YAT render of --target-spp (1000).
- YAT adaptive: bisects --noise-threshold (on a log scale) toward the threshold whose image
  reaches the target; samples and CPU seconds to the target are interpolated (log-log, in MSE)
  between the two renders around it, or are the best render's when none is on the far side.
- LuxCore (PATHCPU, SOBOL at each --luxcore-strength; 0.95 is LuxCore's default adaptive
  strength, 0 samples every pixel alike) and Mitsuba 3 (llvm_ad_rgb, its fastest variant, with
  each --mitsuba-sampler, uniform; the gaussian filter bench/mitsuba3.py converts the scenes'
  Blackman-Harris to): rendered from YAT's export (`yat export-luxcore`) at a few spp, the
  first --target-spp / 4, each next one predicted from the two nearest to the target (log-log),
  until two renders bracket the target and the nearer is within 10% of it in MSE; spp and CPU
  seconds to the target are interpolated log-log between those two.
- CPU seconds: YAT's are its render process's (user + system; parsing and the BVH build, under
  a second here, included); LuxCore's and Mitsuba's are their process's CPU time (all threads)
  around the render itself, measured by bench/luxcore.py and bench/mitsuba3.py (loading, BVH
  and Mitsuba's JIT compilation excluded: Mitsuba's timed render follows an untimed one of the
  same spp, which compiles the kernels). CPU time is what to compare on a shared machine; wall
  time moves with the load. Samples are each renderer's own count.
- Caches. References: target/bench-refs, keyed by the renderer's input (YAT's binary, the
  export's files and the script). Every render's figures: target/bench-refs/time-to-clean.json,
  keyed by renderer, version, settings, reference, YAT's binary or the export's digest, and spp
  or threshold; a re-run with a new YAT binary re-renders only YAT (and YAT's reference, unless
  --reference-binary keeps the old binary for it), one with new settings only what they change.

--write-results writes the section "Time to a clean image against LuxCore and Mitsuba" of
bench/RESULTS.md (after the adaptive-sampling section; other sections are kept) and fills the
seed table's column "core-s to 1000-spp error, adaptive": the row's "ours core-s" (uniform
1000 spp at the seed's resolution) over the CPU-seconds speed-up measured here.

    python3 bench/adaptive.py --binary /tmp/yat                # four scenes at 160x90
    python3 bench/adaptive.py --binary target/fuzz/yat --reference-binary /tmp/ref-yat \\
        --only metal-mario --write-results
    python3 bench/adaptive.py --resolution 320x180 --reference-spp 2048 --rivals none

Prints Markdown tables.
"""

import argparse
import datetime
import importlib.metadata
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench  # noqa: E402  (the shared helpers: venv, measured runs, EXR, references)

SCENES = bench.COMPARED_SCENES
SECTION = "## Time to a clean image against LuxCore and Mitsuba"
# The section goes after the adaptive-sampling section it continues.
AFTER_SECTION = "## Adaptive sampling: samples to the error"
RENDERS_CACHE = bench.REFS / "time-to-clean.json"
# A rival's search stops once two renders bracket the target and the nearer one's MSE is within
# this factor of it: interpolating over at most that much keeps the interpolation's error small.
CLOSE_ENOUGH = 1.1


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


def cached_run(cache, key, variant, render):
    """render() -> (MSE, CPU seconds, mean spp), or the figures cached for the configuration
    `key` and its `variant` (the spp, the threshold: what the searches vary)."""
    done = cache.setdefault(key, {})
    if variant not in done:
        done[variant] = list(render())
        save_cache(cache)
    return tuple(done[variant])


def measure(yat_config, extra):
    """(MSE, CPU seconds, mean samples per pixel) of one YAT render with `extra` arguments;
    yat_config = (binary, scene, args, reference, cache, cache key)."""
    binary, scene, args, reference, cache, key = yat_config

    def render():
        with tempfile.TemporaryDirectory() as tmp:
            figures = yat(binary, scene, args, Path(tmp), extra)
            image = bench.read_exr(Path(tmp) / "out.exr")
        w, h = (int(v) for v in args.resolution.split("x"))
        return bench.clean_mse(image, reference), figures["cpu_seconds"], figures["samples"] / (w * h)

    return cached_run(cache, key, " ".join(extra), render)


def at_target(lo, hi, target):
    """Samples and CPU seconds at MSE `target`, interpolated log-log between the renders lo
    (MSE at most target) and hi (above it), each (error, seconds, spp); lo's own without hi."""
    if hi is None or hi[0] <= lo[0]:
        return lo[2], lo[1]
    t = math.log(hi[0] / target) / math.log(hi[0] / lo[0])
    return tuple(math.exp(math.log(h) + t * (math.log(l) - math.log(h)))
                 for l, h in ((lo[2], hi[2]), (lo[1], hi[1])))


def bracket(runs, target):
    """The render closest to the target at or under it, and the one closest above it."""
    below = [r for r in runs if r[0] <= target]
    above = [r for r in runs if r[0] > target]
    return (max(below, key=lambda r: r[0]) if below else None,
            min(above, key=lambda r: r[0]) if above else None)


def yat_adaptive(yat_config, target):
    """Bisects log(threshold) toward the target; returns (spp, CPU s, renders) or None."""
    args = yat_config[2]
    runs = []  # (error, seconds, spp, threshold)
    lo = hi = None
    threshold = args.start_threshold
    for _ in range(args.steps):
        error, seconds, spp = measure(yat_config, [
            "--spp", str(args.max_spp), "--min-spp", str(args.min_spp),
            "--noise-threshold", f"{threshold:.5g}",
        ])
        runs.append((error, seconds, spp, threshold))
        bench.log(f"  YAT adaptive threshold {threshold:.4g}: MSE {runs[-1][0]:.4g}, "
                  f"{seconds:.1f} CPU s, {spp:.0f} spp")
        lo, hi = bracket(runs, target)
        if lo is None:
            threshold /= 2
        elif hi is None:
            threshold *= 2
        else:
            threshold = math.sqrt(lo[3] * hi[3])
    if lo is None:
        return None
    spp, seconds = at_target(lo, hi, target)
    return spp, seconds, runs


def next_spp(runs, target, target_spp):
    """The spp predicted to reach the target from the two renders nearest to it (log-log; one
    render: MSE ~ 1/spp), nudged past it while every render is on one side of it."""
    near = sorted(runs, key=lambda r: abs(math.log(r[0] / target)))[:2]
    slope = -1.0
    if len(near) == 2 and near[0][2] != near[1][2] and near[0][0] != near[1][0]:
        slope = math.log(near[1][0] / near[0][0]) / math.log(near[1][2] / near[0][2])
        slope = min(max(slope, -2.0), -0.5)
    spp = near[0][2] * (target / near[0][0]) ** (1 / slope)
    lo, hi = bracket(runs, target)
    if lo is None:
        spp *= 1.08
    elif hi is None:
        spp /= 1.08
    return max(1, min(round(spp), 8 * target_spp))


class Rival:
    """One rival renderer configuration: a label, its cache key, render(spp) -> (MSE against
    its reference, render CPU s, mean spp), and the search for the target."""

    def __init__(self, label, key, render, cache):
        self.label, self.key, self.render, self.cache = label, key, render, cache

    def to_target(self, target, args):
        """(spp, CPU s, renders) to the target MSE, or (None, None, renders) if not reached."""
        done = self.cache.setdefault(self.key, {})
        runs = [tuple(r) for r in done.values()]  # (error, cpu s, mean spp)
        spp = max(1, args.target_spp // 4)
        new = 0
        while True:
            lo, hi = bracket(runs, target)
            if lo and hi and min(abs(math.log(r[0] / target)) for r in (lo, hi)) <= \
                    math.log(CLOSE_ENOUGH):
                break
            if runs:
                spp = next_spp(runs, target, args.target_spp)
            if str(spp) in done or new == args.rival_renders:
                break  # as close as the search gets (the prediction repeats a render), or
                # as many new renders as allowed
            error, seconds, mean_spp = cached_run(self.cache, self.key, str(spp),
                                                  lambda: self.render(spp))
            bench.log(f"  {self.label} {spp} spp: MSE {error:.4g}, {seconds:.1f} CPU s, "
                      f"{mean_spp:.0f} mean spp")
            runs.append((error, seconds, mean_spp))
            new += 1
        lo, hi = bracket(runs, target)
        if lo is None:
            return None, None, sorted(runs, key=lambda r: r[2])
        spp, seconds = at_target(lo, hi, target)
        return spp, seconds, sorted(runs, key=lambda r: r[2])


def load_cache():
    return json.loads(RENDERS_CACHE.read_text()) if RENDERS_CACHE.exists() else {}


def save_cache(cache):
    """Writes the figures merged into the file's: runs of other scenes may share the file."""
    merged = load_cache()
    for key, runs in cache.items():
        merged.setdefault(key, {}).update(runs)
    RENDERS_CACHE.parent.mkdir(parents=True, exist_ok=True)
    RENDERS_CACHE.write_text(json.dumps(merged, indent=1, sort_keys=True))


def rivals(scene, export, args, cache, size, yat_reference):
    """The LuxCore and Mitsuba configurations of one exported scene, and the agreement of their
    references with YAT's: ([Rival], [(renderer, mean ratio YAT / it, block correlation, its
    reference noise)])."""
    name = scene.stem
    res = args.resolution
    ref_half = args.reference_spp // 2
    setting = f"rivals-{name}-{res}-{ref_half}spp-d{args.depth}"
    meshes = sorted((export / "meshes").glob("*.ply"))
    xml = export / "scene.xml"
    lux_digest = bench.file_digest(export / "scene.scn", *meshes, bench.ROOT / "bench/luxcore.py")
    mi_digest = bench.file_digest(xml, *meshes, *sorted((export / "textures").glob("*")),
                                  bench.ROOT / "bench/mitsuba3.py")
    lux_version = importlib.metadata.version("pyluxcore")
    mi_version = importlib.metadata.version("mitsuba")

    # bench's renders, moved to d/ref.exr, the name bench.reference takes a reference from;
    # measured renders are read from there too.
    def lux_run(d, spp, seed, strength):
        figures = bench.render_luxcore(export, spp, args.depth, args.threads, d, seed, size,
                                       strength)
        (d / "lux.exr").rename(d / "ref.exr")
        return figures

    def mi_run(d, spp, seed, sampler, warm_up):
        figures = bench.render_mitsuba(xml, "llvm_ad_rgb", sampler, spp, args.depth,
                                       args.threads, size, d, seed, warm_up)
        (d / "mitsuba.exr").rename(d / "ref.exr")
        return figures

    bench.log(f"  LuxCore and Mitsuba references of {name} (2 x {ref_half} spp, cached) ...")
    lux_ref = bench.reference_pair("luxcore", setting, lux_digest,
                                   lambda d, seed: lux_run(d, ref_half, seed, 0))
    mi_ref = bench.reference_pair("mitsuba", setting, mi_digest,
                                  lambda d, seed: mi_run(d, ref_half, seed, "independent", False))
    agreement = [
        (f"LuxCore {lux_version}", float(yat_reference[0].mean() / lux_ref[0].mean()),
         bench.block_correlation(yat_reference[0], lux_ref[0]), lux_ref[1]),
        (f"Mitsuba {mi_version}", float(yat_reference[0].mean() / mi_ref[0].mean()),
         bench.block_correlation(yat_reference[0], mi_ref[0]), mi_ref[1]),
    ]

    def measured(run, reference):
        """render(spp) -> (clean MSE, render CPU s, mean spp) of one rival render."""
        def render(spp):
            with tempfile.TemporaryDirectory() as tmp:
                f = run(Path(tmp), spp)
                image = bench.read_exr(Path(tmp) / "ref.exr")
            return bench.clean_mse(image, reference), f["render_cpu_seconds"], f["spp"]
        return render

    common = f"{res}|d{args.depth}|t{args.threads}|ref{args.reference_spp}|seed{bench.SHORT_SEED}"
    out = []
    for strength in args.luxcore_strength if "luxcore" in args.rivals else []:
        out.append(Rival(
            f"LuxCore {lux_version} PATHCPU SOBOL, adaptive strength {strength:g}",
            f"{name}|luxcore-{lux_version}|sobol-{strength:g}|{common}|{lux_digest}",
            measured(lambda d, spp, s=strength: lux_run(d, spp, bench.SHORT_SEED, s), lux_ref),
            cache))
    for sampler in args.mitsuba_sampler if "mitsuba" in args.rivals else []:
        out.append(Rival(
            f"Mitsuba {mi_version} llvm_ad_rgb {sampler}",
            f"{name}|mitsuba-{mi_version}|llvm_ad_rgb-{sampler}|{common}|{mi_digest}",
            measured(lambda d, spp, s=sampler: mi_run(d, spp, bench.SHORT_SEED, s, True),
                     mi_ref),
            cache))
    return out, agreement


def export_scene(binary, scene, export):
    """YAT's export of the scene for LuxCore, converted for Mitsuba in the same folder."""
    for cmd in ([str(binary), "export-luxcore", str(scene), str(export)],
                [str(bench.VENV_PYTHON), str(bench.ROOT / "bench/mitsuba3.py"), "convert",
                 str(export), str(export)]):
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd[:3])} failed on {scene}: {proc.stderr.strip()}")


def runs_text(runs, fmt):
    return "; ".join(fmt(r) for r in runs)


def write_seed_column(path, measured, resolution):
    """Fills the seed table's adaptive column (bench.ADAPTIVE_COLUMN): per measured scene (file
    name to CPU speed-up), the row's "ours core-s" over the speed-up."""
    lines = path.read_text().split("\n")
    header = None
    for i, line in enumerate(lines):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("|"):
            header = None
        elif header is None:
            header = cells if bench.ADAPTIVE_COLUMN in cells else []
        elif header and cells[0] in measured:
            core_s = cells[header.index("ours core-s")]
            if re.fullmatch(r"[0-9]+", core_s):
                speedup = measured[cells[0]]
                cells[header.index(bench.ADAPTIVE_COLUMN)] = \
                    f"{float(core_s) / speedup:.0f} ({speedup:.2f}x at {resolution})"
                lines[i] = "| " + " | ".join(cells) + " |"
    path.write_text("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--resolution", default="160x90", help="WxH of every render (160x90)")
    ap.add_argument("--reference-spp", type=int, default=4096,
                    help="each reference's spp, the sum of its two halves (4096)")
    ap.add_argument("--target-spp", type=int, default=1000, help="the uniform YAT render whose "
                    "MSE every renderer must reach (1000)")
    ap.add_argument("--max-spp", type=int, default=None,
                    help="adaptive --spp, the most a pixel gets (default 4 x --target-spp)")
    ap.add_argument("--min-spp", type=int, default=16, help="adaptive --min-spp (16)")
    ap.add_argument("--depth", type=int, default=10, help="path depth (10, the seed's)")
    ap.add_argument("--threads", type=int, default=os.cpu_count(), help="render threads")
    ap.add_argument("--steps", type=int, default=5, help="YAT adaptive renders bisecting the "
                    "threshold (5)")
    ap.add_argument("--start-threshold", type=float, default=0.02,
                    help="the first threshold tried (0.02)")
    ap.add_argument("--luxcore-strength", type=float, action="append",
                    help="LuxCore SOBOL adaptive strengths to measure (repeatable; default 0.95)")
    ap.add_argument("--mitsuba-sampler", action="append",
                    help="Mitsuba llvm_ad_rgb samplers to measure (repeatable; default "
                    "multijitter)")
    ap.add_argument("--rival-renders", type=int, default=4,
                    help="most new renders per rival configuration (4)")
    ap.add_argument("--rivals", default="luxcore,mitsuba", help="the other renderers measured: "
                    "luxcore, mitsuba, both (the default, luxcore,mitsuba) or none")
    ap.add_argument("--binary", default=str(bench.YAT), help="the yat binary (default: release)")
    ap.add_argument("--reference-binary", help="the yat binary YAT's references are rendered "
                    "with (default: --binary); a uniform render does not depend on the adaptive "
                    "code, so a copy kept aside spares re-rendering them after each rebuild")
    ap.add_argument("--write-results", action="store_true", help="write this section of "
                    "bench/RESULTS.md and fill the seed table's adaptive column")
    ap.add_argument("--only", help="only scenes whose path contains this text")
    args = ap.parse_args()
    args.luxcore_strength = args.luxcore_strength or [0.95]
    args.mitsuba_sampler = args.mitsuba_sampler or ["multijitter"]
    args.max_spp = args.max_spp or 4 * args.target_spp
    bench.ensure_venv()
    binary = Path(args.binary)
    if binary == bench.YAT:
        bench.build()
    ref_binary = Path(args.reference_binary or binary)
    size = tuple(int(v) for v in args.resolution.split("x"))
    scenes = [s for s in SCENES if not args.only or args.only in s]
    cache = load_cache()

    blocks, measured = [], {}
    for rel in scenes:
        scene = bench.SEED / rel
        if not scene.exists():
            bench.log(f"{scene} not found: skipped")
            continue
        name = scene.stem
        load = os.getloadavg()

        def yat_half(d, seed):
            yat(ref_binary, scene, args, d, ["--spp", str(args.reference_spp // 2), "--seed",
                                             str(seed)])
            (d / "out.exr").rename(d / "ref.exr")

        bench.log(f"{name}: YAT reference (2 x {args.reference_spp // 2} spp, cached) ...")
        setting = f"rivals-{name}-{args.resolution}-{args.reference_spp // 2}spp-d{args.depth}"
        reference = bench.reference_pair("yat", setting, bench.file_digest(ref_binary, scene),
                                         yat_half)
        yat_key = (f"{name}|yat-{bench.file_digest(binary)}|{args.resolution}|d{args.depth}|"
                   f"t{args.threads}|ref{args.reference_spp}-{bench.file_digest(ref_binary)}")
        yat_config = (binary, scene, args, reference, cache, yat_key)
        target, uniform_s, _ = measure(yat_config, ["--spp", str(args.target_spp)])
        bench.log(f"{name}: YAT uniform {args.target_spp} spp MSE {target:.4g} "
                  f"(reference noise {reference[1]:.3g}) in {uniform_s:.1f} CPU s")
        adaptive = yat_adaptive(yat_config, target)
        ada_s = adaptive[1] if adaptive else None
        if adaptive:
            measured[scene.name] = uniform_s / ada_s

        def speedup(seconds):
            return f"{seconds / ada_s:.2f}x" if ada_s and seconds else "-"

        rows = [
            ["YAT uniform (Owen-scrambled Sobol)", f"{args.target_spp}: {target:.3g}, "
             f"{uniform_s:.1f} s", f"{args.target_spp}", f"{uniform_s:.1f}", speedup(uniform_s)],
            ["YAT adaptive (--noise-threshold bisected)",
             runs_text(adaptive[2], lambda r: f"{r[3]:.3g}: {r[2]:.0f} spp, {r[0]:.3g}, "
                       f"{r[1]:.1f} s") if adaptive else "",
             f"{adaptive[0]:.0f}" if adaptive else "not reached",
             f"{ada_s:.1f}" if adaptive else "-", "1.00x" if adaptive else "-"],
        ]
        agreement = []
        if args.rivals != "none":
            with tempfile.TemporaryDirectory() as tmp:
                export = Path(tmp) / "export"
                export_scene(binary, scene, export)
                configs, agreement = rivals(scene, export, args, cache, size, reference)
                for rival in configs:
                    spp, seconds, runs = rival.to_target(target, args)
                    rows.append([
                        rival.label,
                        runs_text(runs, lambda r: f"{r[2]:.0f}: {r[0]:.3g}, {r[1]:.1f} s"),
                        f"{spp:.0f}" if spp else "not reached",
                        f"{seconds:.1f}" if seconds else "-", speedup(seconds),
                    ])
        blocks.append(scene_block(name, target, reference[1], rows, agreement, args, binary,
                                  ref_binary, load))

    text = section(args, blocks)
    print(text)
    if args.write_results and blocks:
        path = bench.ROOT / "bench/RESULTS.md"
        old = path.read_text()
        path.write_text(bench.replace_section(old, SECTION, merge(old, text), AFTER_SECTION))
        write_seed_column(path, measured, args.resolution)
        bench.log(f"wrote the section \"{SECTION[3:]}\" and the seed table's adaptive column "
                  "of bench/RESULTS.md")


def scene_block(name, target, noise, rows, agreement, args, binary, ref_binary, load):
    """One scene's part of the section: when and with what it was measured, and its table."""
    agree = "".join(f" {who}'s reference: mean YAT / it {ratio:.3f}, block correlation "
                    f"{corr:.4f}, its noise {n / target:.2f}x the target." for who, ratio, corr, n
                    in agreement)
    header = ["renderer / sampler", "renders (spp: MSE, CPU s)", "spp to the target",
              "CPU s to it", "its CPU s / YAT adaptive's"]
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return f"""#### {name}

{args.resolution}, references {args.reference_spp} spp (2 x {args.reference_spp // 2}); measured
{when}, load average {load[0]:.1f} to {os.getloadavg()[0]:.1f}; YAT binary
{bench.file_digest(binary)}, YAT's reference by binary {bench.file_digest(ref_binary)} (digests);
adaptive `--min-spp {args.min_spp} --spp {args.max_spp}`, {args.steps} renders bisecting the
threshold from {args.start_threshold:g}. Target MSE {target:.3g}; YAT's reference noise
{noise / target:.2f}x the target.{agree}

{bench.table(header, rows)}
"""


def section(args, blocks):
    """The RESULTS.md section: how it was measured, then each scene's block."""
    return f"""{SECTION}

Issue #21, point 3: the CPU time each renderer needs to reach the error of a uniform
{args.target_spp}-spp YAT render of the same scene, by `bench/adaptive.py` (its docstring says
how): each renderer against its own converged reference, the mean of two renders of half the
reference's spp with different seeds, with that mean's own noise, MSE(a, b) / 4, subtracted
from every MSE; the rivals rendered at a few spp until two renders bracket the target, and spp
and CPU seconds to the target interpolated log-log between them. Machine: {bench.machine()},
{args.threads} render threads for every renderer, shared with other agents (CPU seconds move by
some 10% with the load; samples do not). CPU s: YAT's render process's (user + system, parse
and build included, under a second); LuxCore's and Mitsuba's process CPU time around the render
alone (no loading, no JIT compilation). Last command: `python3 bench/adaptive.py
{" ".join(sys.argv[1:])}`. The last column is each row's CPU seconds over YAT adaptive's: above
1, YAT adaptive reaches the target sooner.

{"".join(b + chr(10) for b in blocks)}"""


def merge(old, text):
    """The section as written now plus the scene blocks of the old one that this run did not
    measure (a run with --only replaces its scenes' blocks and keeps the others), in SCENES'
    order."""
    def blocks(t):
        return {b.split("\n", 1)[0][5:].strip(): b.rstrip("\n") + "\n"
                for b in re.split(r"(?m)^(?=#### )", t)[1:]}

    start = old.find(SECTION)
    end = old.find("\n## ", start + 1)
    kept = blocks(old[start:end if end >= 0 else len(old)]) if start >= 0 else {}
    kept.update(blocks(text))
    head = re.split(r"(?m)^#### ", text)[0]
    order = [Path(s).stem for s in SCENES]
    names = sorted(kept, key=lambda n: order.index(n) if n in order else len(order))
    return head + "\n".join(kept[n] for n in names)


if __name__ == "__main__":
    main()
