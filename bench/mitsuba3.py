#!/usr/bin/env python3
"""Mitsuba 3 for the side-by-side benchmark: converts a scene exported by `yat export-luxcore`
(scene.scn, render.cfg, world-space PLY meshes) into Mitsuba 3's XML scene format, and renders
such a scene with a chosen variant and sampler, writing linear RGB as EXR plus its figures as
JSON. bench.py runs it in the benchmark's virtualenv, one process per render (as it runs yat).

    mitsuba3.py convert EXPORT_DIR OUT_DIR          # OUT_DIR/scene.xml + linear textures
    mitsuba3.py render OUT_DIR/scene.xml --variant llvm_ad_rgb --sampler ldsampler \\
        --spp N --depth D --threads T --width W --height H --seed S --out rgb.exr --stats s.json

APPROXIMATIONS below lists what the conversion matches and what it approximates (bench.py
copies it into bench/RESULTS.md). Anything else in the export is refused with a message saying
what.
"""

import argparse
import glob
import json
import math
import os
import sys
import time
from pathlib import Path
from xml.sax.saxutils import quoteattr

# Path length and Russian roulette, in Mitsuba's terms for YAT's --maxdepth D (see above).
RR_DEPTH = 3
# Blackman-Harris window coefficients (LuxCore's and YAT's filter).
BLACKMAN_HARRIS = (0.35875, 0.48829, 0.14128, 0.01168)
# Mitsuba's far clip must be finite; LuxCore's default yon is 1e30.
MAX_FAR_CLIP = 1.0e7


APPROXIMATIONS = [
    "geometry: the export's world-space PLY meshes as they are (winding, vertex normals, uvs); "
    "spheres are tessellated by the export, as for LuxCore",
    "camera: LuxCore's lookat, the field of view across the shorter image side, a thin lens "
    "with the same aperture radius and focal distance; an off-centre screen window is refused",
    "path depth: YAT's `--maxdepth D` counts scattering vertices, Mitsuba's `max_depth` counts "
    "path segments (1 = emitters seen directly), so `max_depth = D + 1`; Russian roulette from "
    "YAT's third vertex on is `rr_depth = 3` (Mitsuba tests `depth >= rr_depth` after a "
    "vertex's bounce), but Mitsuba's survival probability is min(max throughput x eta^2, 0.95) "
    "where YAT's is max throughput clamped to [0.05, 1]",
    "lamps: YAT's null-material area lights are Mitsuba's null BSDF with an area emitter "
    "(emits, lets rays through); Mitsuba counts the crossing as a path vertex, YAT does not, "
    "and its shadow rays stop at the lamp where YAT's cross it (since session 18): the light "
    "samples of what lies behind a lamp, 0.1% of Captain Falcon's direct light",
    "pixel filter: Mitsuba has no Blackman-Harris; a gaussian of the same standard deviation "
    "(0.554 px for the scenes' half-width 2). Both splat each sample over the filter's "
    "footprint (YAT since session 6; before, it importance-sampled the filter into one pixel)",
    "film: linear RGB float32, no tone mapping, the same as YAT's and LuxCore's EXR",
    "image textures and the environment map: decoded with the export's gamma (2.2 for "
    "textures, 1 for the maps here) and gain into linear EXR files Mitsuba reads raw (its own "
    "decoding would apply the sRGB curve); bilinear lookups, repeat wrap",
    "environment orientation: LuxCore's lat-long map (u = phi / 2pi about +z, v = theta / pi "
    "from +z, which the export matches to YAT's) turned into Mitsuba's (+y up, u from -z "
    "towards +x) by the to_world transform",
    "materials: matte is `diffuse`; mirror a `conductor` with no Fresnel tinted by kr; glass a "
    "smooth `dielectric` with the same indices; metal2 with a reflectance Fresnel (YAT: "
    "Schlick with r0 = kr, GGX alpha = roughness) is a `roughconductor` with GGX alpha = "
    "roughness and a real index n = (1 + sqrt r0) / (1 - sqrt r0), k = 0 (the exact Fresnel "
    "of that index, not Schlick's curve)",
    "samplers: `independent` (Mitsuba's default), `multijitter` and `ldsampler` (its "
    "stratified ones); YAT uses Owen-scrambled Sobol, LuxCore its SOBOL",
]


class Unsupported(Exception):
    """Something in the export that this converter does not express in Mitsuba."""


def parse_sdl(text):
    """LuxCore SDL (`key = value` lines) as {key: value string}."""
    props = {}
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition("=")
        props[key.strip()] = value.strip()
    return props


def group(props, prefix):
    """{name: {property: value}} for keys `prefix.<name>.<property>`."""
    out = {}
    for key, value in props.items():
        if key.startswith(prefix + "."):
            name, _, prop = key[len(prefix) + 1:].partition(".")
            out.setdefault(name, {})[prop] = value
    return out


def unquote(value):
    return value[1:-1] if value.startswith('"') and value.endswith('"') else None


def floats(value):
    return [float(x) for x in value.split()]


def blackman_harris_stddev(radius, steps=4096):
    """Standard deviation of the Blackman-Harris window spanning [-radius, radius]."""
    a0, a1, a2, a3 = BLACKMAN_HARRIS
    num = den = 0.0
    for i in range(steps):
        x = -radius + 2 * radius * (i + 0.5) / steps
        t = 2 * math.pi * (x / (2 * radius) + 0.5)
        w = a0 - a1 * math.cos(t) + a2 * math.cos(2 * t) - a3 * math.cos(3 * t)
        num += x * x * w
        den += w
    return math.sqrt(num / den)


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def lux_matrix(value):
    """A LuxCore matrix property (16 entries column by column) as rows."""
    v = floats(value)
    return [[v[c * 4 + r] for c in range(4)] for r in range(4)]


# Mitsuba's lat-long frame from LuxCore's: a LuxCore-local direction (x, y, z) has Mitsuba
# local coordinates (y, z, -x) (same u and v; a reflection, since the two maps wind opposite
# ways). to_world = LuxCore's light-to-world times the inverse (the transpose) of that map.
LUX_TO_MITSUBA_LATLONG_T = [[0, 0, -1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]


class Converter:
    def __init__(self, export_dir, out_dir):
        self.export_dir = Path(export_dir).resolve()
        self.out_dir = Path(out_dir).resolve()
        self.scene = parse_sdl((self.export_dir / "scene.scn").read_text())
        self.config = parse_sdl((self.export_dir / "render.cfg").read_text())
        self.textures = group(self.scene, "scene.textures")
        self.materials = group(self.scene, "scene.materials")
        self.written_textures = {}

    # -- values ---------------------------------------------------------------------------

    def linear_image(self, file, gamma, gain, key):
        """The image decoded as value ** gamma x gain, written once as a linear EXR."""
        import mitsuba as mi
        import numpy as np

        cached = self.written_textures.get(key)
        if cached:
            return cached
        bitmap = mi.Bitmap(file)
        data = np.array(bitmap, copy=True)
        if np.issubdtype(data.dtype, np.integer):
            data = data.astype(np.float64) / np.iinfo(data.dtype).max
        data = data.astype(np.float64)
        if data.ndim == 2:
            data = data[..., None]
        if data.shape[2] == 1:
            data = np.repeat(data, 3, axis=2)
        data = np.power(np.clip(data[..., :3], 0, None), gamma) * np.asarray(gain)
        path = self.out_dir / "textures" / f"{key}.exr"
        path.parent.mkdir(parents=True, exist_ok=True)
        mi.Bitmap(data.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(str(path))
        self.written_textures[key] = path.relative_to(self.out_dir).as_posix()
        return self.written_textures[key]

    def color(self, name, value, indent):
        """A colour parameter: an inline rgb, or a reference to a converted texture."""
        tex = unquote(value)
        if tex is None:
            rgb = floats(value)
            if len(rgb) == 1:
                rgb *= 3
            return f'{indent}<rgb name="{name}" value="{rgb[0]} {rgb[1]} {rgb[2]}"/>'
        return self.texture(name, tex, indent)

    def scalar(self, value, what):
        if unquote(value) is not None:
            raise Unsupported(f"{what}: a texture where Mitsuba takes a number")
        return floats(value)[0]

    def texture(self, name, tex, indent):
        t = self.textures.get(tex)
        if t is None:
            raise Unsupported(f"texture {tex}: not in the export")
        kind = unquote(t["type"])
        if kind == "constfloat3":
            return self.color(name, t["value"], indent)
        if kind != "imagemap":
            raise Unsupported(f"texture {tex}: type {kind} has no Mitsuba equivalent here")
        if unquote(t.get("mapping.type", '"uvmapping2d"')) != "uvmapping2d":
            raise Unsupported(f"texture {tex}: mapping {t['mapping.type']}")
        if unquote(t.get("channel", '"rgb"')) not in ("rgb", None):
            raise Unsupported(f"texture {tex}: single-channel image")
        wrap = {"repeat": "repeat", "clamp": "clamp"}.get(unquote(t.get("wrap", '"repeat"')))
        if wrap is None:
            raise Unsupported(f"texture {tex}: wrap {t['wrap']} (Mitsuba: repeat, mirror, clamp)")
        gain = floats(t.get("gain", "1"))
        file = self.linear_image(unquote(t["file"]), float(t.get("gamma", "2.2")),
                                 gain * 3 if len(gain) == 1 else gain, tex)
        su, sv = floats(t.get("mapping.uvscale", "1 1"))
        du, dv = floats(t.get("mapping.uvdelta", "0 0"))
        # LuxCore's uvmapping2d is uv x scale + delta; Mitsuba applies the listed transforms
        # in order.
        return "\n".join([
            f'{indent}<texture type="bitmap" name="{name}">',
            f'{indent}    <string name="filename" value={quoteattr(file)}/>',
            f'{indent}    <boolean name="raw" value="true"/>',
            f'{indent}    <string name="wrap_mode" value="{wrap}"/>',
            f'{indent}    <transform name="to_uv">',
            f'{indent}        <scale x="{su}" y="{sv}"/>',
            f'{indent}        <translate x="{du}" y="{dv}"/>',
            f'{indent}    </transform>',
            f'{indent}</texture>',
        ])

    # -- materials ------------------------------------------------------------------------

    def bsdf(self, name, indent, top_level=True):
        """The BSDF element for LuxCore material `name` (with an id when top-level)."""
        m = self.materials.get(name)
        if m is None:
            raise Unsupported(f"material {name}: not in the export")
        kind = unquote(m["type"])
        i2 = indent + "    "
        head = f'{indent}<bsdf type="{{}}"' + (f" id={quoteattr(name)}>" if top_level else ">")
        tail = f"{indent}</bsdf>"
        if kind in ("matte", "roughmatte"):
            return "\n".join([head.format("diffuse"), self.color("reflectance", m["kd"], i2), tail])
        if kind == "mirror":
            return "\n".join([
                head.format("conductor"), f'{i2}<string name="material" value="none"/>',
                self.color("specular_reflectance", m["kr"], i2), tail,
            ])
        if kind == "glass":
            n_in = self.scalar(m.get("interiorior", "1.5"), f"material {name} interiorior")
            n_out = self.scalar(m.get("exteriorior", "1"), f"material {name} exteriorior")
            if n_in == n_out and m.get("kr") == "0 0 0" and m.get("kt") == "1 1 1":
                # The export's stand-in for YAT's null lamp: reflects nothing, bends nothing.
                return head.format("null")[:-1] + "/>"
            return "\n".join([
                head.format("dielectric"), f'{i2}<float name="int_ior" value="{n_in}"/>',
                f'{i2}<float name="ext_ior" value="{n_out}"/>',
                self.color("specular_reflectance", m["kr"], i2),
                self.color("specular_transmittance", m["kt"], i2), tail,
            ])
        if kind == "null":
            return head.format("null")[:-1] + "/>"
        if kind == "metal2":
            fresnel = self.textures.get(unquote(m["fresnel"]) or "")
            if fresnel is None:
                raise Unsupported(f"material {name}: metal2 without a fresnel texture")
            if unquote(fresnel["type"]) == "fresnelcolor":
                if unquote(fresnel["kr"]) is not None:
                    raise Unsupported(f"material {name}: textured fresnel reflectance")
                # The real index whose normal-incidence reflectance is kr.
                eta = [(1 + math.sqrt(r)) / (1 - math.sqrt(r)) if r < 1 else 1e4
                       for r in (min(max(x, 0.0), 0.9999) for x in floats(fresnel["kr"]))]
                k = [0.0, 0.0, 0.0]
            elif unquote(fresnel["type"]) == "fresnelconst":
                eta, k = floats(fresnel["n"]), floats(fresnel["k"])
            else:
                raise Unsupported(f"material {name}: fresnel {fresnel['type']}")
            ur = self.scalar(m.get("uroughness", "0.1"), f"material {name} uroughness")
            vr = self.scalar(m.get("vroughness", "0.1"), f"material {name} vroughness")
            return "\n".join([
                head.format("roughconductor"),
                f'{i2}<string name="distribution" value="ggx"/>',
                f'{i2}<float name="alpha_u" value="{max(ur, 1e-4)}"/>',
                f'{i2}<float name="alpha_v" value="{max(vr, 1e-4)}"/>',
                f'{i2}<rgb name="eta" value="{eta[0]} {eta[1]} {eta[2]}"/>',
                f'{i2}<rgb name="k" value="{k[0]} {k[1]} {k[2]}"/>', tail,
            ])
        if kind == "mix":
            amount = self.scalar(m["amount"], f"material {name} amount")
            return "\n".join([
                head.format("blendbsdf"), f'{i2}<float name="weight" value="{amount}"/>',
                self.bsdf(unquote(m["material1"]), i2, False),
                self.bsdf(unquote(m["material2"]), i2, False),
                tail,
            ])
        raise Unsupported(f"material {name}: type {kind} has no Mitsuba equivalent here")

    # -- scene parts ----------------------------------------------------------------------

    def camera(self):
        s = self.scene
        kind = unquote(s.get("scene.camera.type", '"perspective"'))
        if kind != "perspective":
            raise Unsupported(f"camera {kind}")
        width, height = int(self.config["film.width"]), int(self.config["film.height"])
        x0, x1, y0, y1 = floats(s.get("scene.camera.screenwindow", "-1 1 -1 1"))
        aspect = width / height
        expected = [-aspect, aspect, -1, 1] if aspect >= 1 else [-1, 1, -1 / aspect, 1 / aspect]
        scale = max(abs(x0), abs(x1), abs(y0), abs(y1)) / max(aspect, 1 / aspect)
        if any(abs(a - b * scale) > 1e-4 * scale for a, b in zip([x0, x1, y0, y1], expected)):
            raise Unsupported(f"camera screen window {x0} {x1} {y0} {y1} (not centred)")
        # A screen window wider than the default narrows the field of view.
        fov = math.degrees(2 * math.atan(math.tan(math.radians(
            float(s.get("scene.camera.fieldofview", "45")) / 2)) * scale))
        lens = float(s.get("scene.camera.lensradius", "0"))
        lookat = (f'<lookat origin="{s["scene.camera.lookat.orig"]}" '
                  f'target="{s["scene.camera.lookat.target"]}" up="{s["scene.camera.up"]}"/>')
        sigma = blackman_harris_stddev(float(self.config.get("film.filter.xwidth", "2")))
        if unquote(self.config.get("film.filter.type", '"BLACKMANHARRIS"')) != "BLACKMANHARRIS":
            raise Unsupported(f"pixel filter {self.config['film.filter.type']}")
        near = float(s.get("scene.camera.cliphither", "1e-3"))
        far = min(float(s.get("scene.camera.clipyon", "1e30")), MAX_FAR_CLIP)
        out = [
            f'    <sensor type="{"thinlens" if lens > 0 else "perspective"}">',
            f'        <float name="fov" value="{fov}"/>',
            '        <string name="fov_axis" value="smaller"/>',
            f'        <float name="near_clip" value="{near}"/>',
            f'        <float name="far_clip" value="{far}"/>',
        ]
        if lens > 0:
            out += [
                f'        <float name="aperture_radius" value="{lens}"/>',
                f'        <float name="focus_distance" value="{s["scene.camera.focaldistance"]}"/>',
            ]
        out += [
            f'        <transform name="to_world">{lookat}</transform>',
            '        <sampler type="$sampler">',
            '            <integer name="sample_count" value="$spp"/>',
            '            <integer name="seed" value="$seed"/>',
            '        </sampler>',
            '        <film type="hdrfilm">',
            '            <integer name="width" value="$width"/>',
            '            <integer name="height" value="$height"/>',
            '            <string name="pixel_format" value="rgb"/>',
            '            <string name="component_format" value="float32"/>',
            f'            <rfilter type="gaussian"><float name="stddev" value="{sigma:.6f}"/>'
            '</rfilter>',
            '        </film>',
            '    </sensor>',
        ]
        return out, width, height

    def shapes(self):
        out = []
        objects = group(self.scene, "scene.objects")
        shapes = group(self.scene, "scene.shapes")
        used = set()
        for name, obj in sorted(objects.items(), key=lambda kv: kv[0]):
            shape = shapes[unquote(obj["shape"])]
            if unquote(shape["type"]) != "mesh":
                raise Unsupported(f"shape {obj['shape']}: type {shape['type']}")
            if "transformation" in obj:
                raise Unsupported(f"object {name}: instance transformation")
            material = unquote(obj["material"])
            m = self.materials[material]
            # Relative to the XML file where possible (Mitsuba resolves from its folder), so the
            # scene text does not depend on where the export lies.
            ply = os.path.relpath(self.export_dir / unquote(shape["ply"]), self.out_dir)
            out += [
                '    <shape type="ply">',
                f'        <string name="filename" value={quoteattr(ply)}/>',
                '        <boolean name="face_normals" value="false"/>',
                f'        <ref id={quoteattr(material)}/>',
            ]
            used.add(material)
            if "emission" in m:
                if unquote(m["emission"]) is not None:
                    raise Unsupported(f"material {material}: textured emission")
                gain = floats(m.get("emission.gain", "1 1 1"))
                if float(m.get("emission.power", "0")) > 0:
                    raise Unsupported(f"material {material}: emission given as power")
                radiance = [a * b for a, b in zip(floats(m["emission"]), gain)]
                out += [
                    '        <emitter type="area">',
                    f'            <rgb name="radiance" value="{radiance[0]} {radiance[1]} '
                    f'{radiance[2]}"/>',
                    '        </emitter>',
                ]
            out.append("    </shape>")
        return out, used

    def lights(self):
        out = []
        for name, light in group(self.scene, "scene.lights").items():
            kind = unquote(light["type"])
            gain = floats(light.get("gain", "1 1 1"))
            if kind == "infinite":
                file = self.linear_image(unquote(light["file"]), float(light.get("gamma", "1")),
                                         gain, name)
                m = mat_mul(lux_matrix(light["transformation"]), LUX_TO_MITSUBA_LATLONG_T) \
                    if "transformation" in light else LUX_TO_MITSUBA_LATLONG_T
                values = " ".join(str(m[r][c]) for r in range(4) for c in range(4))
                out += [
                    '    <emitter type="envmap">',
                    f'        <string name="filename" value={quoteattr(file)}/>',
                    f'        <transform name="to_world"><matrix value="{values}"/></transform>',
                    '    </emitter>',
                ]
            elif kind == "constantinfinite":
                c = [a * b for a, b in zip(floats(light["color"]), gain)]
                out += ['    <emitter type="constant">',
                        f'        <rgb name="radiance" value="{c[0]} {c[1]} {c[2]}"/>',
                        '    </emitter>']
            elif kind == "point":
                c = [a * b for a, b in zip(floats(light["color"]), gain)]
                out += ['    <emitter type="point">',
                        f'        <point name="position" value="{light["position"]}"/>',
                        f'        <rgb name="intensity" value="{c[0]} {c[1]} {c[2]}"/>',
                        '    </emitter>']
            else:
                raise Unsupported(f"light {name}: type {kind}")
        return out

    def convert(self):
        self.out_dir.mkdir(parents=True, exist_ok=True)
        sensor, width, height = self.camera()
        shapes, used = self.shapes()
        bsdfs = [self.bsdf(name, "    ") for name in sorted(used)]
        lines = [
            '<scene version="3.0.0">',
            '    <default name="spp" value="16"/>',
            '    <default name="seed" value="0"/>',
            '    <default name="sampler" value="independent"/>',
            f'    <default name="width" value="{width}"/>',
            f'    <default name="height" value="{height}"/>',
            '    <default name="max_depth" value="11"/>',
            f'    <default name="rr_depth" value="{RR_DEPTH}"/>',
                    '    <integrator type="path">',
            '        <integer name="max_depth" value="$max_depth"/>',
            '        <integer name="rr_depth" value="$rr_depth"/>',
            '    </integrator>',
            *sensor, *bsdfs, *shapes, *self.lights(), '</scene>',
        ]
        path = self.out_dir / "scene.xml"
        path.write_text("\n".join(lines) + "\n")
        return path


def libllvm():
    """Debian's libLLVM 19 (bench/setup-env.sh installs it), or None."""
    found = sorted(glob.glob("/usr/lib/*/libLLVM.so.19*") + glob.glob("/usr/lib/llvm-19/lib/libLLVM.so*"))
    return found[0] if found else None


def render(args):
    if args.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        path = libllvm()
        if path is None:
            sys.exit("libLLVM 19 not found: run bench/setup-env.sh")
        os.environ["DRJIT_LIBLLVM_PATH"] = path
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(args.variant)
    dr.set_thread_count(args.threads)
    pixels = args.width * args.height
    params = dict(spp=args.spp, seed=args.seed, sampler=args.sampler, width=args.width,
                  height=args.height, max_depth=args.depth + 1, rr_depth=RR_DEPTH)
    loading = time.perf_counter()
    scene = mi.load_file(args.scene, **params)
    loaded = time.perf_counter()
    compile_seconds = 0.0
    if args.warm_up:
        # The vectorised variant compiles its kernels on the first render (cached on disk
        # after that); a first untimed render of the same size keeps compilation out of the
        # render time, as YAT's and LuxCore's compilation is.
        image = mi.render(scene, spp=args.spp, seed=args.seed + 0x5EED)
        dr.eval(image)
        dr.sync_thread()
        compile_seconds = time.perf_counter() - loaded
    started = time.perf_counter()
    started_cpu = time.process_time()
    image = mi.render(scene, spp=args.spp, seed=args.seed)
    dr.eval(image)
    dr.sync_thread()
    seconds = time.perf_counter() - started
    # All the process's threads (Dr.Jit's pool included), as for the other renderers.
    cpu_seconds = time.process_time() - started_cpu
    # The stratified samplers round the count (ldsampler to a power of two, multijitter to a
    # product of two near its square root): the samples taken are the sampler's count.
    spp = scene.sensors()[0].sampler().sample_count()
    mi.Bitmap(image).write(args.out)
    figures = {
        "width": args.width,
        "height": args.height,
        "spp": spp,
        "load_seconds": loaded - loading,
        "warm_up_seconds": compile_seconds,
        "render_seconds": seconds,
        "render_cpu_seconds": cpu_seconds,
        "samples_per_second": pixels * spp / seconds,
        "variant": args.variant,
        "sampler": args.sampler,
        "mitsuba": mi.__version__,
    }
    Path(args.stats).write_text(json.dumps(figures))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    c = sub.add_parser("convert", help="export dir -> Mitsuba XML scene")
    c.add_argument("export_dir")
    c.add_argument("out_dir")
    r = sub.add_parser("render", help="render a converted scene")
    r.add_argument("scene")
    r.add_argument("--variant", default="llvm_ad_rgb", help="scalar_rgb or llvm_ad_rgb")
    r.add_argument("--sampler", default="independent",
                   help="independent, multijitter or ldsampler")
    r.add_argument("--spp", type=int, required=True)
    r.add_argument("--depth", type=int, required=True, help="YAT's --maxdepth")
    r.add_argument("--threads", type=int, required=True)
    r.add_argument("--width", type=int, required=True)
    r.add_argument("--height", type=int, required=True)
    r.add_argument("--seed", type=int, default=1)
    r.add_argument("--warm-up", action="store_true", help="render once untimed first")
    r.add_argument("--out", required=True, help="linear RGB EXR")
    r.add_argument("--stats", required=True, help="JSON figures")
    args = ap.parse_args()
    if args.command == "convert":
        import mitsuba as mi

        mi.set_variant("scalar_rgb")
        try:
            print(Converter(args.export_dir, args.out_dir).convert())
        except Unsupported as e:
            print(f"not converted: {e}", file=sys.stderr)
            sys.exit(2)
    else:
        render(args)


if __name__ == "__main__":
    main()
