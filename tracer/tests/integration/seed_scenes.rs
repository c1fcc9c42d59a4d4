//! Every complete scene of the original course tracer parses; the incomplete ones fail naming
//! the missing file. The scenes are read at run time from `<workspace>/../shared/seed-project/
//! scenes` (or `$YAT_SEED_SCENES`); the tests skip with a message when they are absent.

use std::f32::consts::PI;
use std::path::Path;

use glam::Vec3;
use yat_tracer::assets::FsSource;
use yat_tracer::desc::{CameraKind, Geometry, LightDesc, SceneDesc, Transport};
use yat_tracer::diag::Severity;
use yat_tracer::lights::InfiniteLight;
use yat_tracer::math::luminance;
use yat_tracer::parse::{parse_scene, ParseError};

use crate::util::seed_scenes;

fn load(dir: &Path, scene: &str) -> Result<SceneDesc, ParseError> {
    let path = dir.join(scene);
    let name = path.file_name().unwrap().to_str().unwrap();
    parse_scene(name, &FsSource::for_main_file(&path))
}

fn triangles(d: &SceneDesc) -> usize {
    d.shapes
        .iter()
        .map(|s| match &s.geometry {
            Geometry::Mesh(m) => m.indices.len(),
            _ => 0,
        })
        .sum()
}

const COMPLETE: &[&str] = &[
    "DepthOfField/depth-of-field-control.lxs",
    "DepthOfField/depth-of-field-low.lxs",
    "DepthOfField/depth-of-field-high.lxs",
    "CornellBox/cornell-box.lxs",
    "CornellBoxFisheye/cornell-box-fisheye-low-fov.lxs",
    "CornellBoxFisheye/cornell-box-fisheye.lxs",
    "CornellBoxFisheye/cornell-box-fisheye-high-fov.lxs",
    "MetalMario/metal-mario-wall.lxs",
    "MetalMario/metal-mario-bg1.lxs",
    "MetalMario/metal-mario-bg2.lxs",
    "MetalMario/metal-mario-bg3.lxs",
    "MetalMario/metal-mario-bg4.lxs",
    "CaptainFalcon/captainfalcon.lxs",
    "GokuSelfie/goku-selfie.lxs",
    "Goku/goku.lxs",
    "Ornstein/ornstein.lxs",
    "Pillar/pillar-point.lxs",
    "Pillar/pillar-reinhard.lxs",
    "Pillar/pillar-sphere-large.lxs",
    "Pillar/pillar-sphere-small.lxs",
    "Pillar/pillar-square-large.lxs",
    "Pillar/pillar-square-small.lxs",
    "Benchmarks/GlassHighIOR.lxs",
    "Benchmarks/GlassHighTransparency.lxs",
    "Benchmarks/GlassLowTransparency.lxs",
    "Benchmarks/GlassMediumTransparency.lxs",
    "Benchmarks/MatteBlue.lxs",
    "Benchmarks/MatteGreen.lxs",
    "Benchmarks/MatteRed.lxs",
    "Benchmarks/MetalHighRoughness.lxs",
    "Benchmarks/MetalLowRoughness.lxs",
    "Benchmarks/MetalMediumRoughness.lxs",
    "Benchmarks/MirrorHighReflectivity.lxs",
    "Benchmarks/MirrorLowReflectivity.lxs",
    "Benchmarks/MirrorMediumReflectivity.lxs",
    "Benchmarks/Spheres.lxs",
    "Benchmarks/TexturedChannels.lxs",
    "Yart.lxs",
];

#[test]
fn every_complete_seed_scene_parses() {
    let Some(dir) = seed_scenes() else { return };
    for scene in COMPLETE {
        let d = load(&dir, scene).unwrap_or_else(|e| panic!("{scene}: {e}"));
        assert!(!d.shapes.is_empty(), "{scene}: no shapes");
        let emitters = d.shapes.iter().filter(|s| s.area_light.is_some()).count();
        assert!(emitters + d.lights.len() > 0, "{scene}: no lights");
        // Differences only about what the files really ask for: the exporter's settings are
        // notes, or listed as changing nothing in the image.
        for w in d
            .warnings
            .iter()
            .filter(|w| w.severity == Severity::Differs)
        {
            assert!(
                !w.message.contains("write_")
                    && !w.message.contains("colorspace")
                    && !w.message.contains("importance"),
                "{scene}: {w}"
            );
        }
    }
}

/// Every seed scene asks for "bidirectional"; the ones with caustics of a delta light render
/// so by default, the others with the path tracer (the same image sooner): the list is what
/// the rule finds in the files, each with the light and the material that make the caustics.
#[test]
fn the_seed_scenes_with_delta_light_caustics_render_bidirectional() {
    let Some(dir) = seed_scenes() else { return };
    let mut bidirectional = Vec::new();
    for scene in COMPLETE {
        let d = load(&dir, scene).unwrap_or_else(|e| panic!("{scene}: {e}"));
        assert_eq!(d.integrator.requested, "bidirectional", "{scene}");
        match (d.transport(), d.delta_caustics()) {
            (Transport::Bidirectional, Some(why)) => bidirectional.push((*scene, why)),
            (Transport::Path, None) => {}
            other => panic!("{scene}: {other:?}"),
        }
    }
    assert_eq!(bidirectional, BIDIRECTIONAL_BY_DEFAULT);
}

const BIDIRECTIONAL_BY_DEFAULT: &[(&str, (&str, &str))] = &[
    ("Benchmarks/GlassHighIOR.lxs", ("point", "glass")),
    ("Benchmarks/GlassHighTransparency.lxs", ("point", "glass")),
    ("Benchmarks/GlassLowTransparency.lxs", ("point", "glass")),
    ("Benchmarks/GlassMediumTransparency.lxs", ("point", "glass")),
    ("Benchmarks/MirrorHighReflectivity.lxs", ("point", "mirror")),
    ("Benchmarks/MirrorLowReflectivity.lxs", ("point", "mirror")),
    (
        "Benchmarks/MirrorMediumReflectivity.lxs",
        ("point", "mirror"),
    ),
    ("Benchmarks/Spheres.lxs", ("point", "mirror")),
    ("Benchmarks/TexturedChannels.lxs", ("point", "mirror")),
];

#[test]
fn every_main_file_is_listed() {
    let Some(dir) = seed_scenes() else { return };
    // Main files are the .lxs files with a WorldBegin (Benchmarks/Lights.lxs is an include).
    let mut found = Vec::new();
    let mut stack = vec![dir.clone()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "lxs")
                && std::fs::read_to_string(&p).unwrap().contains("WorldBegin")
            {
                found.push(p.strip_prefix(&dir).unwrap().to_string_lossy().into_owned());
            }
        }
    }
    let incomplete = INCOMPLETE.iter().map(|(s, _)| *s);
    for f in &found {
        assert!(
            COMPLETE.contains(&f.as_str()) || incomplete.clone().any(|s| s == f),
            "{f} is a main file this test does not cover"
        );
    }
}

const INCOMPLETE: &[(&str, &str)] = &[
    (
        "Dragon/dragon.lxs",
        "dragon/Scene/00001/LuxRender-Geometry.lxo",
    ),
    (
        "Sponza/sponza.lxs",
        "sponza/Scene/00001/LuxRender-Geometry.lxo",
    ),
    ("StanfordBunny.lxs", "Meshes/Bunny.lxo"),
    ("2StanfordBunnies.lxs", "Meshes/Bunny.lxo"),
    ("4StanfordBunnies.lxs", "Meshes/Bunny.lxo"),
    ("4DifferentStanfordBunnies.lxs", "Meshes/Bunny.lxo"),
];

#[test]
fn incomplete_seed_scenes_fail_naming_the_missing_file() {
    let Some(dir) = seed_scenes() else { return };
    for (scene, missing) in INCOMPLETE {
        let e = load(&dir, scene).expect_err(scene);
        let ParseError::Asset { error, .. } = &e else {
            panic!("{scene}: expected a missing-file error, got {e}")
        };
        assert!(
            e.to_string().contains(&format!("\"{missing}\"")),
            "{scene}: {e}"
        );
        assert!(error.to_string().contains("tried"), "{e}");
    }
}

#[test]
fn cornell_box_contents() {
    let Some(dir) = seed_scenes() else { return };
    let d = load(&dir, "CornellBox/cornell-box.lxs").unwrap();
    assert_eq!(d.shapes.len(), 8);
    assert_eq!(triangles(&d), 32);
    assert!(d.lights.is_empty());
    let lamps: Vec<_> = d.shapes.iter().filter(|s| s.area_light.is_some()).collect();
    assert_eq!(lamps.len(), 1);
    // A 0.1 x 0.1 quad scaled by 12.0807: L x gain x power x efficacy / (area x pi x Y(L)).
    let l = Vec3::new(1.0, 0.919_171_9, 0.623_396_5);
    let area = (0.1 * 12.080_707f32).powi(2);
    let expected = l * 2.0 * 100.0 * 17.0 / (area * PI * luminance(l));
    let r = lamps[0].area_light.as_ref().unwrap().radiance().unwrap();
    assert!(
        ((r - expected) / expected).abs().max_element() < 1e-3,
        "{r} vs {expected}"
    );
    assert_eq!((d.film.xresolution, d.film.yresolution), (960, 540));
    assert_eq!(d.integrator.max_depth, 16);
    let eye = d.camera.camera_to_world.transform_point3(Vec3::ZERO);
    assert!((eye - Vec3::new(0.212_302, -10.580_39, 2.727_224)).length() < 1e-4);
    let forward = d.camera.camera_to_world.transform_vector3(Vec3::Z);
    assert!((forward - Vec3::Y).length() < 1e-5);
}

#[test]
fn depth_of_field_spheres_and_lens() {
    let Some(dir) = seed_scenes() else { return };
    for (scene, lens) in [
        ("DepthOfField/depth-of-field-control.lxs", 0.0),
        ("DepthOfField/depth-of-field-low.lxs", 0.05),
        ("DepthOfField/depth-of-field-high.lxs", 0.1),
    ] {
        let d = load(&dir, scene).unwrap();
        let spheres = d
            .shapes
            .iter()
            .filter(|s| matches!(s.geometry, Geometry::Sphere(_)))
            .count();
        assert_eq!(spheres, 3, "{scene}");
        assert_eq!(d.camera.lens_radius, lens, "{scene}");
        assert_eq!(d.textures.len(), 1, "{scene}: the checkerboard floor");
    }
}

#[test]
fn fisheye_and_environment_scenes() {
    let Some(dir) = seed_scenes() else { return };
    let d = load(&dir, "CornellBoxFisheye/cornell-box-fisheye-high-fov.lxs").unwrap();
    assert_eq!(d.camera.kind, CameraKind::Fisheye { fov: 76.0 });
    let d = load(&dir, "MetalMario/metal-mario-bg1.lxs").unwrap();
    let maps: Vec<_> = d
        .lights
        .iter()
        .filter_map(|l| match l {
            LightDesc::Infinite(InfiniteLight { map: Some(m), .. }) => Some(m.filename.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(maps, vec!["backgrounds/bg01.jpg"]);
    assert!(triangles(&d) > 30_000);
    let paths: Vec<_> = d.assets.iter().map(|a| a.path.as_str()).collect();
    assert_eq!(
        paths,
        vec![
            "mario/Scene/00001/LuxRender-Materials.lxm",
            "mario/Scene/00001/LuxRender-Geometry.lxo",
            "backgrounds/bg01.jpg"
        ]
    );
}
