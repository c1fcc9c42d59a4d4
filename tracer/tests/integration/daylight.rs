//! Sun and sky lights end to end: parsed from `.lxs`, rendered, and compared with their
//! analytic values; light colours given as textures; the daylight scene of `scenes/`.

use std::f64::consts::{PI, TAU};
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use yat_tracer::assets::{FsSource, MemorySource};
use yat_tracer::desc::*;
use yat_tracer::film::{Film, MAX_UNIT_SUM};
use yat_tracer::lights::{LightKind, PointLight, SkyLight, SunLight};
use yat_tracer::math::luminance;
use yat_tracer::parse::{blackbody_rgb, parse_scene};
use yat_tracer::render::{plan_units, RenderOverrides, RenderScene, RenderSettings};

use crate::render::render_whole;
use crate::util::workspace_root;

fn parse(text: &str) -> SceneDesc {
    let mut source = MemorySource::new();
    source.insert("main.lxs", Arc::from(text.as_bytes()));
    parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"))
}

fn render(desc: &SceneDesc, source: &dyn yat_tracer::assets::AssetSource, spp: u32) -> Film {
    render_whole(desc, source, spp, None)
}

/// Irradiance on an upward-facing plane from the sky's upper hemisphere, by quadrature of
/// the model (light space is world space here).
fn sky_irradiance(sky: &SkyLight) -> Vec3 {
    let model = sky.model().expect("model");
    let (nt, np) = (400, 800);
    let mut sum = glam::DVec3::ZERO;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) / nt as f64 * PI / 2.0;
        for j in 0..np {
            let phi = (j as f64 + 0.5) / np as f64 * TAU;
            let d = glam::DVec3::new(
                libm::sin(theta) * libm::cos(phi),
                libm::sin(theta) * libm::sin(phi),
                libm::cos(theta),
            );
            let weight =
                libm::cos(theta) * libm::sin(theta) * (PI / 2.0 / nt as f64) * (TAU / np as f64);
            sum += model(d.as_vec3()).as_dvec3() * weight;
        }
    }
    sum.as_vec3() * sky.gain
}

/// A matte ground of albedo 0.5 seen from straight above: every pixel shows 0.5 / pi x the
/// irradiance of the sun (radiance x solid angle x cos) and of the sky's upper half.
#[test]
fn ground_under_sunsky2_has_the_analytic_radiance() {
    for ty in ["sunsky2", "sunsky"] {
        let desc = parse(&format!(
            r#"Film "fleximage" "integer xresolution" [24] "integer yresolution" [24]
LookAt 0 0 1  0 0 0  0 1 0
Camera "perspective" "float fov" [20]
WorldBegin
LightSource "{ty}" "vector sundir" [0.5 0.3 0.8124] "float turbidity" [3] "float gain" [0.001]
Material "matte" "color Kd" [0.5 0.5 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-100 -100 0  100 -100 0  100 100 0  -100 100 0]
WorldEnd
"#
        ));
        let [LightDesc::Sun(sun), LightDesc::Sky(sky)] = &desc.lights[..] else {
            panic!("{ty}: {:?}", desc.lights);
        };
        assert_eq!((sun.relsize, sun.turbidity, sun.gain), (1.0, 3.0, 0.001));
        assert_eq!(sky.name(), if ty == "sunsky2" { "sky2" } else { "sky" });
        let sin2 = f64::from(sun.sin2_max());
        let solid_angle = TAU * (1.0 - (1.0 - sin2).sqrt());
        let e_sun = sun.radiance() * (solid_angle as f32) * sun.to_sun.z;
        let e_sky = sky_irradiance(sky);
        let expected = luminance(e_sun + e_sky) * 0.5 / std::f32::consts::PI;
        let film = render(&desc, &MemorySource::new(), 16);
        let pixels = film.radiance();
        let mean =
            pixels.iter().map(|&p| f64::from(luminance(p))).sum::<f64>() / pixels.len() as f64;
        let err = (mean / f64::from(expected) - 1.0).abs();
        assert!(
            err < 0.02,
            "{ty}: mean {mean}, expected {expected} (sun {}, sky {})",
            luminance(e_sun),
            luminance(e_sky)
        );
        // The sun gives most of it on a clear day.
        assert!(luminance(e_sun) > 2.0 * luminance(e_sky), "{ty}");
    }
}

#[test]
fn light_colours_may_be_textures() {
    let desc = parse(
        r#"Camera "perspective"
WorldBegin
Texture "warm" "color" "blackbody" "float temperature" [3000]
Texture "half" "color" "scale" "texture tex1" "warm" "color tex2" [0.5 0.5 0.5]
Texture "img" "color" "checkerboard" "color tex1" [1 0 0] "color tex2" [0 0 1]
LightSource "point" "texture L" "warm" "float gain" [2]
LightSource "point" "texture L" "half"
LightSource "point" "color L" "img"
WorldEnd
"#,
    );
    let intensities: Vec<Vec3> = desc
        .lights
        .iter()
        .map(|l| match l {
            LightDesc::Point(PointLight { intensity, .. }) => *intensity,
            other => panic!("{other:?}"),
        })
        .collect();
    let warm = blackbody_rgb(3000.0);
    assert!(
        (intensities[0] - 2.0 * warm).abs().max_element() < 1e-5,
        "{intensities:?}"
    );
    assert!(
        (intensities[1] - 0.5 * warm).abs().max_element() < 1e-5,
        "{intensities:?}"
    );
    // A checkerboard varies over a surface: the default colour, with a warning naming it.
    assert_eq!(intensities[2], Vec3::ONE);
    assert!(
        desc.warnings
            .iter()
            .any(|w| w.to_string().contains("\"img\"")),
        "{:?}",
        desc.warnings
    );
}

#[test]
fn the_daylight_scene_renders_lit() {
    let path = workspace_root().join("scenes/daylight/daylight.lxs");
    let source = FsSource::for_main_file(Path::new(&path));
    let desc = parse_scene("daylight.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    assert!(matches!(
        desc.lights[..],
        [LightDesc::Sun(SunLight { .. }), LightDesc::Sky(_)]
    ));
    let settings = RenderSettings::resolve(
        &desc,
        &RenderOverrides {
            spp: Some(4),
            resolution: Some((64, 36)),
            ..Default::default()
        },
    );
    let scene = RenderScene::build(&desc, &source, &settings).expect("scene builds");
    let mut film = Film::new(scene.frame());
    for unit in plan_units(&settings) {
        film.add(&scene.render_unit(&unit).0).unwrap();
    }
    let pixels = film.radiance();
    let mean = pixels.iter().map(|&p| f64::from(luminance(p))).sum::<f64>() / pixels.len() as f64;
    // Sunlit ground (albedo ~0.3) and a clear sky: some thousands of cd/m^2.
    assert!((1000.0..20_000.0).contains(&mean), "mean luminance {mean}");
    // Through the file's own tone map the image is neither black nor blown out.
    let display = film.to_display(&desc.film);
    let mean_byte = display.pixels().map(|p| f64::from(p[1])).sum::<f64>() / (64.0 * 36.0);
    assert!(
        (40.0..220.0).contains(&mean_byte),
        "mean display value {mean_byte}"
    );
}

/// A pixel that looks straight at the sun at LuxRender's gain of 1 sums past what the film
/// holds within a few hundred samples; its unit reports the clamped sum (which every
/// coordinator accepts) and the film shows it saturated, not black or wrapped.
#[test]
fn a_pixel_on_the_sun_reports_a_sum_the_film_holds() {
    let desc = parse(
        r#"Film "fleximage" "integer xresolution" [1] "integer yresolution" [1]
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [0.01]
WorldBegin
LightSource "sun" "vector sundir" [0 0 1]
WorldEnd
"#,
    );
    let settings = RenderSettings::resolve(
        &desc,
        &RenderOverrides {
            spp: Some(4096),
            ..Default::default()
        },
    );
    let scene = RenderScene::build(&desc, &MemorySource::new(), &settings).expect("builds");
    let mut film = Film::new(scene.frame());
    for unit in plan_units(&settings) {
        let (buffer, _) = scene.render_unit(&unit);
        for &[r, g, b] in &buffer.rgb {
            for v in [r, g, b] {
                assert!(v.is_finite() && v.abs() <= MAX_UNIT_SUM, "{v}");
            }
        }
        film.add(&buffer).unwrap();
    }
    // 512 samples of a unit at about 1e9 each pass the clamp: the sums sit at it.
    assert!(film.pixel(0, 0).min_element() > 1e7, "{}", film.pixel(0, 0));
}
