//! Participating media end to end: the volume statements and the attribute state they live
//! in, glass2's index from its volumes, Beer-Lambert behind an index-matched slab and from a
//! camera inside a volume, and a white furnace of scattering smoke.

use std::sync::Arc;

use glam::Vec3;
use yat_tracer::assets::{FsSource, MemorySource};
use yat_tracer::desc::*;
use yat_tracer::diag::Severity;
use yat_tracer::film::Film;
use yat_tracer::material::Glass;
use yat_tracer::medium::{Clear, Homogeneous};
use yat_tracer::parse::parse_scene;

use crate::render::render_whole;
use crate::util::workspace_root;

fn parse(text: &str) -> SceneDesc {
    let mut source = MemorySource::new();
    source.insert("main.lxs", Arc::from(text.as_bytes()));
    parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"))
}

fn render(desc: &SceneDesc, spp: u32) -> Film {
    render_whole(desc, &MemorySource::new(), spp, None)
}

fn mean(film: &Film, x0: u32, x1: u32, y0: u32, y1: u32) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for y in y0..y1 {
        for x in x0..x1 {
            sum += film.pixel(x, y);
        }
    }
    sum / ((x1 - x0) * (y1 - y0)) as f32
}

/// An axis-aligned box from `lo` to `hi` as an inline mesh, wound so that every face's
/// normal points out (the side LuxRender calls the exterior).
fn box_mesh(lo: Vec3, hi: Vec3) -> String {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    // Each face's corners counter-clockwise seen from outside.
    let faces = [
        [0, 2, 3, 1], // z = lo
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let mut indices = Vec::new();
    for f in faces {
        indices.extend([f[0], f[1], f[2], f[0], f[2], f[3]]);
    }
    let points: Vec<String> = (0..8)
        .map(|i| {
            let c = corner(i);
            format!("{} {} {}", c.x, c.y, c.z)
        })
        .collect();
    let indices: Vec<String> = indices.iter().map(|i| i.to_string()).collect();
    format!(
        "Shape \"trianglemesh\" \"integer indices\" [{}] \"point P\" [{}]",
        indices.join(" "),
        points.join(" ")
    )
}

/// Named volumes with LuxRender's defaults, Interior and Exterior saved and restored by
/// attribute blocks, the camera in the Exterior current at WorldEnd and a light in the one at
/// its LightSource, and what is not rendered
/// (an unknown volume name, a heterogeneous volume, a Volume region) warned about.
#[test]
fn volume_statements_follow_the_attribute_state() {
    let desc = parse(
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective"
VolumeIntegrator "multi"
WorldBegin
MakeNamedVolume "air" "clear" "float fresnel" [1.0002926]
MakeNamedVolume "ink" "clear" "color absorption" [0.5 1 2]
MakeNamedVolume "smoke" "homogeneous" "color sigma_a" [0.1 0.2 0.3] "color sigma_s" [2 2 2] "float g" [0.4]
MakeNamedVolume "cloud" "heterogeneous"
Volume "homogeneous" "color sigma_s" [1 1 1]
Exterior "air"
AttributeBegin
  Interior "ink"
  Shape "sphere" "float radius" [1]
  AttributeBegin
    Interior "smoke"
    Exterior ""
    Shape "sphere" "float radius" [0.5]
    LightSource "point" "point from" [0 0 0.1]
  AttributeEnd
  Shape "sphere" "float radius" [0.25]
  Exterior "smoke"
  LightSource "sunsky" "vector sundir" [0 0 1]
AttributeEnd
LightSource "point"
Interior "nothing"
Shape "sphere" "float radius" [2]
Interior "cloud"
Shape "sphere" "float radius" [3]
WorldEnd
"#,
    );
    let media = &desc.volumes.media;
    assert_eq!(media.len(), 3, "{media:?}");
    assert_eq!(
        media[0],
        MediumDesc::Clear(Clear {
            index: 1.000_292_6,
            dispersion: None,
            absorption: Vec3::ZERO
        })
    );
    assert_eq!(
        media[1],
        MediumDesc::Clear(Clear {
            index: 1.5,
            dispersion: None,
            absorption: Vec3::new(0.5, 1.0, 2.0)
        })
    );
    assert_eq!(
        media[2],
        MediumDesc::Homogeneous(Homogeneous {
            index: 1.5,
            dispersion: None,
            sigma_a: Vec3::new(0.1, 0.2, 0.3),
            sigma_s: Vec3::splat(2.0),
            g: Vec3::splat(0.4),
        })
    );
    let (air, ink, smoke) = (Some(MediumId(0)), Some(MediumId(1)), Some(MediumId(2)));
    let sides: Vec<(Option<MediumId>, Option<MediumId>)> = desc
        .shapes
        .iter()
        .map(|s| (s.media.interior, s.media.exterior))
        .collect();
    assert_eq!(
        sides,
        vec![
            (ink, air),
            (smoke, None),
            (ink, air),
            (None, air),
            (None, air)
        ]
    );
    assert_eq!(desc.volumes.camera, air);
    // Each LightSource in the Exterior current at it (a sunsky is two lights, a sun and a sky).
    assert_eq!(desc.lights.len(), 4);
    assert_eq!(desc.volumes.lights, vec![None, smoke, smoke, air]);
    let warnings: Vec<&str> = desc.warnings.iter().map(|w| w.message.as_str()).collect();
    for expected in [
        "heterogeneous",
        "Volume: volume regions",
        "no volume named \"nothing\"",
    ] {
        assert!(
            warnings.iter().any(|w| w.contains(expected)),
            "no warning about {expected}: {warnings:?}"
        );
    }
}

/// glass2 refracts with its shape's Interior index over its Exterior's (1 for a side with no
/// volume, so glass2 with no volumes at all is index 1 as in LuxRender); the other glasses
/// keep their own index.
#[test]
fn glass2_takes_its_index_from_the_interior_volume() {
    let desc = parse(
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
MakeNamedVolume "water" "clear" "float fresnel" [1.33]
MakeNamedVolume "flint" "homogeneous" "float fresnel" [1.7]
Material "glass2"
AttributeBegin
  Interior "water"
  Shape "sphere" "float radius" [1]
AttributeEnd
AttributeBegin
  Interior "flint"
  Exterior "water"
  Shape "sphere" "float radius" [1]
  Shape "sphere" "float radius" [2]
AttributeEnd
Shape "sphere" "float radius" [1]
Material "glass" "float index" [1.6]
Interior "water"
Shape "sphere" "float radius" [1]
WorldEnd
"#,
    );
    let index = |shape: usize| match &desc.materials[desc.shapes[shape].material.0 as usize] {
        MaterialDesc::Glass(Glass { index, .. }) => *index,
        other => panic!("{other:?}"),
    };
    assert_eq!(index(0), ConstOrTexture::float(1.33));
    assert_eq!(index(1), ConstOrTexture::float(1.7 / 1.33));
    // The same glass2 and volumes share one material.
    assert_eq!(desc.shapes[1].material, desc.shapes[2].material);
    assert_eq!(index(3), ConstOrTexture::float(1.0));
    assert_eq!(index(4), ConstOrTexture::float(1.6));
}

/// Through a slab of glass2 whose interior is an index-matched (fresnel 1) clear volume of
/// absorption sigma, seen head-on by an orthographic camera against a uniform sky, every
/// pixel is exp(-sigma d) times what it is without the slab: nothing is reflected, nothing
/// refracted.
#[test]
fn index_matched_slab_transmits_beer_lambert() {
    let sigma = Vec3::new(0.2, 1.0, 3.0);
    let d = 0.5;
    let scene = |slab: bool| {
        parse(&format!(
            r#"Film "fleximage" "integer xresolution" [8] "integer yresolution" [8]
LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic"
WorldBegin
LightSource "infinite" "color L" [1 1 1]
MakeNamedVolume "ink" "clear" "float fresnel" [1] "color absorption" [{} {} {}]
Material "glass2"
Interior "ink"
{}
WorldEnd
"#,
            sigma.x,
            sigma.y,
            sigma.z,
            if slab {
                box_mesh(
                    Vec3::new(-3.0, -3.0, -d / 2.0),
                    Vec3::new(3.0, 3.0, d / 2.0),
                )
            } else {
                String::new()
            }
        ))
    };
    let sky = mean(&render(&scene(false), 4), 0, 8, 0, 8);
    assert!(sky.min_element() > 0.5, "{sky}");
    let expected = (-sigma * d).exp();
    let got = mean(&render(&scene(true), 4), 0, 8, 0, 8) / sky;
    println!("slab: {got} vs exp(-sigma d) = {expected}");
    assert!(
        (got - expected).abs().max_element() < 1e-3,
        "{got} vs exp(-sigma d) = {expected}"
    );
}

/// A camera inside a clear volume (the Exterior current at WorldEnd) sees an emitter 5 units
/// away dimmed by exp(-sigma 5) against the same scene without the volume.
#[test]
fn camera_volume_dims_what_it_sees() {
    let sigma = Vec3::new(0.05, 0.2, 0.4);
    let scene = |exterior: &str| {
        parse(&format!(
            r#"Film "fleximage" "integer xresolution" [8] "integer yresolution" [8]
LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic"
WorldBegin
MakeNamedVolume "fog" "clear" "color absorption" [{} {} {}]
Exterior "{exterior}"
AttributeBegin
  AreaLightSource "area" "color L" [2 2 2]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-3 -3 0  3 -3 0  3 3 0  -3 3 0]
AttributeEnd
WorldEnd
"#,
            sigma.x, sigma.y, sigma.z
        ))
    };
    let (fog, clear) = (scene("fog"), scene(""));
    assert_eq!(fog.volumes.camera, Some(MediumId(0)));
    assert_eq!(clear.volumes.camera, None);
    let unobstructed = mean(&render(&clear, 4), 0, 8, 0, 8);
    assert!(unobstructed.min_element() > 1.0, "{unobstructed}");
    let expected = (-sigma * 5.0).exp();
    let got = mean(&render(&fog, 4), 0, 8, 0, 8) / unobstructed;
    assert!(
        (got - expected).abs().max_element() < 1e-3,
        "{got} vs exp(-5 sigma) = {expected}"
    );
}

/// White furnace: a sphere of smoke that scatters and does not absorb (albedo 1, forward
/// phase), bounded by a null surface, under a uniform sky of radiance 0.5, shows the sky's
/// radiance wherever one looks, within 1%: the free-flight weights, the phase function and
/// next-event estimation at scattering events (through the null boundary) conserve energy.
/// An absorbing smoke of the same scattering is visibly darker.
#[test]
fn scattering_smoke_in_a_furnace_conserves_energy() {
    let film = render(&smoke_furnace(0.0, Some("multi")), 256);
    // The centre pixels look through the sphere's middle (about 3 optical depths).
    let centre = mean(&film, 6, 10, 6, 10);
    println!("furnace: centre {centre} vs sky 0.5");
    for c in centre.to_array() {
        assert!((c - 0.5).abs() < 0.005, "furnace: {centre}");
    }
    let dark = mean(
        &render(&smoke_furnace(1.0, Some("multi")), 64),
        6,
        10,
        6,
        10,
    );
    assert!(dark.max_element() < 0.5 * 0.6, "absorbing smoke: {dark}");
}

/// A sphere of smoke absorbing `sigma_a` and scattering 1.5 a unit, behind a null surface,
/// under a uniform sky of radiance 0.5, seen through its middle; `VolumeIntegrator
/// "volume_integrator"` when given.
fn smoke_furnace(sigma_a: f32, volume_integrator: Option<&str>) -> SceneDesc {
    let integrator = volume_integrator
        .map(|name| format!("VolumeIntegrator \"{name}\"\n"))
        .unwrap_or_default();
    parse(&format!(
        r#"Film "fleximage" "integer xresolution" [16] "integer yresolution" [16]
LookAt 0 -4 0  0 0 0  0 0 1
Camera "perspective" "float fov" [30]
SurfaceIntegrator "path" "integer maxdepth" [256]
{integrator}WorldBegin
LightSource "infinite" "color L" [0.5 0.5 0.5]
MakeNamedVolume "smoke" "homogeneous" "float fresnel" [1] "color sigma_a" [{sigma_a} {sigma_a} {sigma_a}] "color sigma_s" [1.5 1.5 1.5] "float g" [0.5]
Material "null"
Interior "smoke"
Shape "sphere" "float radius" [1]
WorldEnd
"#
    ))
}

/// LuxRender's default volume integrator ("emission", also "none") only attenuates light in
/// volumes: the furnace's smoke then shows the sky through its middle dimmed by its extinction
/// over the diameter, 0.5 exp(-1.5 x 2) = 0.0249 (within 10%, the pixel filter reaching rays
/// through shorter chords), where "multi" shows the whole 0.5; "single" is named a difference.
#[test]
fn the_default_volume_integrator_only_attenuates_as_luxrenders_does() {
    for integrator in [None, Some("emission"), Some("none")] {
        let desc = smoke_furnace(0.0, integrator);
        assert_eq!(
            desc.volumes.media[0],
            MediumDesc::Clear(Clear {
                index: 1.0,
                dispersion: None,
                absorption: Vec3::splat(1.5)
            }),
            "{integrator:?}"
        );
        assert!(
            desc.warnings
                .iter()
                .any(|w| w.severity == Severity::Note && w.message.contains("only attenuates")),
            "{:?}",
            desc.warnings
        );
    }
    let centre = mean(&render(&smoke_furnace(0.0, None), 16), 7, 9, 7, 9);
    let expected = 0.5 * libm::expf(-3.0);
    for c in centre.to_array() {
        assert!(
            (c / expected - 1.0).abs() < 0.1,
            "{centre} against {expected}"
        );
    }
    let single = smoke_furnace(0.0, Some("single"));
    assert!(matches!(
        single.volumes.media[0],
        MediumDesc::Homogeneous(_)
    ));
    assert!(
        single
            .warnings
            .iter()
            .any(|w| w.severity == Severity::Differs
                && w.message.contains("VolumeIntegrator \"single\"")),
        "{:?}",
        single.warnings
    );
}

/// The scene of `scenes/volumes` parses without a warning, with its two volumes on the
/// cube and the sphere, and renders without NaNs; the left third (seen through the cube of
/// glass that absorbs green and blue) is redder than the right third (grey smoke).
#[test]
fn the_volumes_scene_renders_tinted_glass_and_grey_smoke() {
    let path = workspace_root().join("scenes/volumes/volumes.lxs");
    let source = FsSource::for_main_file(&path);
    let desc = parse_scene("volumes.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    assert_eq!(desc.volumes.media.len(), 2);
    let interiors: Vec<Option<MediumId>> = desc.shapes.iter().map(|s| s.media.interior).collect();
    assert_eq!(
        interiors,
        vec![None, Some(MediumId(0)), Some(MediumId(1)), None]
    );
    let film = render_whole(&desc, &source, 16, Some((48, 27)));
    let (left, right) = (mean(&film, 4, 16, 4, 24), mean(&film, 32, 44, 4, 24));
    assert!(
        left.is_finite() && right.min_element() > 0.0,
        "{left} {right}"
    );
    let redness = |c: Vec3| c.x / c.z;
    assert!(
        redness(left) > 1.2 * redness(right),
        "left {left} (through the glass) vs right {right}"
    );
}
