#!/usr/bin/env python3
"""Renders a scene exported by `yat export-luxcore` with LuxCoreRender's CPU path tracer
(pyluxcore, PATHCPU) or its bidirectional one (--engine BIDIRCPU: --depth is the eye path's
depth, --light-depth the light path's) and writes linear RGB as EXR plus its figures as JSON.
bench.py runs it in the benchmark's virtualenv, one process per render (as it runs yat).

    luxcore.py EXPORT_DIR --spp N --depth D --threads T [--width W --height H] \
        [--engine BIDIRCPU --light-depth L] [--light-groups G] --out rgb.exr --stats stats.json

With --light-groups G it also writes each light group's radiance (LuxCore's RADIANCE_GROUP
output of light id g, which the export gives group g's lights) as rgb.group<g>.exr.

Timing starts when RenderSession.Start() returns (scene and BVH ready) and stops when the
halt condition is met, like yat's render_seconds; render_cpu_seconds is the process's CPU time
(all its threads) over the same span. SOBOL's adaptive strength is LuxCore's own default (0.95:
pixels are picked in proportion to their estimated noise, the mean spp stays --spp) unless
--adaptive-strength says otherwise (0 = every pixel alike).
"""

import argparse
import json
import os
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("export_dir")
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--depth", type=int, required=True)
    ap.add_argument("--threads", type=int, required=True)
    ap.add_argument("--sampler", default="SOBOL",
                    help="SOBOL (LuxCore's default), RANDOM or METROPOLIS")
    ap.add_argument("--engine", default="PATHCPU", help="PATHCPU or BIDIRCPU")
    ap.add_argument("--light-depth", type=int, help="BIDIRCPU's light path depth (default --depth)")
    ap.add_argument("--adaptive-strength", type=float,
                    help="sampler.sobol.adaptive.strength (LuxCore's default: 0.95)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--width", type=int, help="image width (default: the export's film)")
    ap.add_argument("--height", type=int, help="image height (default: the export's film)")
    ap.add_argument("--light-groups", type=int, default=0,
                    help="light groups to write apart, as OUT's stem + .group<g>.exr")
    ap.add_argument("--out", required=True, help="linear RGB EXR")
    ap.add_argument("--stats", required=True, help="JSON figures")
    args = ap.parse_args()
    out = os.path.abspath(args.out)
    stats_path = os.path.abspath(args.stats)

    import pyluxcore

    pyluxcore.Init(lambda _msg: None)
    # The export's paths are relative to its folder; LuxCore resolves them from the cwd.
    os.chdir(args.export_dir)
    cfg = pyluxcore.Properties("render.cfg")
    props = {
        "renderengine.type": args.engine,
        "renderengine.seed": args.seed,
        "native.threads.count": args.threads,
        "sampler.type": args.sampler,
        "path.pathdepth.total": args.depth,
        "path.pathdepth.diffuse": args.depth,
        "path.pathdepth.glossy": args.depth,
        "path.pathdepth.specular": args.depth,
        "batch.haltspp": args.spp,
        "film.outputs.0.type": "RGB",
        "film.outputs.0.filename": out,
    }
    stem = os.path.splitext(out)[0]
    for g in range(args.light_groups):
        props[f"film.outputs.{1 + g}.type"] = "RADIANCE_GROUP"
        props[f"film.outputs.{1 + g}.id"] = g
        props[f"film.outputs.{1 + g}.filename"] = f"{stem}.group{g}.exr"
    if args.engine == "BIDIRCPU":
        props["path.maxdepth"] = args.depth
        props["light.maxdepth"] = args.light_depth or args.depth
    if args.adaptive_strength is not None:
        props["sampler.sobol.adaptive.strength"] = args.adaptive_strength
    if args.width and args.height:
        props["film.width"] = args.width
        props["film.height"] = args.height
    for key, value in props.items():
        cfg.Set(pyluxcore.Property(key, value))

    loading = time.perf_counter()
    scene_props = pyluxcore.Properties(cfg.Get("scene.file").GetString())
    # LuxCore's image comes out one pixel row lower than YAT's and Mitsuba's of the same
    # camera (seen as rows of the Cornell lamp matching exactly one row apart): the screen
    # window moves down by one row of the film about to be rendered to make up for it.
    window = "scene.camera.screenwindow"
    if scene_props.IsDefined(window):
        x0, x1, y0, y1 = scene_props.Get(window).GetFloats()
        row = (y1 - y0) / cfg.Get("film.height").GetInt()
        scene_props.Set(pyluxcore.Property(window, [x0, x1, y0 - row, y1 - row]))
    scene = pyluxcore.Scene()
    scene.Parse(scene_props)
    config = pyluxcore.RenderConfig(cfg, scene)
    session = pyluxcore.RenderSession(config)
    session.Start()
    started = time.perf_counter()
    started_cpu = time.process_time()
    while True:
        session.UpdateStats()
        if session.HasDone():
            break
        time.sleep(0.02)
    seconds = time.perf_counter() - started
    cpu_seconds = time.process_time() - started_cpu
    stats = session.GetStats()
    session.Stop()
    film = session.GetFilm()
    width, height = film.GetWidth(), film.GetHeight()
    passes = stats.Get("stats.renderengine.pass").GetInt()
    figures = {
        "width": width,
        "height": height,
        "spp": passes,
        "load_seconds": started - loading,
        "render_seconds": seconds,
        "render_cpu_seconds": cpu_seconds,
        "samples_per_second": width * height * passes / seconds,
        "luxcore_samples_per_second": stats.Get("stats.renderengine.total.samplesec").GetFloat(),
        "rays_per_second": stats.Get("stats.renderengine.total.raysec").GetFloat(),
        "sampler": args.sampler,
        "engine": args.engine,
        # The value in force (LuxCore's default when not set).
        "adaptive_strength": (
            config.GetProperty("sampler.sobol.adaptive.strength").GetFloat()
            if args.sampler == "SOBOL" else None
        ),
        "pyluxcore": pyluxcore.Version(),
    }
    film.SaveOutputs()
    with open(stats_path, "w") as f:
        json.dump(figures, f)
    # pyluxcore 2.11 crashes in interpreter shutdown after a render; everything is written.
    os._exit(0)


if __name__ == "__main__":
    main()
