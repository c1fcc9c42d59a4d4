//! Area lights whose colour is a texture (`AreaLightSource "area" "texture L" "name"`): the
//! texture is evaluated where the surface is seen and where a light sample lands, with the
//! same value either way, and LuxRender's power normalisation divides by its mean.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use yat_tracer::assets::{AssetSource, MemorySource};
use yat_tracer::desc::{LatLongConvention, SceneDesc};
use yat_tracer::geometry::SceneGeometry;
use yat_tracer::lights::Lights;
use yat_tracer::math::Ray;
use yat_tracer::parse::parse_scene;
use yat_tracer::texture::Textures;

/// A 2 x 2 square at z = 1 facing down, u along x: its left or right half (u below or above
/// 0.5) white, the other black; and a sphere of radius 0.5 at (0, 0, 4) with a 3D checker.
fn scene(area_light: &str) -> (SceneDesc, SceneGeometry, Lights) {
    let text = format!(
        "Camera \"perspective\"\nWorldBegin\n\
         Texture \"halves\" \"color\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [1]\n\
           \"color tex1\" [1 1 1] \"color tex2\" [0 0 0]\n\
         Texture \"checks\" \"color\" \"checkerboard\" \"integer dimension\" [3]\n\
           \"color tex1\" [2 2 2] \"color tex2\" [0.5 0.5 0.5] \"vector scale\" [4 4 4]\n\
         AttributeBegin\n{area_light}\n\
         Shape \"trianglemesh\" \"integer indices\" [0 2 1 0 3 2]\n\
           \"point P\" [-1 -1 1 1 -1 1 1 1 1 -1 1 1] \"float uv\" [0 0 1 0 1 1 0 1]\n\
         AttributeEnd\n\
         AttributeBegin\nAreaLightSource \"area\" \"texture L\" \"checks\" \"float power\" [0]\n\
         Translate 0 0 4\nShape \"sphere\" \"float radius\" [0.5]\nAttributeEnd\n\
         WorldEnd\n"
    );
    let mut source = MemorySource::new();
    source.insert("main.lxs", Arc::from(text.as_bytes()));
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let (geometry, lights) = geometry_and_lights(&desc, &source, "main.lxs");
    (desc, geometry, lights)
}

/// The geometry and lights of `desc` as the renderer builds them (its textures shared with
/// the area lights); panics naming `what` if they do not build. Shared with
/// `geometry_on_scenes`.
pub fn geometry_and_lights(
    desc: &SceneDesc,
    source: &dyn AssetSource,
    what: &str,
) -> (SceneGeometry, Lights) {
    let geometry = SceneGeometry::build(&desc.shapes);
    let textures =
        Arc::new(Textures::new(&desc.textures, source).unwrap_or_else(|e| panic!("{what}: {e}")));
    let lights = Lights::build(
        &desc.shapes,
        &desc.lights,
        &geometry,
        &textures,
        source,
        LatLongConvention::Seed,
    )
    .unwrap_or_else(|e| panic!("{what}: {e}"));
    (geometry, lights)
}

/// The radiance seen looking straight up from `p` (the square's emission there).
fn seen_up(geometry: &SceneGeometry, lights: &Lights, p: Vec3) -> Vec3 {
    let hit = geometry
        .intersect(&Ray::new(p, Vec3::Z), f32::INFINITY)
        .expect("the square is above");
    lights.emitted(&hit, -Vec3::Z)
}

/// Irradiance at `p` on an upward-facing plane from the square's points with x in
/// [x0, x1], radiance 1 (quadrature of h^2 / r^4 over the area).
fn square_irradiance(p: Vec3, x0: f64, x1: f64) -> f64 {
    let n = 400;
    let (dx, dy) = ((x1 - x0) / n as f64, 2.0 / n as f64);
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let x = x0 + (i as f64 + 0.5) * dx - f64::from(p.x);
            let y = -1.0 + (j as f64 + 0.5) * dy - f64::from(p.y);
            let h = 1.0 - f64::from(p.z);
            let r2 = x * x + y * y + h * h;
            sum += h * h / (r2 * r2) * dx * dy;
        }
    }
    sum
}

/// A deterministic sequence in [0, 1)^3 (a 3D Halton-like lattice is not needed here).
fn u3(i: u32, n: u32) -> (f32, Vec2) {
    let golden = 0.618_034_f64;
    let a = (f64::from(i) + 0.5) / f64::from(n);
    let b = (f64::from(i) * golden).fract();
    let c = (f64::from(i) * 0.754_877_666_2).fract();
    (a as f32, Vec2::new(b as f32, c as f32))
}

#[test]
fn a_textured_area_light_emits_its_texture_where_seen_and_where_sampled() {
    let (_, geometry, lights) =
        scene("AreaLightSource \"area\" \"texture L\" \"halves\" \"float power\" [0]");
    let (left, right) = (Vec3::new(-0.5, 0.0, 0.0), Vec3::new(0.5, 0.0, 0.0));
    let (seen_left, seen_right) = (
        seen_up(&geometry, &lights, left),
        seen_up(&geometry, &lights, right),
    );
    // One half shows the texture's white, the other its black.
    assert!(
        (seen_left == Vec3::ONE && seen_right == Vec3::ZERO)
            || (seen_left == Vec3::ZERO && seen_right == Vec3::ONE),
        "{seen_left} {seen_right}"
    );
    let white_x = if seen_left == Vec3::ONE {
        (-1.0, 0.0)
    } else {
        (0.0, 1.0)
    };

    // Light sampling from points of the floor below: the irradiance of the white half only.
    let n = 1 << 16;
    for p in [left, right, Vec3::ZERO, Vec3::new(-0.9, 0.4, 0.0)] {
        let mut e = 0.0f64;
        for i in 0..n {
            let (u_select, u) = u3(i, n);
            if let Some(s) = lights.sample(p, None, u_select, u) {
                // Only the square is below z = 1: the sphere's samples point up past it and
                // are shadowed by the square's back in a render; here they are left out.
                if s.wi.z > 0.0 && s.dist < 1.5 / s.wi.z {
                    e += f64::from(s.li.x * s.wi.z / s.pdf);
                }
            }
        }
        e /= f64::from(n);
        let expected = square_irradiance(p, white_x.0, white_x.1);
        assert!(
            (e - expected).abs() < 0.01 * expected.max(0.05),
            "irradiance at {p}: sampled {e:.4}, quadrature {expected:.4}"
        );
    }
    // Below the centre the white half gives exactly half of the whole square's irradiance,
    // 4 a/sqrt(a^2+h^2) atan(a/sqrt(a^2+h^2)) / 2 with a = h = 1.
    let s = 1.0 / 2f64.sqrt();
    let half = 2.0 * s * libm::atan(s);
    assert!((square_irradiance(Vec3::ZERO, white_x.0, white_x.1) - half).abs() < 1e-3);
}

#[test]
fn a_sampled_point_carries_the_radiance_a_ray_sees_there() {
    let (_, geometry, lights) =
        scene("AreaLightSource \"area\" \"texture L\" \"halves\" \"float power\" [0]");
    let n = 4096;
    let mut checked = [0, 0];
    for from in [Vec3::new(0.3, -0.2, 0.0), Vec3::new(0.1, 0.2, 2.5)] {
        for i in 0..n {
            let (u_select, u) = u3(i, n);
            let Some(s) = lights.sample(from, None, u_select, u) else {
                continue;
            };
            let Some(hit) = geometry.intersect(&Ray::new(from, s.wi), f32::INFINITY) else {
                continue;
            };
            // The ray's first hit is the sampled point (not another surface in front).
            if (hit.t - s.dist).abs() > 1e-3 * s.dist {
                continue;
            }
            let seen = lights.emitted(&hit, -s.wi);
            assert!(
                (seen - s.li).abs().max_element() <= 1e-4 * s.li.max_element().max(1.0),
                "from {from}: sampled {} but seen {seen} at {}",
                s.li,
                hit.p
            );
            checked[usize::from(hit.p.z > 2.0)] += 1;
        }
    }
    // Both the square and the sphere were compared, over both of each one's colours.
    assert!(checked[0] > 500 && checked[1] > 500, "{checked:?}");
}

#[test]
fn power_normalisation_divides_by_the_texture_mean() {
    // power x efficacy / (area x pi x mean luminance): 100 x 17 / (4 pi 0.5) for the white
    // half, the texture's mean being 0.5.
    let (_, geometry, lights) = scene("AreaLightSource \"area\" \"texture L\" \"halves\" \"float power\" [100] \"float efficacy\" [17]");
    let white = [Vec3::new(-0.5, 0.0, 0.0), Vec3::new(0.5, 0.0, 0.0)]
        .map(|p| seen_up(&geometry, &lights, p).x)
        .into_iter()
        .fold(0.0, f32::max);
    let expected = 1700.0 / (4.0 * PI * 0.5);
    assert!(
        (f64::from(white) - expected).abs() < 1e-3 * expected,
        "{white} vs {expected}"
    );
}
