#!/usr/bin/env python3
"""YAT's benchmark: renders a fixed list of scenes at a fixed spp and depth with the release
binary and prints, per scene, resolution, spp, parse/build time, render time, samples/s, rays/s,
peak memory and core-seconds per sample; sets our time for the seed scenes (scaled to 1000 spp)
beside the original tracer's published table; and renders the compared seed scenes with
LuxCoreRender and Mitsuba 3 too (same machine, threads, resolution, spp and depth), reporting
samples/s and Monte Carlo efficiency 1 / (MSE against the renderer's own converged reference x
render seconds).

    python3 bench/bench.py                 # everything, writes bench/RESULTS.md
    python3 bench/bench.py --quick         # fewer samples, no side by side, prints only
    python3 bench/bench.py --no-compare    # our scenes and the seed table only
    python3 bench/bench.py --compare-only  # only the side by side: rewrites its section of
                                           # bench/RESULTS.md (up to the next "## " heading),
                                           # keeps every other section

The side by side runs bench/setup-env.sh first (the virtualenv bench/.venv with pyluxcore,
mitsuba, numpy and OpenEXR, and Debian's libllvm19 for Mitsuba's llvm variant) and re-runs
itself in that virtualenv. Scenes go to LuxCore through `yat export-luxcore` and on to Mitsuba
through bench/mitsuba3.py's converter. Converged references are cached in target/bench-refs
(keyed by scene, resolution, spp and depth, and by YAT's binary, the exported scene or the
converted scene). Speed lives here, never in timed tests.
"""

import argparse
import datetime
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SEED = Path(os.environ.get("YAT_SEED_SCENES", ROOT.parent / "shared/seed-project/scenes"))
# Cargo's target folder (CARGO_TARGET_DIR when set, as build() builds there).
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
YAT = TARGET / "release/yat"
# The profile-optimised build of deploy/build-pgo.sh (`--pgo`).
PGO_YAT = ROOT / "target/pgo/yat"
VENV = ROOT / "bench/.venv"
VENV_PYTHON = VENV / "bin/python"
SETUP = ROOT / "bench/setup-env.sh"
REFS = TARGET / "bench-refs"

# Seed scenes rendered by YAT, LuxCore and Mitsuba 3, all at one resolution (a quarter of the
# pixels of 960x540; the same aspect as every one of them). The fisheye scenes are left out
# (neither LuxCore nor Mitsuba has the course's fisheye camera).
COMPARED_SCENES = [
    "CornellBox/cornell-box.lxs",
    "DepthOfField/depth-of-field-high.lxs",
    "MetalMario/metal-mario-bg1.lxs",
    "CaptainFalcon/captainfalcon.lxs",
]
COMPARED_RESOLUTION = (480, 270)
MITSUBA_VARIANTS = ["scalar_rgb", "llvm_ad_rgb"]
# Mitsuba's default sampler and its two stratified ones.
MITSUBA_SAMPLERS = ["independent", "multijitter", "ldsampler"]
# Mitsuba's converged reference: any sampler converges to the same image; the vectorised
# variant gets there soonest.
MITSUBA_REFERENCE = ("llvm_ad_rgb", "independent")
SHORT_SEED, REFERENCE_SEED = 1, 7

# (scene relative to its root, the original tracer's published time at 1000 spp on 8 cores in
# seconds from the seed project's README, and its samples/s on this bench's 2-core machine
# with 2 threads, depth 10, or None where it was not measured). The second is the original
# rebuilt from its public source and run here (figures from the project's LuxCore notes); set
# beside its published time it says how much faster this hardware runs the same program, so
# the table can tell our lead from the hardware's.
SEED_TABLE = [
    ("DepthOfField/depth-of-field-control.lxs", 9 * 60 + 45, None),
    ("DepthOfField/depth-of-field-low.lxs", 9 * 60 + 36, None),
    ("DepthOfField/depth-of-field-high.lxs", 9 * 60 + 25, 0.69e6),
    ("CornellBoxFisheye/cornell-box-fisheye-low-fov.lxs", 17 * 60 + 36, None),
    ("CornellBoxFisheye/cornell-box-fisheye.lxs", 14 * 60 + 14, 0.29e6),
    ("CornellBoxFisheye/cornell-box-fisheye-high-fov.lxs", 8 * 60 + 11, None),
    ("CornellBox/cornell-box.lxs", 19 * 60 + 19, 0.37e6),
    ("MetalMario/metal-mario-wall.lxs", 54 * 60 + 29, None),
    ("MetalMario/metal-mario-bg1.lxs", 10 * 60 + 26, 0.40e6),
    ("MetalMario/metal-mario-bg2.lxs", 10 * 60 + 18, None),
    ("MetalMario/metal-mario-bg3.lxs", 10 * 60 + 29, None),
    ("MetalMario/metal-mario-bg4.lxs", 10 * 60 + 23, None),
    ("CaptainFalcon/captainfalcon.lxs", 2 * 3600 + 47 * 60 + 55, 0.11e6),
    ("GokuSelfie/goku-selfie.lxs", 18 * 60 + 18, None),
    ("Ornstein/ornstein.lxs", 30 * 60 + 29, None),
]
ORIGINAL_CORES = 8
ORIGINAL_MEASURED_THREADS = 2
# The original's `-s 1000` draws floor(sqrt(1000))^2 jittered camera rays per pixel.
ORIGINAL_RAYS_PER_PIXEL = 961

OWN_SCENES = [
    "cornell/cornell-box.lxs",
    "cornell/cornell-fisheye-60.lxs",
    "dof/dof-0.1.lxs",
    "envmap/envmap-hdr.lxs",
    "materials/materials.lxs",
    "heavy/heavy.lxs",
]


def build(pgo=False):
    if pgo:
        subprocess.run([str(ROOT / "deploy/build-pgo.sh")], cwd=ROOT, check=True)
    else:
        subprocess.run(["cargo", "build", "--release", "-p", "yat"], cwd=ROOT, check=True)
    if not (ROOT / "scenes/heavy/heavy.ply").exists():
        subprocess.run(
            ["cargo", "run", "--release", "-p", "yat-tracer", "--example", "make_scene_assets"],
            cwd=ROOT,
            check=True,
        )


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def ensure_venv():
    """Re-runs the script that was started (this one, or one importing it such as
    bench/adaptive.py) inside bench/.venv, made or brought up to date by SETUP first."""
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    subprocess.run([str(SETUP)], check=True)
    script = str(Path(sys.argv[0]).resolve())
    os.execv(str(VENV_PYTHON), [str(VENV_PYTHON), script, *sys.argv[1:]])


def run_measured(cmd, what, stats):
    """Runs a render process; returns its JSON figures plus wall time and child peak RSS."""
    start = datetime.datetime.now()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    # wait4 gives this child's own rusage (peak RSS), not the sum over all children.
    _, status, usage = os.wait4(proc.pid, 0)
    wall = (datetime.datetime.now() - start).total_seconds()
    err = proc.stderr.read().decode(errors="replace")
    if status != 0:
        raise RuntimeError(f"{what} failed ({status}): {err.strip()[-500:]}")
    figures = json.loads(Path(stats).read_text())
    figures["wall_seconds"] = wall
    figures["cpu_seconds"] = usage.ru_utime + usage.ru_stime
    figures["peak_rss_mb"] = usage.ru_maxrss / 1024
    return figures


def render(scene, spp, depth, threads, out_dir, seed=0, size=None, binary=None, extra=()):
    """One YAT render in-process on `threads` threads (at `size`, else the Film's; at max depth
    `depth`, else the scene's; with `binary`, else the release build; `extra` further options);
    writes out_dir/out.png and out.exr. No previews or checkpoints: the figures time rendering,
    and the other renderers write nothing meanwhile either."""
    stats = out_dir / "stats.json"
    cmd = [
        str(binary or YAT), "render", str(scene), "--quiet", "--spp", str(spp),
        "--threads", str(threads), "--seed", str(seed), "--stats-json", str(stats),
        "-o", str(out_dir / "out.png"), "--exr", "--preview-every", "0", "--checkpoint-every", "0",
        *extra,
    ] + (["--maxdepth", str(depth)] if depth is not None else []) \
      + (["--resolution", f"{size[0]}x{size[1]}"] if size else [])
    return run_measured(cmd, f"yat on {scene}", stats)


def render_luxcore(export_dir, spp, depth, threads, out_dir, seed, size, strength=None,
                   engine="PATHCPU", sampler="SOBOL", light_depth=None):
    """One LuxCore render of an exported scene at `size` with `engine` and `sampler` (BIDIRCPU:
    `depth` the eye path's, `light_depth` the light path's), with the SOBOL sampler's adaptive
    `strength` (default: LuxCore's); writes out_dir/lux.exr."""
    stats = out_dir / "lux.json"
    cmd = [
        str(VENV_PYTHON), str(ROOT / "bench/luxcore.py"), str(export_dir), "--spp", str(spp),
        "--depth", str(depth), "--threads", str(threads), "--seed", str(seed),
        "--width", str(size[0]), "--height", str(size[1]), "--engine", engine,
        "--sampler", sampler, "--out", str(out_dir / "lux.exr"), "--stats", str(stats),
    ] + (["--adaptive-strength", str(strength)] if strength is not None else []) \
      + (["--light-depth", str(light_depth)] if light_depth is not None else [])
    return run_measured(cmd, f"LuxCore on {export_dir}", stats)


def read_exr(path):
    import numpy as np
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        channels = f.channels()
        if "RGB" in channels:
            return np.asarray(channels["RGB"].pixels, dtype=np.float64)[..., :3]
        return np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def file_digest(*paths):
    h = hashlib.sha256()
    for p in paths:
        h.update(Path(p).read_bytes())
    return h.hexdigest()[:16]


def reference(kind, setting, digest, make):
    """A converged reference image, cached in REFS per renderer, scene setting and input digest;
    `make(dir)` renders it into dir/ref.exr. A new digest replaces the setting's older references,
    which no binary can reproduce any more."""
    path = REFS / f"{kind}-{setting}-{digest}.exr"
    if not path.exists():
        REFS.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory() as tmp:
            make(Path(tmp))
            shutil.move(Path(tmp) / "ref.exr", path)
        for stale in REFS.glob(f"{kind}-{setting}-*.exr"):
            if stale != path:
                stale.unlink()
    return read_exr(path)


def reference_pair(kind, setting, digest, make_half, seeds=(REFERENCE_SEED, REFERENCE_SEED + 1)):
    """A converged reference as the mean of two independent renders (`make_half(dir, seed)`
    renders one into dir/ref.exr; each cached by reference()), and the mean's own noise: the
    expected squared error each pixel of the mean carries, MSE(a, b) / 4 (a and b differ by
    twice a half's noise; the mean carries half a half's), and the two halves. An MSE against
    the mean minus that noise is the MSE against the true image, whichever renderer's reference
    it is."""
    a, b = (reference(kind, f"{setting}-seed{seed}", digest, lambda d, s=seed: make_half(d, s))
            for seed in seeds)
    return (a + b) / 2, mse(a, b) / 4, (a, b)


def mse(image, ref):
    """Mean squared error per channel over all pixels."""
    import numpy as np

    return float(np.mean((image - ref) ** 2))


def clean_mse(image, reference):
    """MSE against a reference pair's mean (reference_pair), minus the mean's own noise."""
    mean, noise, _ = reference
    return mse(image, mean) - noise


def clean_relmse(image, reference, floor=0.1):
    """Per-pixel relative MSE, (image - mean)^2 / (mean^2 + (floor x the image mean)^2) over
    pixels and channels, against a reference pair (reference_pair) less each pixel's share of its
    noise. Unlike the MSE, a few pixels far brighter than the rest (a lamp seen directly, its
    highlights) do not decide it: every pixel's error counts relative to its own brightness, the
    floor keeping the darkest from counting without bound."""
    import numpy as np

    mean, _, (a, b) = reference
    # The weight from the reference's 3x3 box mean: weighed by its own noisy value, a pixel's
    # noise would set its weight and its error together, which biases the difference.
    h, w = mean.shape[:2]
    padded = np.pad(mean, ((1, 1), (1, 1), (0, 0)), mode="edge")
    smooth = sum(padded[i:i + h, j:j + w] for i in range(3) for j in range(3)) / 9
    weight = 1 / (smooth ** 2 + (floor * mean.mean()) ** 2)
    return float(np.mean(((image - mean) ** 2 - (a - b) ** 2 / 4) * weight))


def block_correlation(a, b, block=16):
    """Correlation of block-mean luminance: the same picture, whatever the noise."""
    import numpy as np

    def blocks(x):
        h, w = x.shape[0] // block * block, x.shape[1] // block * block
        y = x[:h, :w].mean(-1).reshape(h // block, block, w // block, block).mean((1, 3))
        return y.ravel()

    return float(np.corrcoef(blocks(a), blocks(b))[0, 1])


def render_mitsuba(xml, variant, sampler, spp, depth, threads, size, out_dir, seed, warm_up):
    """One Mitsuba 3 render of a converted scene; writes out_dir/mitsuba.exr."""
    stats = out_dir / "mitsuba.json"
    cmd = [
        str(VENV_PYTHON), str(ROOT / "bench/mitsuba3.py"), "render", str(xml), "--variant",
        variant, "--sampler", sampler, "--spp", str(spp), "--depth", str(depth), "--threads",
        str(threads), "--width", str(size[0]), "--height", str(size[1]), "--seed", str(seed),
        "--out", str(out_dir / "mitsuba.exr"), "--stats", str(stats),
    ] + (["--warm-up"] if warm_up else [])
    return run_measured(cmd, f"Mitsuba {variant} {sampler} on {xml}", stats)


def side_by_side(args):
    """YAT, LuxCore and Mitsuba 3 (both variants, three samplers) on COMPARED_SCENES at
    COMPARED_RESOLUTION; returns the Markdown tables and the export notes."""
    import numpy as np

    size = COMPARED_RESOLUTION
    res = f"{size[0]}x{size[1]}"
    spp, ref_spp = args.compare_spp, args.ref_spp
    yat_key = file_digest(YAT)
    runs, summary, notes = [], [], []
    for rel in COMPARED_SCENES:
        if args.only and args.only not in rel:
            continue
        scene = SEED / rel
        name = scene.name
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            export = tmp / "export"
            proc = subprocess.run(
                [str(YAT), "export-luxcore", str(scene), str(export)],
                capture_output=True, text=True,
            )
            if proc.returncode != 0:
                notes.append(f"{name}: not compared: {proc.stderr.strip().splitlines()[-1]}")
                continue
            notes += [f"{name}: {line[6:]}" for line in proc.stderr.splitlines()
                      if line.startswith("note: ")]
            proc = subprocess.run(
                [str(VENV_PYTHON), str(ROOT / "bench/mitsuba3.py"), "convert", str(export),
                 str(export)],
                capture_output=True, text=True,
            )
            if proc.returncode != 0:
                notes.append(f"{name}: not compared: {proc.stderr.strip().splitlines()[-1]}")
                continue
            xml = export / "scene.xml"
            meshes = sorted((export / "meshes").glob("*.ply"))
            lux_key = file_digest(export / "scene.scn", *meshes, ROOT / "bench/luxcore.py")
            mi_key = file_digest(xml, *meshes, *sorted((export / "textures").glob("*")),
                                 ROOT / "bench/mitsuba3.py")

            # Each reference is the mean of two renders of half its samples (other seeds than
            # the timed renders'): the MSE against it less its own noise is the MSE against the
            # converged image. A reference of a few hundred samples still carries an eighth or
            # so of a 16-spp render's error, more for a noisier sampler: left in, it would count
            # against whichever renderer it belongs to.
            half = max(ref_spp // 2, 1)

            def yat_ref(d, seed):
                log(f"  YAT reference {name} at {half} spp, seed {seed} ...")
                render(scene, half, args.depth, args.threads, d, seed, size)
                (d / "out.exr").rename(d / "ref.exr")

            def lux_ref(d, seed):
                log(f"  LuxCore reference {name} at {half} spp, seed {seed} ...")
                render_luxcore(export, half, args.depth, args.threads, d, seed, size)
                (d / "lux.exr").rename(d / "ref.exr")

            def mi_ref(d, seed):
                log(f"  Mitsuba reference {name} at {half} spp, seed {seed} ...")
                render_mitsuba(xml, MITSUBA_REFERENCE[0], MITSUBA_REFERENCE[1], half,
                               args.depth, args.threads, size, d, seed, False)
                (d / "mitsuba.exr").rename(d / "ref.exr")

            setting = f"{name}-{res}-{half}spp-d{args.depth}"
            y_ref = reference_pair("yat", setting, yat_key, yat_ref)
            l_ref = reference_pair("luxcore", setting, lux_key, lux_ref)
            m_ref = reference_pair("mitsuba", setting, mi_key, mi_ref)

            load = os.getloadavg()[0]
            log(f"comparing {name} at {spp} spp (load {load:.1f}, {args.compare_rounds} rounds) ...")
            # (label from figures, sampler, render, its image, its reference)
            jobs = [(lambda f: "YAT", "Owen-scrambled Sobol",
                     lambda: render(scene, spp, args.depth, args.threads, tmp, SHORT_SEED, size),
                     tmp / "out.exr", y_ref),
                    (lambda f: f"LuxCore {f['pyluxcore']} PATHCPU", None,
                     lambda: render_luxcore(export, spp, args.depth, args.threads, tmp,
                                            SHORT_SEED, size),
                     tmp / "lux.exr", l_ref)]
            for variant in MITSUBA_VARIANTS:
                for sampler in MITSUBA_SAMPLERS:
                    jobs.append((
                        lambda f, v=variant: f"Mitsuba {f['mitsuba']} {v}", sampler,
                        lambda v=variant, s=sampler: render_mitsuba(
                            xml, v, s, spp, args.depth, args.threads, size, tmp, SHORT_SEED, True),
                        tmp / "mitsuba.exr", m_ref))
            # Rounds interleave the renderers, so a change in the machine's speed between them
            # falls on all alike. Each renderer and sampler is timed by its median run: on this
            # shared virtual machine one renderer's runs spread by 20-50% with nothing else
            # running, and the fastest of a few is a lottery that the best of three samplers
            # (three times the draws) wins more often than YAT's one sampler does.
            timed = [[] for _ in jobs]
            for _ in range(args.compare_rounds):
                for job_runs, (_, _, run, image, ref) in zip(timed, jobs):
                    f = run()
                    job_runs.append((f, clean_mse(read_exr(image), ref)))
            results = []  # (renderer, sampler, figures of the median run, mse, fastest s, ref)
            for job_runs, (label, sampler, _, _, ref) in zip(timed, jobs):
                job_runs.sort(key=lambda r: r[0]["render_seconds"])
                f, e = job_runs[(len(job_runs) - 1) // 2]
                fastest = job_runs[0][0]["render_seconds"]
                results.append((label(f), sampler or f["sampler"], f, e, fastest, ref))
                log(f"  {results[-1][0]} {results[-1][1]}: "
                    f"{[round(r[0]['render_seconds'], 2) for r in job_runs]} s, MSE {e:.3g}")
            effs = [1 / (e * f["render_seconds"]) for _, _, f, e, _, _ in results]
            effs_fastest = [1 / (e * fastest) for _, _, _, e, fastest, _ in results]
            for (who, sampler, f, e, fastest, ref), eff in zip(results, effs):
                rays = f.get("rays_per_second")
                runs.append([
                    name, who, sampler, f"{f['render_seconds']:.2f} ({fastest:.2f})",
                    f"{f['samples_per_second'] / 1e6:.3f}",
                    f"{rays / 1e6:.2f}" if rays else "-", f"{e:.3g}", f"{ref[1]:.2g}",
                    f"{eff:.3g}",
                    f"{effs[0] / eff:.2f}x",
                ])

            def best(variant):
                i = max((i for i, r in enumerate(results) if r[0].endswith(variant)),
                        key=lambda i: effs[i])
                fastest = max(effs_fastest[i] for i, r in enumerate(results)
                              if r[0].endswith(variant))
                return (f"{effs[0] / effs[i]:.2f}x ({results[i][1]}; fastest runs "
                        f"{effs_fastest[0] / fastest:.2f}x)")

            summary.append([
                name, res, f"{spp} / {ref_spp}", f"{load:.1f}",
                f"{y_ref[0].mean() / l_ref[0].mean():.3f}",
                f"{block_correlation(y_ref[0], l_ref[0]):.4f}",
                f"{y_ref[0].mean() / m_ref[0].mean():.3f}",
                f"{block_correlation(y_ref[0], m_ref[0]):.4f}",
                f"{effs[0] / effs[1]:.2f}x", best("scalar_rgb"), best("llvm_ad_rgb"),
            ])
    runs_table = table(
        ["scene", "renderer", "sampler", "render s (fastest)", "M samples/s", "M rays/s", "MSE",
         "its reference's noise", "efficiency", "YAT efficiency / this"],
        runs,
    )
    summary_table = table(
        ["scene", "resolution", "spp / ref spp", "load", "mean YAT / LuxCore (refs)",
         "block corr", "mean YAT / Mitsuba (refs)", "block corr",
         "efficiency YAT / LuxCore", "YAT / Mitsuba scalar best", "YAT / Mitsuba llvm best"],
        summary,
    )
    return runs_table, summary_table, notes


def replace_section(text, heading, section, after=None):
    """`text` with its section `heading` ("## ..." up to the next "## " heading) replaced by
    `section`; a missing section goes in after the section `after` (else at the end)."""
    lines = text.rstrip("\n").split("\n")

    def span(title):
        start = next((i for i, l in enumerate(lines) if l.startswith(title)), None)
        if start is None:
            return None
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")),
                   len(lines))
        return start, end

    found = span(heading)
    if found is None:
        at = (span(after) or (len(lines), len(lines)))[1] if after else len(lines)
        found = (at, at)
    start, end = found
    new = ([""] if start > 0 and lines[start - 1] else []) + section.rstrip("\n").split("\n")
    new += [""] if end < len(lines) else []
    return "\n".join(lines[:start] + new + lines[end:]) + "\n"


def fmt_row(cols, widths):
    return "| " + " | ".join(str(c).ljust(w) for c, w in zip(cols, widths)) + " |"


def table(header, rows):
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    lines = [fmt_row(header, widths), "|" + "|".join("-" * (w + 2) for w in widths) + "|"]
    lines += [fmt_row(r, widths) for r in rows]
    return "\n".join(lines)


def machine():
    """The CPU, its cores and its widest vector unit: Mitsuba's llvm variant runs 16 lanes
    with AVX-512 and 8 without, which halved its speed between two runs on machines that
    both called themselves "AMD EPYC"."""
    cpu = platform.processor() or platform.machine()
    vectors = ""
    try:
        info = open("/proc/cpuinfo").read().splitlines()
        cpu = next(l.split(":", 1)[1].strip() for l in info if l.startswith("model name"))
        flags = next(l.split(":", 1)[1].split() for l in info if l.startswith("flags"))
        vectors = ("; AVX-512" if "avx512f" in flags
                   else "; AVX2, no AVX-512" if "avx2" in flags else "; no AVX2")
    except (OSError, StopIteration):
        pass
    return f"{cpu}, {os.cpu_count()} cores{vectors}"


def yat_build(args):
    """Which YAT build the figures are of, and the binary it ran as (the baseline build hands
    over to its x86-64-v3 sibling on a CPU with AVX2: `--stats-json` says which rendered)."""
    with tempfile.TemporaryDirectory() as d:
        figures = render(ROOT / "scenes/cornell/cornell-box.lxs", 1, None, 1, Path(d),
                         size=(16, 9))
    build = ("profile-optimised (`deploy/build-pgo.sh`)" if args.pgo
             else "the README's (`cargo build --release`)")
    return f"{build}; rendering as its {figures.get('instruction_set', 'unknown')} binary"


def side_by_side_section(args):
    """The side-by-side section of RESULTS.md (run now)."""
    sys.path.insert(0, str(ROOT / "bench"))
    sys.dont_write_bytecode = True  # no __pycache__ in the source tree
    import mitsuba3

    before = os.getloadavg()
    runs_table, summary_table, notes = side_by_side(args)
    after = os.getloadavg()
    notes = "\n".join(f"- {n}" for n in notes) or "- none"
    approximations = "\n".join(f"- {a}" for a in mitsuba3.APPROXIMATIONS)
    size = COMPARED_RESOLUTION
    return f"""## Side by side with LuxCoreRender and Mitsuba 3

- machine: {machine()}; {args.threads} render threads for every renderer
- YAT build: {yat_build(args)}
- date: {datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")}
- command: `python3 bench/bench.py {" ".join(sys.argv[1:])}` (setup: `bench/setup-env.sh`,
  which `bench.py` runs itself)
- load average (1 min) {before[0]:.1f} at the start, {after[0]:.1f} at the end; the "load"
  column is at each scene's timed renders, and counts the benchmark's own render threads. The
  machine may be shared and its speed moves: absolute figures move with it, ratios within one
  scene's renders (interleaved) are what the table is for.

Each scene as YAT parsed it, written out by `yat export-luxcore` (LuxCore's own .lxs importer
drops the spheres and the planar mapping, refuses metal2's fresnel colour and loses the named
materials and the camera) and converted from that export to Mitsuba 3's XML by
`bench/mitsuba3.py`. The export writes YAT's null-material lamps (they emit and let every ray
through) as clear, index-matched glass carrying the emission: a surface rays stop at, collect
the emission and go on through unchanged. It used to write black matte, which absorbed the rays
reaching the lamp (LuxCore's Cornell box came out 1.3% darker than YAT's); LuxCore's own `null`
material is skipped inside its intersection routine, so no ray would see the emission. LuxCore's
image also comes out one pixel row lower than YAT's and Mitsuba's; `bench/luxcore.py` moves
its screen window down one row to match. All render at {size[0]}x{size[1]}, path depth {args.depth}, on the same
threads. Each renderer renders a converged reference of its own ({args.ref_spp} spp: the mean of
two renders of half as many with seeds of their own; Mitsuba's with `{MITSUBA_REFERENCE[0]}` and
`{MITSUBA_REFERENCE[1]}`, one reference for both variants) and short renders
({args.compare_spp} spp). MSE is per channel over all pixels of the linear images, less the
reference's own noise (MSE(half a, half b) / 4, the "its reference's noise" column): what is
left is the error against the converged image, whatever each reference's sampler (since session
19; before, the reference's noise stayed in, which favoured the renderer with the less noisy
reference). Efficiency = 1 / (MSE x render s), and "YAT efficiency / this" is YAT's over the
row's. The summary compares the references (mean radiance, and correlation of 16x16-pixel
block luminance: the renderers rendered the same picture) and names each Mitsuba variant's
most efficient sampler.

Render seconds: the median of {args.compare_rounds} timed renders per renderer and sampler,
interleaved round by round, and the fastest in brackets; efficiencies and their ratios are of
the medians, and the summary adds the ratio of the fastest runs (each variant's best sampler
on them). Medians, because one renderer's runs spread by 20-50% on the shared virtual
machine this was measured on even with nothing else running, and the best of three samplers'
fastest runs is the luckiest of three times as many draws as YAT's. YAT's and LuxCore's
from the scene and BVH being ready to the last sample; Mitsuba's around `mi.render` on a loaded
scene, after an untimed render of the same size (the llvm variant JIT-compiles its kernels on
the first render, several seconds; they are cached after that). LuxCore runs PATHCPU with its
default sampler (SOBOL, adaptive strength 0.95); its samples/s and rays/s are its own
statistics.

{summary_table}

{runs_table}

What the Mitsuba conversion matches and approximates:
{approximations}

Export notes:
{notes}
"""


# The seed table's column that bench/adaptive.py fills; bench.py keeps its cells.
ADAPTIVE_COLUMN = "core-s to 1000-spp error, adaptive"


def split_sections(text):
    """(preamble, [(heading line, whole section text)]) of a Markdown file's "## " sections."""
    parts = ("\n" + text).split("\n## ")
    sections = [("## " + p.split("\n", 1)[0], "## " + p.rstrip("\n")) for p in parts[1:]]
    return parts[0].strip("\n"), sections


def write_sections(path, new):
    """Writes the "## " sections of `new` into the Markdown file at `path` in place of the
    sections with the same heading (`replace_section`), keeping every other section
    (hand-written findings, other scripts' tables) where it is; `new`'s preamble, if any,
    replaces the file's."""
    text = path.read_text() if path.exists() else ""
    new_head, new_sections = split_sections(new)
    for heading, body in new_sections:
        text = replace_section(text, heading, body)
    old_head, sections = split_sections(text)
    head = new_head or old_head or "# YAT benchmark results"
    path.write_text("\n\n".join([head] + [body for _, body in sections]) + "\n")


def adaptive_cells(path):
    """Scene name to its cell in the seed table's adaptive column of the file at `path`."""
    cells = {}
    header = None
    for line in path.read_text().split("\n") if path.exists() else []:
        row = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("|"):
            header = None
        elif header is None:
            header = row if ADAPTIVE_COLUMN in row else []
        elif header and len(row) == len(header) and not set(row[0]) <= set("-"):
            cells[row[0]] = row[header.index(ADAPTIVE_COLUMN)]
    return cells


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel (default 16)")
    ap.add_argument("--depth", type=int, default=10, help="path depth (default 10, the seed's)")
    ap.add_argument("--threads", type=int, default=os.cpu_count(), help="render threads")
    ap.add_argument("--quick", action="store_true", help="4 spp, and do not write RESULTS.md")
    ap.add_argument("--only", help="render only scenes whose path contains this text")
    ap.add_argument("--no-compare", action="store_true",
                    help="skip the side by side with LuxCore and Mitsuba")
    ap.add_argument("--compare-only", action="store_true",
                    help="only the side by side; rewrites its section of RESULTS.md")
    ap.add_argument("--compare-spp", type=int, default=16,
                    help="spp of the side by side's timed renders (default 16)")
    ap.add_argument("--ref-spp", type=int, default=1024,
                    help="spp of the side by side's converged references (default 1024)")
    ap.add_argument("--compare-rounds", type=int, default=5,
                    help="timed renders per renderer in the side by side, interleaved; "
                         "efficiency of each one's median (default 5)")
    ap.add_argument("--pgo", action="store_true",
                    help="build with deploy/build-pgo.sh and measure its profile-optimised "
                         "binary, target/pgo/yat (the same images, sooner)")
    ap.add_argument("--no-build", action="store_true",
                    help="use the release binary as it is (do not run cargo build first)")
    args = ap.parse_args()
    spp = 4 if args.quick else args.spp
    with_compare = not (args.quick or args.no_compare) and SEED.exists()
    if with_compare:
        ensure_venv()

    if args.pgo:
        global YAT
        YAT = PGO_YAT
    if not args.no_build:
        build(args.pgo)
    results = ROOT / "bench/RESULTS.md"
    if args.compare_only:
        section = side_by_side_section(args)
        print(section)
        if not args.only:
            write_sections(results, section)
            log("rewrote the side-by-side section of bench/RESULTS.md")
        return

    scenes = [("seed", SEED / s, (t, here)) for s, t, here in SEED_TABLE] + [
        ("own", ROOT / "scenes" / s, None) for s in OWN_SCENES
    ]
    if args.only:
        scenes = [s for s in scenes if args.only in str(s[1])]
    if not SEED.exists():
        log(f"seed scenes not found at {SEED}: benchmarking our own scenes only")
        scenes = [s for s in scenes if s[0] == "own"]

    rows, seed_rows = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for kind, scene, original in scenes:
            log(f"rendering {scene.name} at {spp} spp ...")
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
                published, original_here = original
                # Linear in spp: the seed's table is at 1000 spp.
                ours_1000 = f["render_seconds"] * 1000 / f["spp"]
                ours_core = ours_1000 * args.threads
                theirs_core = published * ORIGINAL_CORES
                ratio = theirs_core / ours_core
                hardware = beyond = "-"
                if original_here is not None:
                    rays = f["width"] * f["height"] * ORIGINAL_RAYS_PER_PIXEL
                    published_per_sample = theirs_core / rays
                    here_per_sample = ORIGINAL_MEASURED_THREADS / original_here
                    factor = published_per_sample / here_per_sample
                    hardware, beyond = f"{factor:.1f}x", f"{ratio / factor:.1f}x"
                seed_rows.append([
                    scene.name, f"{ours_1000:.0f}", f"{ours_core:.0f}", f"{published}",
                    f"{theirs_core}", f"{ratio:.1f}x", hardware, beyond,
                ])

    main_table = table(
        ["scene", "resolution", "spp", "parse / build s", "render s", "M samples/s",
         "M rays/s", "peak MB", "core-us/sample"],
        rows,
    )
    adaptive = adaptive_cells(results)
    seed_table = table(
        ["scene", "ours s @1000spp", "ours core-s", "original s (8 cores)", "original core-s",
         "core-s ratio", "hardware", "beyond hardware", ADAPTIVE_COLUMN],
        [row + [adaptive.get(row[0], "-")] for row in seed_rows],
    )
    compare_section = side_by_side_section(args) if with_compare else ""
    report = f"""# YAT benchmark results

- machine: {machine()}; {args.threads} render threads
- date: {datetime.date.today().isoformat()}
- command: `python3 bench/bench.py{' --spp ' + str(args.spp) if args.spp != 16 else ''}`
- settings: {spp} spp, path depth {args.depth}, release build

## Every scene

{main_table}

core-us/sample = render seconds x threads / samples (CPU time per camera sample).

## The original tracer's table, re-created

Our time at {spp} spp scaled linearly to 1000 spp; the original's published time at 1000 spp,
depth 10 on an 8-core AMD FX-8150 (OpenJDK 8), converted to core-seconds (x 8).
"hardware" is how much faster this machine runs the original itself, per core-second and
camera ray: its published time against the original rebuilt from its public source and run
here (2 threads, depth 10; measured on five of the scenes). "beyond hardware" is the
core-seconds ratio divided by it: the part of the lead that is YAT's, not the machine's.
"{ADAPTIVE_COLUMN}": ours core-s divided by the speed-up in CPU seconds that
adaptive sampling measured against a uniform 1000-spp render at the resolution given in the cell
(`bench/adaptive.py --write-results`, see "Adaptive sampling, measured on the binary" below), not
a full-resolution run; bench.py carries the cells over from the file it rewrites.

{seed_table}

{compare_section}"""
    print(report)
    if not (args.quick or args.only or args.no_compare):
        write_sections(results, report)
        log("wrote bench/RESULTS.md")


if __name__ == "__main__":
    main()
