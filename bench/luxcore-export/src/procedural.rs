//! The procedural textures as LuxCore textures: noise (fbm, wrinkled, windy, marble), dots,
//! brick, bilerp, uv, band, add, subtract, normalmap and the blender_* family, with their 3D
//! mappings as LuxCore's global/local/uv mapping3d. LuxCore's blender textures give the
//! pattern's intensity only, so YAT's blend of tex1 into tex2 becomes a mix texture around it.

use std::path::Path;

use yat_tracer::desc::{ConstOrTexture, Mapping2D, TextureKind};
use yat_tracer::texture::blender::noise_basis::{Metric, NoiseBasis};
use yat_tracer::texture::blender::{musgrave, Blender, BlenderKind};
use yat_tracer::texture::{
    Bond, Coordinates, Fbm, Mapping3D, NormalMap, Op, TextureType, Wrinkled,
};

use crate::props::{matrix, quoted, tex_value, v3, Props};

/// LuxCore's mapping3d of a YAT 3D mapping (its transformation is world to texture).
pub fn write_mapping3d(p: &mut Props, prefix: &str, mapping: &Mapping3D) {
    let kind = match mapping.coordinates {
        Coordinates::Global => "globalmapping3d",
        Coordinates::Local => "localmapping3d",
        Coordinates::Uv => "uvmapping3d",
    };
    p.set(format!("{prefix}.mapping.type"), quoted(kind));
    p.set(
        format!("{prefix}.mapping.transformation"),
        matrix(&mapping.world_to_texture),
    );
}

fn basis_name(b: NoiseBasis) -> &'static str {
    match b {
        NoiseBasis::BlenderOriginal => "blender_original",
        NoiseBasis::OriginalPerlin => "original_perlin",
        NoiseBasis::ImprovedPerlin => "improved_perlin",
        NoiseBasis::VoronoiF1 => "voronoi_f1",
        NoiseBasis::VoronoiF2 => "voronoi_f2",
        NoiseBasis::VoronoiF3 => "voronoi_f3",
        NoiseBasis::VoronoiF4 => "voronoi_f4",
        NoiseBasis::VoronoiF2F1 => "voronoi_f2_f1",
        NoiseBasis::VoronoiCrackle => "voronoi_crackle",
        NoiseBasis::CellNoise => "cell_noise",
    }
}

fn hard(h: bool) -> String {
    quoted(if h { "hard_noise" } else { "soft_noise" })
}

fn wave_name(w: yat_tracer::texture::blender::common::Wave) -> String {
    use yat_tracer::texture::blender::common::Wave;
    quoted(match w {
        Wave::Sin => "sin",
        Wave::Saw => "saw",
        Wave::Tri => "tri",
    })
}

/// Writes a blender_* texture: its pattern under `{prefix}_f`, the blend under `prefix`.
fn write_blender(p: &mut Props, prefix: &str, t: &Blender, color: bool, notes: &mut Vec<String>) {
    let f = format!("{prefix}_f");
    let mut set = |key: &str, value: String| p.set(format!("{f}.{key}"), value);
    set("type", quoted(t.name()));
    set("bright", t.base.bright.to_string());
    set("contrast", t.base.contrast.to_string());
    match &t.kind {
        BlenderKind::Clouds(c) => {
            set("noisebasis", quoted(basis_name(c.basis)));
            set("noisetype", hard(c.hard));
            set("noisesize", c.size.to_string());
            set("noisedepth", c.depth.to_string());
            if c.color {
                notes.push(format!("{prefix}: blender_clouds \"color\" exported grey"));
            }
        }
        BlenderKind::Wood(w) => {
            let kind = ["bands", "rings", "bandnoise", "ringnoise"][w.kind as usize];
            set("woodtype", quoted(kind));
            set("noisebasis2", wave_name(w.wave));
            set("noisebasis", quoted(basis_name(w.basis)));
            set("noisetype", hard(w.hard));
            set("noisesize", w.size.to_string());
            set("turbulence", w.turbulence.to_string());
        }
        BlenderKind::Marble(m) => {
            set(
                "marbletype",
                quoted(["soft", "sharp", "sharper"][m.sharpness]),
            );
            set("noisebasis2", wave_name(m.wave));
            set("noisebasis", quoted(basis_name(m.basis)));
            set("noisetype", hard(m.hard));
            set("noisesize", m.size.to_string());
            set("noisedepth", m.depth.to_string());
            set("turbulence", m.turbulence.to_string());
        }
        BlenderKind::Musgrave(m) => {
            set("musgravetype", quoted(musgrave::TYPES[m.kind]));
            set("noisebasis", quoted(basis_name(m.fractal.basis)));
            set("dimension", m.fractal.h.to_string());
            set("lacunarity", m.fractal.lacunarity.to_string());
            set("octaves", m.fractal.octaves.to_string());
            set("offset", m.offset.to_string());
            set("gain", m.gain.to_string());
            set("intensity", m.outscale.to_string());
            set("noisesize", m.size.to_string());
        }
        BlenderKind::Stucci(s) => {
            set(
                "stuccitype",
                quoted(["plastic", "wall_in", "wall_out"][s.kind]),
            );
            set("noisebasis", quoted(basis_name(s.basis)));
            set("noisetype", hard(s.hard));
            set("noisesize", s.size.to_string());
            set("turbulence", s.turbulence.to_string());
        }
        BlenderKind::Noise(n) => set("noisedepth", n.depth.to_string()),
        BlenderKind::Voronoi(v) => {
            let (metric, exponent) = match v.metric {
                Metric::Actual => ("actual_distance", 2.0),
                Metric::Squared => ("distance_squared", 2.0),
                Metric::Manhattan => ("manhattan", 2.0),
                Metric::Chebychev => ("chebychev", 2.0),
                Metric::MinkowskiHalf => ("minkovsky_half", 0.5),
                Metric::MinkowskiFour => ("minkovsky_four", 4.0),
                Metric::Minkowski(e) => ("minkovsky", e),
            };
            set("distmetric", quoted(metric));
            set("exponent", exponent.to_string());
            for (i, w) in v.weights.iter().enumerate() {
                set(&format!("w{}", i + 1), w.to_string());
            }
            set("intensity", v.outscale.to_string());
            set("noisesize", v.size.to_string());
            if v.coltype != 0 {
                notes.push(format!(
                    "{prefix}: blender_voronoi colour type exported as intensity"
                ));
            }
        }
        BlenderKind::DistortedNoise(d) => {
            set("noise_distortion", quoted(basis_name(d.distorted)));
            set("noisebasis", quoted(basis_name(d.distortion)));
            set("distortion", d.amount.to_string());
            set("noisesize", d.size.to_string());
        }
        BlenderKind::Magic(m) => {
            set("noisedepth", m.depth.to_string());
            set("turbulence", m.turbulence.to_string());
        }
        BlenderKind::Blend(b) => {
            let names = [
                "linear",
                "quadratic",
                "easing",
                "diagonal",
                "spherical",
                "halo",
                "radial",
            ];
            set("progressiontype", quoted(names[b.kind]));
            set(
                "direction",
                quoted(if b.flip { "vertical" } else { "horizontal" }),
            );
        }
    }
    write_mapping3d(p, &f, &t.base.mapping);
    p.set(format!("{prefix}.type"), quoted("mix"));
    p.set(
        format!("{prefix}.amount"),
        quoted(&f["scene.textures.".len()..]),
    );
    p.set(format!("{prefix}.texture1"), tex_value(&t.base.tex1, color));
    p.set(format!("{prefix}.texture2"), tex_value(&t.base.tex2, color));
}

/// Writes texture `kind` under `prefix` when it is a procedural one; false for any other kind.
pub fn write_procedural(
    p: &mut Props,
    prefix: &str,
    kind: &TextureKind,
    color: bool,
    scene_dir: &Path,
    notes: &mut Vec<String>,
) -> bool {
    let tv = |t: &ConstOrTexture| tex_value(t, color);
    let set = |p: &mut Props, key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    match kind {
        TextureKind::Fbm(Fbm(o)) | TextureKind::Wrinkled(Wrinkled(o)) => {
            set(p, "type", quoted(kind.name()));
            set(p, "octaves", o.octaves.to_string());
            set(p, "roughness", o.roughness.to_string());
            write_mapping3d(p, prefix, &o.mapping);
        }
        TextureKind::Windy(t) => {
            set(p, "type", quoted("windy"));
            write_mapping3d(p, prefix, &t.mapping);
        }
        TextureKind::Marble(t) => {
            set(p, "type", quoted("marble"));
            set(p, "octaves", t.octaves.octaves.to_string());
            set(p, "roughness", t.octaves.roughness.to_string());
            set(p, "scale", t.scale.to_string());
            set(p, "variation", t.variation.to_string());
            write_mapping3d(p, prefix, &t.octaves.mapping);
        }
        TextureKind::Dots(t) => {
            set(p, "type", quoted("dots"));
            set(p, "inside", tv(&t.inside));
            set(p, "outside", tv(&t.outside));
            write_mapping2d(p, prefix, &t.mapping, notes);
        }
        TextureKind::Brick(t) => {
            let bond = match t.bond {
                Bond::Running if t.run == 0.0 => "stacked",
                Bond::Running => "running",
                Bond::Flemish => "flemish",
                Bond::English => "english",
                Bond::Herringbone => "herringbone",
                Bond::Basket => "basket",
                Bond::ChainLink => "chain link",
            };
            set(p, "type", quoted("brick"));
            set(p, "brickbond", quoted(bond));
            // LuxCore 2.x blends bricktex into brickmodtex by a random amount per brick
            // (plus brickmodbias), where LuxRender 1.x multiplies bricktex by brickmodtex
            // evaluated at the brick's index: the default white brickmodtex turned half the
            // bricks' colour to white. Bias -1 makes LuxCore return bricktex alone, so a
            // constant modulation is folded into it.
            set(p, "brickmodbias", "-1".to_string());
            let brick = match (&t.brick, &t.modulation) {
                (_, ConstOrTexture::Const(m)) if *m == glam::Vec3::ONE => t.brick,
                (ConstOrTexture::Const(b), ConstOrTexture::Const(m)) => {
                    ConstOrTexture::Const(*b * *m)
                }
                _ => {
                    notes.push(format!(
                        "{prefix}: brickmodtex cannot be evaluated per brick in LuxCore; left out"
                    ));
                    t.brick
                }
            };
            set(p, "bricktex", tv(&brick));
            set(p, "mortartex", tv(&t.mortar));
            // The description holds the bond-adjusted sizes; herringbone and basket only read
            // the width.
            set(p, "brickwidth", t.size.x.to_string());
            set(p, "brickdepth", t.size.y.to_string());
            set(p, "brickheight", t.size.z.to_string());
            set(p, "mortarsize", t.mortar_size.to_string());
            set(p, "brickrun", t.run.to_string());
            write_mapping3d(p, prefix, &t.mapping);
        }
        TextureKind::Bilerp(t) => {
            set(p, "type", quoted("bilerp"));
            let c = |v: glam::Vec3| if color { v3(v) } else { v.x.to_string() };
            set(p, "texture00", c(t.v00));
            set(p, "texture01", c(t.v01));
            set(p, "texture10", c(t.v10));
            set(p, "texture11", c(t.v11));
            write_mapping2d(p, prefix, &t.mapping, notes);
        }
        TextureKind::Uv(t) => {
            set(p, "type", quoted("uv"));
            write_mapping2d(p, prefix, &t.mapping, notes);
        }
        TextureKind::Band(t) => {
            set(p, "type", quoted("band"));
            set(p, "amount", tex_value(&t.amount, false));
            for (i, (o, v)) in t.offsets.iter().zip(&t.textures).enumerate() {
                set(p, &format!("offset{i}"), o.to_string());
                let value = match v {
                    ConstOrTexture::Const(c) => v3(*c),
                    ConstOrTexture::Texture(_) => {
                        notes.push(format!("{prefix}: band value {} is a texture; LuxCore takes colours (white used)", i + 1));
                        "1 1 1".into()
                    }
                };
                set(p, &format!("value{i}"), value);
            }
        }
        TextureKind::Arithmetic(t) => {
            set(
                p,
                "type",
                quoted(match t.op {
                    Op::Add => "add",
                    Op::Subtract => "subtract",
                }),
            );
            set(p, "texture1", tv(&t.tex1));
            set(p, "texture2", tv(&t.tex2));
        }
        TextureKind::Harlequin(_) => {
            set(p, "type", quoted("constfloat3"));
            set(p, "value", "0.5 0.5 0.5".into());
            notes.push(format!("{prefix}: LuxCore has no harlequin; grey used"));
        }
        TextureKind::NormalMap(NormalMap(image)) => {
            let img = format!("{prefix}_img");
            p.set(format!("{img}.type"), quoted("imagemap"));
            let path = scene_dir.join(&image.filename);
            p.set(format!("{img}.file"), quoted(&path.to_string_lossy()));
            p.set(format!("{img}.gamma"), image.gamma);
            p.set(format!("{img}.gain"), image.gain);
            write_mapping2d(p, &img, &image.mapping, notes);
            set(p, "type", quoted("normalmap"));
            set(p, "texture", quoted(&img["scene.textures.".len()..]));
        }
        TextureKind::Blender(t) => write_blender(p, prefix, t, color, notes),
        _ => return false,
    }
    true
}

/// LuxCore's uvmapping2d for a uv mapping; other 2D mappings are noted and exported as uv.
fn write_mapping2d(p: &mut Props, prefix: &str, mapping: &Mapping2D, notes: &mut Vec<String>) {
    let (s, d) = match *mapping {
        Mapping2D::Uv {
            uscale,
            vscale,
            udelta,
            vdelta,
        } => ((uscale, vscale), (udelta, vdelta)),
        _ => {
            notes.push(format!("{prefix}: a non-uv 2D mapping exported as uv"));
            ((1.0, 1.0), (0.0, 0.0))
        }
    };
    p.set(format!("{prefix}.mapping.type"), quoted("uvmapping2d"));
    p.set(
        format!("{prefix}.mapping.uvscale"),
        format!("{} {}", s.0, s.1),
    );
    p.set(
        format!("{prefix}.mapping.uvdelta"),
        format!("{} {}", d.0, d.1),
    );
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use yat_tracer::assets::MemorySource;
    use yat_tracer::parse::parse_scene;

    use crate::{export, ExportOptions};

    /// The SDL of a scene with `world`, as (key, value) lines.
    fn sdl(world: &str) -> String {
        let text = format!(
            "LookAt 0 -5 1  0 0 1  0 0 1\nCamera \"perspective\"\n\
             Film \"fleximage\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n\
             WorldBegin\n{world}\nShape \"sphere\"\nWorldEnd\n"
        );
        let mut source = MemorySource::new();
        source.insert("main.lxs", text.into_bytes().into());
        let desc = parse_scene("main.lxs", &source).expect("parses");
        export(&desc, Path::new("/scenes"), &ExportOptions::default())
            .expect("exports")
            .scene
    }

    fn value<'a>(scn: &'a str, key: &str) -> &'a str {
        scn.lines()
            .find_map(|l| l.strip_prefix(key)?.strip_prefix(" = "))
            .unwrap_or_else(|| panic!("{key} missing from\n{scn}"))
    }

    #[test]
    fn noise_textures_and_their_3d_mapping_carry_over() {
        let scn = sdl(
            "Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 5 \"float roughness\" 0.7 \
               \"vector translate\" [1 2 3]\n\
             Material \"matte\" \"texture Kd\" \"f\"",
        );
        assert_eq!(value(&scn, "scene.textures.tex0.type"), "\"fbm\"");
        assert_eq!(value(&scn, "scene.textures.tex0.octaves"), "5");
        assert_eq!(value(&scn, "scene.textures.tex0.roughness"), "0.7");
        assert_eq!(
            value(&scn, "scene.textures.tex0.mapping.type"),
            "\"globalmapping3d\""
        );
        // World to texture: the translation is undone (column-major, last column -t).
        let m: Vec<f32> = value(&scn, "scene.textures.tex0.mapping.transformation")
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(&m[12..15], &[-1.0, -2.0, -3.0]);
    }

    #[test]
    fn brick_colour_is_bricktex_times_a_constant_brickmodtex() {
        // LuxRender 1.x: bricktex x brickmodtex; LuxCore with bias -1: bricktex alone.
        let scn = sdl(
            "Texture \"b\" \"color\" \"brick\" \"color bricktex\" [0.5 0.2 0.1] \
               \"color brickmodtex\" [0.5 1 2]\n\
             Material \"matte\" \"texture Kd\" \"b\"",
        );
        assert_eq!(value(&scn, "scene.textures.tex0.brickmodbias"), "-1");
        assert_eq!(value(&scn, "scene.textures.tex0.bricktex"), "0.25 0.2 0.2");
        assert!(!scn.contains("brickmodtex"), "{scn}");
    }

    #[test]
    fn blender_textures_become_a_mix_around_luxcores_pattern() {
        let scn = sdl(
            "Texture \"w\" \"float\" \"blender_wood\" \"string type\" \"rings\" \"float tex1\" 0.2 \"float tex2\" 0.8\n\
             Material \"matte\" \"texture Kd\" \"w\"",
        );
        assert_eq!(
            value(&scn, "scene.textures.tex0_f.type"),
            "\"blender_wood\""
        );
        assert_eq!(value(&scn, "scene.textures.tex0_f.woodtype"), "\"rings\"");
        assert_eq!(value(&scn, "scene.textures.tex0.type"), "\"mix\"");
        assert_eq!(value(&scn, "scene.textures.tex0.amount"), "\"tex0_f\"");
        assert_eq!(value(&scn, "scene.textures.tex0.texture1"), "0.2");
    }

    #[test]
    fn a_bump_map_becomes_bumptex() {
        let scn = sdl("Texture \"h\" \"float\" \"wrinkled\"\n\
             Material \"glossy\" \"texture bumpmap\" \"h\" \"float bumpmapsampledistance\" 0.002");
        assert_eq!(value(&scn, "scene.materials.mat0.type"), "\"glossy2\"");
        assert_eq!(value(&scn, "scene.materials.mat0.bumptex"), "\"tex0\"");
        assert_eq!(
            value(&scn, "scene.materials.mat0.bumpsamplingdistance"),
            "0.002"
        );
    }
}
