//! The LuxRender 1.x materials beyond the course's set, read from scenes held in memory:
//! carpaint presets and layers, glossycoating, glossytranslucent, layered, shinymetal,
//! velvet, scatter and metal with an .nk data file.

use std::sync::Arc;

use glam::{Affine3A, Vec2, Vec3};
use yat_tracer::assets::{AssetKind, MemorySource};
use yat_tracer::desc::*;
use yat_tracer::geometry::SurfaceHit;
use yat_tracer::material::{carpaint, CarPaint, GlossyTranslucent, Materials, Metal};
use yat_tracer::parse::parse_scene;
use yat_tracer::texture::Textures;

fn parse_with(body: &str, files: &[(&str, &[u8])]) -> Result<SceneDesc, String> {
    let text = format!("Camera \"perspective\"\nWorldBegin\n{body}\nWorldEnd\n");
    let mut s = MemorySource::new();
    s.insert("main.lxs", Arc::from(text.as_bytes()));
    for (name, bytes) in files {
        s.insert(*name, Arc::from(*bytes));
    }
    parse_scene("main.lxs", &s).map_err(|e| e.to_string())
}

fn world(body: &str) -> SceneDesc {
    parse_with(body, &[]).unwrap_or_else(|e| panic!("{e}"))
}

fn material(d: &SceneDesc, shape: usize) -> &MaterialDesc {
    &d.materials[d.shapes[shape].material.0 as usize]
}

#[test]
fn every_extra_material_is_read_as_itself() {
    let d = world(
        "Material \"carpaint\"\nShape \"sphere\"\n\
         Material \"velvet\"\nShape \"sphere\"\n\
         Material \"shinymetal\"\nShape \"sphere\"\n\
         Material \"glossytranslucent\"\nShape \"sphere\"\n\
         Material \"scatter\"\nShape \"sphere\"\n\
         MakeNamedMaterial \"base\" \"string type\" \"matte\"\n\
         MakeNamedMaterial \"coated\" \"string type\" \"glossycoating\" \"string basematerial\" \"base\"\n\
         NamedMaterial \"coated\"\nShape \"sphere\"\n\
         MakeNamedMaterial \"stack\" \"string type\" \"layered\" \"string namedmaterial1\" \"coated\" \"float opacity1\" [0.25] \"string namedmaterial2\" \"base\"\n\
         NamedMaterial \"stack\"\nShape \"sphere\"",
    );
    let names: Vec<&str> = (0..7).map(|i| material(&d, i).name()).collect();
    assert_eq!(
        names,
        [
            "carpaint",
            "velvet",
            "shinymetal",
            "glossytranslucent",
            "scatter",
            "glossycoating",
            "layered"
        ]
    );
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}

#[test]
fn carpaint_presets_and_custom_layers() {
    let d = parse_with(
        "Material \"carpaint\" \"string name\" \"bmw339\"\nShape \"sphere\"\n\
         Material \"carpaint\" \"string name\" \"no such paint\"\nShape \"sphere\"\n\
         Material \"carpaint\"\nShape \"sphere\"\n\
         Material \"carpaint\" \"color Kd\" [0.5 0.1 0.1] \"float M2\" [0.25] \"color Ka\" [0.1 0.2 0.3] \"float d\" [0.5]\nShape \"sphere\"\n\
         Material \"carpaint\" \"string name\" \"white\" \"color Kd\" [1 0 0]\nShape \"sphere\"",
        &[],
    )
    .unwrap();
    let paint = |i: usize| match material(&d, i) {
        MaterialDesc::CarPaint(p) => p.clone(),
        other => panic!("carpaint expected, got {other:?}"),
    };
    let preset = |name: &str| {
        CarPaint::from_preset(
            carpaint::preset(name).unwrap(),
            ConstOrTexture::float(0.0),
            ConstOrTexture::float(0.0),
        )
    };
    assert_eq!(paint(0), preset("bmw339"));
    assert_eq!(
        paint(0).kd,
        ConstOrTexture::color(Vec3::new(0.012, 0.015, 0.016))
    );
    // An unknown preset warns and is ford f8, LuxRender's default.
    assert_eq!(paint(1), preset("ford f8"));
    assert!(d
        .warnings
        .iter()
        .any(|w| w.message.contains("no such paint")));
    // No name: every missing layer parameter is ford f8's.
    assert_eq!(paint(2), preset("ford f8"));
    let custom = paint(3);
    assert_eq!(custom.kd, ConstOrTexture::color(Vec3::new(0.5, 0.1, 0.1)));
    assert_eq!(custom.m[1], ConstOrTexture::float(0.25));
    assert_eq!(custom.m[0], preset("ford f8").m[0]);
    assert_eq!(custom.ks, preset("ford f8").ks);
    assert_eq!(
        (custom.ka, custom.depth),
        (
            ConstOrTexture::color(Vec3::new(0.1, 0.2, 0.3)),
            ConstOrTexture::float(0.5)
        )
    );
    // With a preset, LuxRender ignores the layer parameters (a warning says so).
    assert_eq!(paint(4), preset("white"));
    assert!(d
        .warnings
        .iter()
        .any(|w| w.message.contains("\"Kd\" is ignored")));
    assert_eq!(carpaint::PRESETS.len(), 8);
}

#[test]
fn glossytranslucent_back_face_parameters() {
    let d = world(
        "Material \"glossytranslucent\" \"color Ks\" [0.2 0.2 0.2] \"color backface_Ks\" [0.7 0.7 0.7]\nShape \"sphere\"\n\
         Material \"glossytranslucent\" \"bool onesided\" \"false\" \"color backface_Ks\" [0.7 0.7 0.7] \"float backface_uroughness\" [0.3]\nShape \"sphere\"",
    );
    let MaterialDesc::GlossyTranslucent(GlossyTranslucent { front, back, .. }) = material(&d, 0)
    else {
        panic!()
    };
    assert_eq!(front.ks, ConstOrTexture::float(0.2));
    assert!(
        back.is_none(),
        "onesided (the default) shares the front coat"
    );
    let MaterialDesc::GlossyTranslucent(GlossyTranslucent { back, .. }) = material(&d, 1) else {
        panic!()
    };
    let back = back.as_ref().expect("a back coat");
    assert_eq!(
        (back.ks, back.uroughness, back.vroughness),
        (
            ConstOrTexture::float(0.7),
            ConstOrTexture::float(0.3),
            ConstOrTexture::float(0.0)
        )
    );
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}

fn hit() -> SurfaceHit {
    SurfaceHit {
        t: 1.0,
        p: Vec3::ZERO,
        ng: Vec3::Z,
        ns: Vec3::Z,
        uv: Vec2::ZERO,
        dpdu: Vec3::X,
        dpdv: Vec3::Y,
        shape: 0,
        prim: 0,
    }
}

/// The fraction of `n` stratified mix numbers for which material `id` is a pass-through,
/// and the mean of f(wo = wi = normal) * pi over the others.
fn resolve_stats(d: &SceneDesc, id: MaterialId) -> (f64, f64) {
    let materials = Materials::new(d.materials.clone());
    let textures = Textures::default();
    let n = 10_000;
    let (mut through, mut f) = (0u32, 0.0f64);
    for i in 0..n {
        let u = (i as f32 + 0.5) / n as f32;
        let bsdf = materials.bsdf(id, &hit(), &Affine3A::IDENTITY, &textures, u);
        if bsdf.is_pass_through() {
            through += 1;
        } else {
            f += f64::from(bsdf.eval(Vec3::Z, Vec3::Z).x) * std::f64::consts::PI;
        }
    }
    let through = f64::from(through) / f64::from(n);
    (through, f / (f64::from(n) * (1.0 - through).max(1e-9)))
}

#[test]
fn layered_catches_rays_top_down_and_lets_the_rest_through() {
    let d = world(
        "MakeNamedMaterial \"a\" \"string type\" \"matte\" \"color Kd\" [0.2 0.2 0.2]\n\
         MakeNamedMaterial \"b\" \"string type\" \"matte\" \"color Kd\" [0.8 0.8 0.8]\n\
         MakeNamedMaterial \"s\" \"string type\" \"layered\" \"string namedmaterial1\" \"a\" \"float opacity1\" [0.25] \"string namedmaterial2\" \"b\" \"float opacity2\" [0.5]\n\
         NamedMaterial \"s\"\nShape \"sphere\"",
    );
    let (through, f) = resolve_stats(&d, d.shapes[0].material);
    // Top layer 0.25; second 0.75 * 0.5 = 0.375; the rest, 0.375, passes through.
    assert!((through - 0.375).abs() < 1e-3, "{through}");
    let expected = (0.25 * 0.2 + 0.375 * 0.8) / 0.625;
    assert!((f - expected).abs() < 1e-3, "{f} vs {expected}");
}

#[test]
fn glossycoating_puts_its_coat_over_its_base() {
    let d = world(
        "MakeNamedMaterial \"base\" \"string type\" \"matte\" \"color Kd\" [0.5 0.5 0.5]\n\
         MakeNamedMaterial \"c\" \"string type\" \"glossycoating\" \"string basematerial\" \"base\" \"color Ks\" [0.04 0.04 0.04] \"float uroughness\" [0] \"float vroughness\" [0]\n\
         NamedMaterial \"c\"\nShape \"sphere\"\n\
         Material \"glossy\" \"color Kd\" [0.5 0.5 0.5] \"color Ks\" [0.04 0.04 0.04] \"float uroughness\" [0] \"float vroughness\" [0]\nShape \"sphere\"",
    );
    let materials = Materials::new(d.materials.clone());
    let textures = Textures::default();
    let coated = materials.bsdf(
        d.shapes[0].material,
        &hit(),
        &Affine3A::IDENTITY,
        &textures,
        0.5,
    );
    let glossy = materials.bsdf(
        d.shapes[1].material,
        &hit(),
        &Affine3A::IDENTITY,
        &textures,
        0.5,
    );
    // A smooth coat over matte is glossy: the base seen through it at normal incidence is
    // Kd (1 - 0.04)^2 / (1 - F_avg) / pi.
    let f_avg = 0.04 + 0.96 / 21.0;
    let expected = 0.5 * 0.96 * 0.96 / (1.0 - f_avg) / std::f32::consts::PI;
    for bsdf in [coated, glossy] {
        let f = bsdf.eval(Vec3::Z, Vec3::Z).x;
        assert!((f - expected).abs() < 1e-5, "{f} vs {expected}");
    }
}

#[test]
fn shinymetal_mixes_mirror_and_glossy_in_proportion() {
    let d = world(
        "Material \"shinymetal\" \"color Kr\" [0.3 0.3 0.3] \"color Ks\" [0.6 0.6 0.6]\nShape \"sphere\"",
    );
    let materials = Materials::new(d.materials.clone());
    let textures = Textures::default();
    let n = 10_000;
    let mirrors = (0..n)
        .filter(|i| {
            let u = (*i as f32 + 0.5) / n as f32;
            materials
                .bsdf(
                    d.shapes[0].material,
                    &hit(),
                    &Affine3A::IDENTITY,
                    &textures,
                    u,
                )
                .is_specular()
        })
        .count();
    // |Kr| / (|Kr| + |Ks|) of the hits are the mirror.
    assert!(
        (mirrors as f64 / f64::from(n) - 1.0 / 3.0).abs() < 1e-3,
        "{mirrors}"
    );
}

#[test]
fn metal_reads_an_nk_file_and_names_the_line_of_a_bad_one() {
    let nk = b"; a luxpop file\n4000 1.0 2.0\n7000 4.0 5.0\n";
    let d = parse_with(
        "Material \"metal\" \"string name\" \"data/x.nk\"\nShape \"sphere\"",
        &[("data/x.nk", nk)],
    )
    .unwrap();
    let MaterialDesc::Metal(Metal {
        fresnel: Fresnel::Conductor { eta, k },
        ..
    }) = material(&d, 0)
    else {
        panic!()
    };
    // 650, 550 and 450 nm between 400 nm (1, 2) and 700 nm (4, 5).
    assert!(
        (*eta - Vec3::new(3.5, 2.5, 1.5)).abs().max_element() < 1e-5,
        "{eta}"
    );
    assert!(
        (*k - Vec3::new(4.5, 3.5, 2.5)).abs().max_element() < 1e-5,
        "{k}"
    );
    assert!(d
        .assets
        .iter()
        .any(|a| a.path == "data/x.nk" && a.kind == AssetKind::Nk));

    let err = parse_with(
        "Material \"metal\" \"string name\" \"bad.nk\"\nShape \"sphere\"",
        &[("bad.nk", b"4000 1.0 2.0\n5000 1.0 oops\n")],
    )
    .unwrap_err();
    assert!(
        err.contains("main.lxs:3") && err.contains("\"bad.nk\" line 2"),
        "{err}"
    );
}
