use std::f32::consts::{PI, TAU};
use std::io::Cursor;
use std::sync::Arc;

use glam::{DVec3, Mat4, Vec2, Vec3};

use super::*;
use crate::assets::MemorySource;
use crate::desc::{AreaLightDesc, Disk, Geometry, ShapeDesc, Sphere};
use crate::geometry::tests::{mesh, scene_desc, shape, sphere};
use crate::math::{luminance, Frame, Ray};

fn build_with(
    shapes: Vec<ShapeDesc>,
    lights: Vec<LightDesc>,
    source: &MemorySource,
    latlong: LatLongConvention,
) -> (SceneGeometry, Lights) {
    let desc = scene_desc(shapes, lights);
    let geometry = SceneGeometry::build(&desc.shapes);
    let lights = Lights::build(
        &desc.shapes,
        &desc.lights,
        &geometry,
        &Arc::default(),
        source,
        latlong,
    )
    .unwrap();
    (geometry, lights)
}

fn build(shapes: Vec<ShapeDesc>, lights: Vec<LightDesc>) -> (SceneGeometry, Lights) {
    build_with(
        shapes,
        lights,
        &MemorySource::new(),
        LatLongConvention::Seed,
    )
}

fn emitter(geometry: Geometry, m: Mat4, radiance: Vec3) -> ShapeDesc {
    ShapeDesc {
        area_light: Some(AreaLightDesc::constant(radiance)),
        media: Default::default(),
        ..shape(geometry, m)
    }
}

/// A square of side `side` centred at the origin in the z = 0 plane, facing -z.
fn square_facing_down(side: f32) -> Geometry {
    let h = side / 2.0;
    Geometry::Mesh(Arc::new(mesh(
        vec![
            Vec3::new(-h, -h, 0.0),
            Vec3::new(h, -h, 0.0),
            Vec3::new(h, h, 0.0),
            Vec3::new(-h, h, 0.0),
        ],
        vec![[0, 2, 1], [0, 3, 2]],
    )))
}

fn disk(radius: f32) -> Geometry {
    Geometry::Disk(Disk {
        height: 0.0,
        radius,
        inner_radius: 0.0,
        phimax: 360.0,
    })
}

fn point(position: Vec3, intensity: f32) -> LightDesc {
    LightDesc::Point(PointLight {
        position,
        intensity: Vec3::splat(intensity),
    })
}

/// Monte Carlo estimate of the irradiance at `p` on a surface facing `n`, by light sampling.
fn irradiance(lights: &Lights, p: Vec3, n: Vec3, samples: u32, seed: u64) -> Vec3 {
    let mut rng = fastrand::Rng::with_seed(seed);
    let mut sum = glam::DVec3::ZERO;
    for _ in 0..samples {
        let u = Vec2::new(rng.f32(), rng.f32());
        if let Some(s) = lights.sample(p, None, rng.f32(), u) {
            let cos = s.wi.dot(n).max(0.0);
            sum += (s.li * cos / s.pdf).as_dvec3();
        }
    }
    (sum / f64::from(samples)).as_vec3()
}

fn rel_err(got: f32, want: f32) -> f32 {
    (got / want - 1.0).abs()
}

#[test]
fn square_emitter_irradiance_matches_the_form_factor() {
    let radiance = Vec3::new(2.0, 1.0, 0.5);
    let (side, h) = (1.0, 1.5);
    let m = Mat4::from_translation(Vec3::new(0.0, 0.0, h));
    let (_, lights) = build(vec![emitter(square_facing_down(side), m, radiance)], vec![]);
    let e = irradiance(&lights, Vec3::ZERO, Vec3::Z, 400_000, 1);
    // Point under the corner of an a x b rectangle parallel to it at height h:
    // F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))].
    let x = side / 2.0 / h;
    let s = (1.0 + x * x).sqrt();
    let corner = (2.0 * x / s * libm::atanf(x / s)) / (2.0 * PI);
    let expected = radiance * PI * 4.0 * corner;
    for c in 0..3 {
        assert!(
            rel_err(e[c], expected[c]) < 0.01,
            "E = {e}, expected {expected}"
        );
    }

    // Small and far: E ~ L A cos / d^2, seen 30 degrees off the emitter's axis.
    let (side, d) = (0.2, 10.0);
    let (_, lights) = build(
        vec![emitter(square_facing_down(side), Mat4::IDENTITY, Vec3::ONE)],
        vec![],
    );
    let p = Vec3::new(0.0, d * 0.5, -d * 0.75f32.sqrt());
    let to_light = -p.normalize();
    let e = irradiance(&lights, p, to_light, 100_000, 2);
    let expected = side * side * libm::cosf((30f32).to_radians()) / (d * d);
    assert!(
        rel_err(e.x, expected) < 0.02,
        "E = {}, expected {expected}",
        e.x
    );
}

#[test]
fn sphere_and_disk_emitters_give_exact_irradiance() {
    // A sphere of radius r seen from distance d: E = pi L (r/d)^2 on a surface facing it,
    // sampled through the cone it subtends.
    let (r, d) = (0.5, 3.0);
    let (_, lights) = build(vec![emitter(sphere(r), Mat4::IDENTITY, Vec3::ONE)], vec![]);
    let p = Vec3::new(0.0, -d, 0.0);
    let e = irradiance(&lights, p, Vec3::Y, 200_000, 3);
    assert!(rel_err(e.x, PI * (r / d) * (r / d)) < 0.005, "E = {}", e.x);
    // Tiny and far: the small-angle branch of the cone sampling.
    let (r, d) = (0.01, 20.0);
    let (_, lights) = build(vec![emitter(sphere(r), Mat4::IDENTITY, Vec3::ONE)], vec![]);
    let e = irradiance(&lights, Vec3::new(d, 0.0, 0.0), -Vec3::X, 20_000, 4);
    assert!(rel_err(e.x, PI * (r / d) * (r / d)) < 0.005, "E = {}", e.x);

    // A disk of radius R at height h above the point, facing it (the disk faces +z, so turn
    // it over): E = pi L R^2 / (h^2 + R^2). Uniform area sampling.
    let (radius, h) = (1.0, 2.0);
    let m = Mat4::from_translation(Vec3::new(0.0, 0.0, h)) * Mat4::from_rotation_x(PI);
    let (_, lights) = build(vec![emitter(disk(radius), m, Vec3::ONE)], vec![]);
    let e = irradiance(&lights, Vec3::ZERO, Vec3::Z, 400_000, 5);
    let expected = PI * radius * radius / (h * h + radius * radius);
    assert!(
        rel_err(e.x, expected) < 0.01,
        "E = {}, expected {expected}",
        e.x
    );
}

#[test]
fn pdf_hit_agrees_with_sample_at_the_sampled_point() {
    let shapes = vec![
        emitter(
            square_facing_down(1.0),
            Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0)),
            Vec3::ONE,
        ),
        emitter(
            sphere(0.5),
            Mat4::from_translation(Vec3::new(3.0, 0.0, 1.0)),
            Vec3::splat(4.0),
        ),
        // A partial sphere and a stretched disk take the uniform-area path.
        emitter(
            Geometry::Sphere(Sphere {
                radius: 0.7,
                zmin: -0.7,
                zmax: 0.3,
                phimax: 270.0,
            }),
            Mat4::from_translation(Vec3::new(-3.0, 0.0, 1.0)),
            Vec3::splat(2.0),
        ),
        emitter(
            disk(0.5),
            Mat4::from_translation(Vec3::new(0.0, 3.0, 1.0))
                * Mat4::from_rotation_x(1.2)
                * Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0)),
            Vec3::splat(3.0),
        ),
    ];
    let (geometry, lights) = build(shapes, vec![point(Vec3::new(0.0, 0.0, 5.0), 1.0)]);
    let mut rng = fastrand::Rng::with_seed(11);
    let mut checked = [0usize; 4];
    for _ in 0..40_000 {
        let p = Vec3::new(
            rng.f32() * 4.0 - 2.0,
            rng.f32() * 4.0 - 2.0,
            rng.f32() * 0.5 - 1.0,
        );
        let Some(s) = lights.sample(p, None, rng.f32(), Vec2::new(rng.f32(), rng.f32())) else {
            continue;
        };
        if s.delta {
            continue;
        }
        let hit = geometry
            .intersect(&Ray::new(p, s.wi), s.dist * 1.001)
            .expect("a sampled light point is on the light's surface");
        assert!(
            (hit.t - s.dist).abs() < 1e-3 * s.dist,
            "t {} vs dist {}",
            hit.t,
            s.dist
        );
        // At grazing angles cos at the light, and so the pdf, is ill-conditioned in f32.
        if hit.ng.dot(-s.wi) < 0.05 {
            continue;
        }
        let pdf = lights.pdf_hit(p, &hit);
        assert!(
            rel_err(pdf, s.pdf) < 1e-3,
            "pdf_hit {pdf} vs sample {}",
            s.pdf
        );
        assert_eq!(lights.emitted(&hit, -s.wi), s.li);
        checked[hit.shape as usize] += 1;
    }
    assert!(
        checked.iter().all(|&n| n > 500),
        "samples per emitter {checked:?}"
    );
}

#[test]
fn area_lights_emit_from_the_front_only() {
    let m = Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0));
    let (geometry, lights) = build(vec![emitter(square_facing_down(1.0), m, Vec3::ONE)], vec![]);
    let above = Vec3::new(0.1, 0.1, 4.0);
    assert!((0..100).all(|i| lights
        .sample(above, None, 0.5, Vec2::new(i as f32 / 100.0, 0.3))
        .is_none()));
    let hit = geometry
        .intersect(&Ray::new(above, -Vec3::Z), f32::INFINITY)
        .unwrap();
    assert_eq!(lights.emitted(&hit, Vec3::Z), Vec3::ZERO);
    assert_eq!(lights.pdf_hit(above, &hit), 0.0);
    let below = Vec3::new(0.1, 0.1, 0.0);
    let hit = geometry
        .intersect(&Ray::new(below, Vec3::Z), f32::INFINITY)
        .unwrap();
    assert_eq!(lights.emitted(&hit, -Vec3::Z), Vec3::ONE);
    assert!(lights.pdf_hit(below, &hit) > 0.0);

    // ReverseOrientation turns a sphere light inwards: nothing reaches the outside.
    let mut inward = emitter(sphere(1.0), Mat4::IDENTITY, Vec3::ONE);
    inward.reverse_orientation = true;
    let (_, lights) = build(vec![inward], vec![]);
    assert!((0..100).all(|i| lights
        .sample(Vec3::X * 3.0, None, 0.5, Vec2::new(i as f32 / 100.0, 0.7))
        .is_none()));
    assert!(lights
        .sample(Vec3::X * 0.3, None, 0.5, Vec2::new(0.2, 0.7))
        .is_some());
}

#[test]
fn delta_lights_follow_their_definitions() {
    let spot = LightDesc::Spot(SpotLight {
        position: Vec3::ZERO,
        direction: -Vec3::Z,
        intensity: Vec3::splat(8.0),
        cone_angle: 30.0,
        cone_delta_angle: 10.0,
    });
    let (_, lights) = build(vec![], vec![spot]);
    let at_angle = |deg: f32| {
        let p = Vec3::new(
            libm::sinf(deg.to_radians()),
            0.0,
            -libm::cosf(deg.to_radians()),
        ) * 2.0;
        lights
            .sample(p, None, 0.5, Vec2::ZERO)
            .map_or(0.0, |s| s.li.x)
    };
    assert!((at_angle(0.0) - 2.0).abs() < 1e-5, "I / d^2 on the axis");
    assert!(
        (at_angle(19.0) - 2.0).abs() < 1e-5,
        "full inside coneangle - conedeltaangle"
    );
    assert_eq!(at_angle(31.0), 0.0);
    // Halfway in cosine between cos 30 and cos 20 the smoothstep is 1/2.
    let mid = libm::acosf(0.5 * (libm::cosf(30f32.to_radians()) + libm::cosf(20f32.to_radians())))
        .to_degrees();
    assert!((at_angle(mid) - 1.0).abs() < 1e-3, "{}", at_angle(mid));

    let distant = LightDesc::Distant(DistantLight {
        to_light: Vec3::new(0.0, 1.0, 1.0).normalize(),
        radiance: Vec3::new(1.0, 2.0, 3.0),
    });
    let lights_d = vec![
        point(Vec3::new(0.0, 0.0, 4.0), 1.0),
        point(Vec3::new(0.0, 0.0, -4.0), 3.0),
        distant,
    ];
    let (_, lights) = build(vec![], lights_d);
    // Powers 4 pi x 1, 4 pi x 3 and pi R^2 Y(L) with R = 1 (no geometry).
    let powers = [
        4.0 * PI,
        12.0 * PI,
        PI * luminance(Vec3::new(1.0, 2.0, 3.0)),
    ];
    let total: f32 = powers.iter().sum();
    let mut seen = [false; 3];
    for i in 0..1000 {
        let s = lights
            .sample(Vec3::ZERO, None, (i as f32 + 0.5) / 1000.0, Vec2::ZERO)
            .unwrap();
        assert!(s.delta);
        let which = if s.dist.is_infinite() {
            assert_eq!(s.li, Vec3::new(1.0, 2.0, 3.0));
            assert!((s.wi - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
            2
        } else {
            assert!((s.dist - 4.0).abs() < 1e-6);
            let k = if s.wi.z > 0.0 { 0 } else { 1 };
            assert!((s.li.x - [1.0, 3.0][k] / 16.0).abs() < 1e-6);
            k
        };
        assert!(rel_err(s.pdf, powers[which] / total) < 1e-5);
        seen[which] = true;
    }
    assert!(seen.iter().all(|&s| s));
}

/// An 8-bit PNG in memory.
fn png(width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 3]) -> Arc<[u8]> {
    let img = image::RgbImage::from_fn(width, height, |x, y| image::Rgb(texel(x, y)));
    let mut bytes = Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner().into()
}

fn env_light(filename: &str, light_to_world: Mat4) -> LightDesc {
    LightDesc::Infinite(InfiniteLight {
        radiance: Vec3::ONE,
        map: Some(EnvMapDesc {
            filename: filename.into(),
            gamma: 1.0,
        }),
        light_to_world,
    })
}

fn env_lights(source: &MemorySource, light: LightDesc, convention: LatLongConvention) -> Lights {
    build_with(vec![], vec![light], source, convention).1
}

fn spherical(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        libm::sinf(theta) * libm::cosf(phi),
        libm::sinf(theta) * libm::sinf(phi),
        libm::cosf(theta),
    )
}

#[test]
fn latlong_marker_shows_in_the_direction_each_convention_puts_it() {
    // 8 x 4 map, black but for a red texel at column 6, row 1: its centre is u = 0.8125,
    // v = 0.375, so theta = 0.375 pi.
    let mut source = MemorySource::new();
    source.insert(
        "env.png",
        png(8, 4, |x, y| {
            if (x, y) == (6, 1) {
                [255, 0, 0]
            } else {
                [0, 0, 0]
            }
        }),
    );
    let theta = 0.375 * PI;
    // Seed: u = (pi + phi) / 2 pi -> phi = 2 pi u - pi = 0.625 pi.
    // LuxRender: s = phi / 2 pi with phi in [0, 2 pi) -> phi = 1.625 pi.
    for (convention, phi) in [
        (LatLongConvention::Seed, 0.625 * PI),
        (LatLongConvention::LuxRender, 1.625 * PI),
    ] {
        let lights = env_lights(&source, env_light("env.png", Mat4::IDENTITY), convention);
        let marker = spherical(theta, phi);
        assert!(
            (lights.environment(marker) - Vec3::X).length() < 1e-4,
            "{convention:?}: {}",
            lights.environment(marker)
        );
        // Half a turn away is black.
        assert_eq!(lights.environment(spherical(theta, phi + PI)), Vec3::ZERO);
        // Importance sampling finds the marker: samples land in the 3 x 3 texels the
        // bilinear lookup spreads it over, most of them (0.75^2 x the sin(theta) share of the
        // middle row, about 0.6) in the marker's own texel.
        let mut rng = fastrand::Rng::with_seed(9);
        let mut in_marker = 0;
        for _ in 0..1000 {
            let s = lights
                .sample(Vec3::ZERO, None, 0.5, Vec2::new(rng.f32(), rng.f32()))
                .unwrap();
            let phi = libm::atan2f(s.wi.y, s.wi.x);
            let u = match convention {
                LatLongConvention::Seed => (PI + phi) / (2.0 * PI),
                LatLongConvention::LuxRender => phi.rem_euclid(2.0 * PI) / (2.0 * PI),
            };
            let (column, row) = ((u * 8.0) as u32, (libm::acosf(s.wi.z) / PI * 4.0) as u32);
            assert!(
                (5..=7).contains(&column) && row <= 2,
                "{convention:?}: {}",
                s.wi
            );
            in_marker += u32::from((column, row) == (6, 1));
        }
        assert!(
            in_marker > 550 && in_marker < 650,
            "{convention:?}: {in_marker}"
        );

        // Rotated light space (z up -> world y up): the marker turns with it.
        let rotation = Mat4::from_rotation_x(-PI / 2.0);
        let lights = env_lights(&source, env_light("env.png", rotation), convention);
        let world = rotation.transform_vector3(marker);
        assert!((lights.environment(world) - Vec3::X).length() < 1e-4);
    }

    // Pinned formulas on a 4 x 1 map with one colour per column: with Seed, -x has u = 1
    // (wrapping onto the seam between the last and first columns) and +x has u = 0.5 (the
    // seam between columns 1 and 2); LuxRender puts +x at s = 0 and +y at s = 0.25.
    let colours = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 0]];
    let c = |i: usize| Vec3::from_array(colours[i].map(|v| f32::from(v) / 255.0));
    source.insert("columns.png", png(4, 1, |x, _| colours[x as usize]));
    let seed = env_lights(
        &source,
        env_light("columns.png", Mat4::IDENTITY),
        LatLongConvention::Seed,
    );
    let lux = env_lights(
        &source,
        env_light("columns.png", Mat4::IDENTITY),
        LatLongConvention::LuxRender,
    );
    let near = |a: Vec3, b: Vec3| (a - b).length() < 1e-4;
    assert!(near(seed.environment(-Vec3::X), (c(3) + c(0)) / 2.0));
    assert!(near(seed.environment(Vec3::X), (c(1) + c(2)) / 2.0));
    assert!(
        near(seed.environment(Vec3::Y), (c(2) + c(3)) / 2.0),
        "+y: u = 0.75"
    );
    assert!(near(lux.environment(Vec3::X), (c(3) + c(0)) / 2.0));
    assert!(near(lux.environment(-Vec3::X), (c(1) + c(2)) / 2.0));
    assert!(
        near(lux.environment(Vec3::Y), (c(0) + c(1)) / 2.0),
        "+y: s = 0.25"
    );
}

#[test]
fn env_map_sampling_estimates_the_map_integral() {
    // One distribution cell per texel, and (1024 x 512) one per 2 x 2 texels.
    for (w, h) in [(64, 32), (1024, 512)] {
        env_map_sampling_estimates_the_integral_of(w, h);
    }
}

fn env_map_sampling_estimates_the_integral_of(w: u32, h: u32) {
    let texel = spotted_map(w, h);
    let mut source = MemorySource::new();
    source.insert("env.png", png(w, h, &texel));
    let integral = map_integral(&texel, w, h, |_| 1.0);
    let rotation = Mat4::from_rotation_y(0.4) * Mat4::from_rotation_z(1.0);
    for convention in [LatLongConvention::Seed, LatLongConvention::LuxRender] {
        let lights = env_lights(&source, env_light("env.png", rotation), convention);
        let mut rng = fastrand::Rng::with_seed(21);
        let n = 400_000;
        let mut sum = glam::DVec3::ZERO;
        let mut pdf_mismatches = 0;
        for _ in 0..n {
            let u = Vec2::new(rng.f32(), rng.f32());
            let s = lights
                .sample(Vec3::ZERO, None, rng.f32(), u)
                .unwrap_or_else(|| panic!("{u}"));
            let pdf = lights.pdf_environment(s.wi, None);
            // The sample carries its own texel's density; converting its direction back to
            // map coordinates can round into the neighbouring texel on a texel edge.
            if rel_err(pdf, s.pdf) >= 1e-3 {
                pdf_mismatches += 1;
            }
            let li = lights.environment(s.wi);
            assert!((li - s.li).abs().max_element() <= 1e-3 * li.max_element().max(1e-3));
            let (li_both, pdf_both) = lights.environment_and_pdf(s.wi, None);
            assert_eq!((li_both, pdf_both), (li, pdf));
            sum += (s.li / s.pdf).as_dvec3();
        }
        assert!(
            pdf_mismatches * 1000 < n,
            "{pdf_mismatches} of {n} pdfs disagree"
        );
        let estimate = sum / f64::from(n);
        for c in 0..3 {
            let err = (estimate[c] / integral[c] - 1.0).abs();
            assert!(
                err < 0.01,
                "{w}x{h} {convention:?}: estimate {estimate}, integral {integral}"
            );
        }
    }
}

#[test]
fn constant_infinite_light_is_uniform_and_shares_with_other_lights() {
    let sky = LightDesc::Infinite(InfiniteLight {
        radiance: Vec3::splat(0.5),
        map: None,
        light_to_world: Mat4::IDENTITY,
    });
    let (_, lights) = build(vec![], vec![sky.clone()]);
    assert_eq!(
        lights.environment(Vec3::new(0.3, -0.2, 0.9).normalize()),
        Vec3::splat(0.5)
    );
    assert!(rel_err(lights.pdf_environment(Vec3::Z, None), 1.0 / (4.0 * PI)) < 1e-6);
    // Irradiance on a surface under a uniform sky: pi L.
    let e = irradiance(&lights, Vec3::ZERO, Vec3::Z, 200_000, 8);
    assert!(rel_err(e.x, PI * 0.5) < 0.01, "E = {}", e.x);

    // Beside a far brighter point light the sky still gets the floor's share.
    let (_, lights) = build(vec![], vec![sky, point(Vec3::Z, 1e6)]);
    let p_sky = lights.pdf_environment(Vec3::Z, None) * 4.0 * PI;
    assert!(
        rel_err(p_sky, 0.1 / 1.1) < 1e-4,
        "sky selection probability {p_sky}"
    );
}

#[test]
fn a_missing_env_map_is_an_error_naming_the_file() {
    let desc = scene_desc(vec![], vec![env_light("maps/sky.hdr", Mat4::IDENTITY)]);
    let geometry = SceneGeometry::build(&desc.shapes);
    let err = Lights::build(
        &desc.shapes,
        &desc.lights,
        &geometry,
        &Arc::default(),
        &MemorySource::new(),
        LatLongConvention::Seed,
    )
    .err()
    .expect("missing file");
    assert!(err.to_string().contains("maps/sky.hdr"), "{err}");

    let mut source = MemorySource::new();
    source.insert("maps/sky.hdr", Arc::from(&b"not an image"[..]));
    let err = Lights::build(
        &desc.shapes,
        &desc.lights,
        &geometry,
        &Arc::default(),
        &source,
        LatLongConvention::Seed,
    )
    .err()
    .expect("undecodable file");
    assert!(matches!(err, LightError::Decode(_)) && err.to_string().contains("maps/sky.hdr"));
}

#[test]
fn no_lights_means_no_samples() {
    let (_, lights) = build(vec![shape(sphere(1.0), Mat4::IDENTITY)], vec![]);
    assert!(lights.is_empty());
    assert!(lights
        .sample(Vec3::X * 3.0, None, 0.5, Vec2::splat(0.5))
        .is_none());
    assert_eq!(lights.environment(Vec3::Z), Vec3::ZERO);
    assert_eq!(lights.pdf_environment(Vec3::Z, None), 0.0);
}

fn sun(to_sun: Vec3, relsize: f32) -> SunLight {
    SunLight {
        to_sun,
        turbidity: 2.0,
        relsize,
        gain: 1.0,
    }
}

fn sky(model: SkyModel, sundir: Vec3, turbidity: f32, light_to_world: Mat4) -> SkyLight {
    SkyLight {
        model,
        sundir: sundir.normalize(),
        turbidity,
        gain: 1.0,
        light_to_world,
    }
}

const PREETHAM: SkyModel = SkyModel::Preetham { consts: [1.0; 5] };

#[test]
fn sun_irradiance_is_its_radiance_times_its_solid_angle_whatever_its_size() {
    let to_sun = Vec3::new(0.3, -0.4, 0.8).normalize();
    let mut irradiances = Vec::new();
    for relsize in [1.0, 4.0] {
        let s = sun(to_sun, relsize);
        let radiance = s.radiance();
        assert_eq!(
            radiance,
            sun_rgb(libm::acosf(to_sun.z), 2.0) / (relsize * relsize)
        );
        let (_, lights) = build(vec![], vec![LightDesc::Sun(s)]);
        // The cone's solid angle 2 pi (1 - cos theta_max), in f64.
        let sin2 = f64::from(relsize) * 695_500.0 / 149_600_000.0;
        let sin2 = sin2 * sin2;
        let solid_angle = 2.0 * std::f64::consts::PI * (1.0 - (1.0 - sin2).sqrt());
        let expected = radiance.as_dvec3() * solid_angle;
        let e = irradiance(&lights, Vec3::ZERO, to_sun, 20_000, 31).as_dvec3();
        for c in 0..3 {
            assert!(
                (e[c] / expected[c] - 1.0).abs() < 1e-3,
                "relsize {relsize}: E = {e}, expected {expected}"
            );
        }
        // Tilted 60 degrees away from the sun, cos 60 of it.
        let tilted = Frame::from_normal(to_sun).to_world(Vec3::new(
            libm::sinf(60f32.to_radians()),
            0.0,
            libm::cosf(60f32.to_radians()),
        ));
        let e60 = irradiance(&lights, Vec3::ZERO, tilted, 20_000, 32).as_dvec3();
        assert!((e60.y / (0.5 * expected.y) - 1.0).abs() < 2e-3, "{e60}");
        // An escaping ray into the disc sees the radiance, with the sampler's density.
        assert_eq!(lights.environment(to_sun), radiance);
        let pdf = lights.pdf_environment(to_sun, None);
        assert!((f64::from(pdf) * solid_angle - 1.0).abs() < 1e-3, "{pdf}");
        let off = Frame::from_normal(to_sun).to_world(Vec3::new(0.03, 0.0, 1.0).normalize());
        assert_eq!(lights.environment(off), Vec3::ZERO);
        irradiances.push(e);
    }
    // relsize spreads the same power over a larger disc.
    assert!((irradiances[1].y / irradiances[0].y - 1.0).abs() < 2e-3);
}

#[test]
fn sun_colour_and_brightness_follow_the_atmosphere() {
    // Overhead at turbidity 2: about 1.3e9 cd/m^2 (the measured noon sun is 1.6e9 at sea
    // level for a very clear sky), white with a warm tint.
    let overhead = sun_rgb(0.0, 2.0);
    let y = luminance(overhead);
    assert!((1.0e9..1.7e9).contains(&y), "Y = {y}");
    assert!(
        overhead.x > overhead.z && overhead.z / overhead.x > 0.7,
        "{overhead}"
    );
    // Near the horizon: dimmer and redder; more haze: dimmer.
    let low = sun_rgb(80f32.to_radians(), 2.0);
    assert!(luminance(low) < 0.6 * y, "{low}");
    assert!(low.z / low.x < 0.8 * overhead.z / overhead.x, "{low}");
    assert!(luminance(sun_rgb(0.0, 6.0)) < 0.8 * y);
    // Below the horizon: nothing.
    assert_eq!(sun_rgb(95f32.to_radians(), 2.0), Vec3::ZERO);
}

/// Zenith luminance of Preetham's model, cd/m^2.
fn preetham_zenith_luminance(theta_s: f32, t: f32) -> f32 {
    let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
    ((4.0453 * t - 4.9710) * libm::tanf(chi) - 0.2155 * t + 2.4192) * 1000.0
}

#[test]
fn sky_radiance_matches_the_models_at_zenith_and_horizon() {
    let sundir = Vec3::new(0.0, 0.6, 0.8);
    let theta_s = libm::acosf(sundir.normalize().z);
    // Preetham: the zenith luminance is the model's own formula.
    let desc = sky(PREETHAM, sundir, 3.0, Mat4::IDENTITY);
    let (_, lights) = build(vec![], vec![LightDesc::Sky(desc.clone())]);
    let zenith = luminance(lights.environment(Vec3::Z));
    let want = preetham_zenith_luminance(theta_s, 3.0);
    assert!(
        rel_err(zenith, want) < 5e-3,
        "zenith {zenith}, model {want}"
    );
    // The tabulated sky agrees with the model it was tabulated from, below the horizon too
    // (where it repeats the horizon).
    for (desc, tolerance) in [
        (desc, 0.01),
        (sky(SkyModel::Hosek, sundir, 3.0, Mat4::IDENTITY), 0.01),
    ] {
        let model = desc.model().unwrap();
        let (_, lights) = build(vec![], vec![LightDesc::Sky(desc.clone())]);
        for dir in [
            Vec3::Z,
            Vec3::new(1.0, 0.0, 0.02).normalize(),
            Vec3::new(-0.3, 0.5, 0.4).normalize(),
        ] {
            let (got, want) = (lights.environment(dir), model(dir));
            assert!(
                (got - want).abs().max_element() < tolerance * want.max_element(),
                "{:?} at {dir}: {got} vs {want}",
                desc.model
            );
        }
        // Below the horizon the sky is lit (the horizon's zenith angle, the true angle to
        // the sun), not black.
        let below = model(Vec3::new(1.0, 0.0, -0.5).normalize());
        assert!(below.min_element() > 0.0 && below.is_finite(), "{below}");
        // A clear sky is blue overhead and brighter towards the sun.
        let z = model(Vec3::Z);
        assert!(z.z > z.x, "{:?}: zenith {z}", desc.model);
        let near_sun = model((sundir.normalize() + Vec3::new(0.0, 0.0, 0.1)).normalize());
        assert!(luminance(near_sun) > 2.0 * luminance(z), "{:?}", desc.model);
    }
    // Both models give a clear-day zenith of a few thousand cd/m^2 for the sun at 37 degrees.
    let hosek = sky(SkyModel::Hosek, sundir, 3.0, Mat4::IDENTITY)
        .model()
        .unwrap();
    let y = luminance(hosek(Vec3::Z));
    assert!((1000.0..10_000.0).contains(&y), "Hosek zenith {y}");
}

#[test]
fn sky_sampling_density_integrates_to_one_and_matches_evaluation() {
    let rotation = Mat4::from_rotation_x(-PI / 2.0) * Mat4::from_rotation_z(0.7);
    for desc in [
        sky(SkyModel::Hosek, Vec3::new(0.2, 0.5, 0.3), 2.2, rotation),
        sky(PREETHAM, Vec3::new(-0.4, 0.1, 0.9), 4.0, Mat4::IDENTITY),
    ] {
        let model = desc.model().unwrap();
        let (_, lights) = build(vec![], vec![LightDesc::Sky(desc.clone())]);
        let mut rng = fastrand::Rng::with_seed(77);
        // The density over the sphere, by uniform directions: its mean x 4 pi is 1.
        let n = 200_000;
        let mut pdf_sum = 0.0f64;
        for _ in 0..n {
            let z = 1.0 - 2.0 * rng.f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.0 * PI * rng.f32();
            let dir = Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z);
            pdf_sum += f64::from(lights.pdf_environment(dir, None));
        }
        let total = pdf_sum / f64::from(n) * 4.0 * std::f64::consts::PI;
        assert!((total - 1.0).abs() < 0.01, "{:?}: {total}", desc.model);
        // Importance-sampled estimate of the integral of luminance over the sphere against
        // a quadrature of the model itself; and each sample's density is what
        // pdf_environment says.
        let mut estimate = 0.0f64;
        let mut mismatches = 0;
        for _ in 0..n {
            let s = lights
                .sample(Vec3::ZERO, None, rng.f32(), Vec2::new(rng.f32(), rng.f32()))
                .unwrap();
            if rel_err(lights.pdf_environment(s.wi, None), s.pdf) >= 1e-3 {
                mismatches += 1;
            }
            estimate += f64::from(luminance(s.li) / s.pdf);
        }
        assert!(mismatches * 1000 < n, "{mismatches} pdfs disagree");
        let estimate = estimate / f64::from(n);
        let (nt, np) = (400, 800);
        let mut quadrature = 0.0f64;
        for i in 0..nt {
            let theta = (i as f64 + 0.5) / nt as f64 * std::f64::consts::PI;
            for j in 0..np {
                let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                let d = Vec3::new(
                    (libm::sin(theta) * libm::cos(phi)) as f32,
                    (libm::sin(theta) * libm::sin(phi)) as f32,
                    libm::cos(theta) as f32,
                );
                quadrature += f64::from(luminance(model(d)))
                    * libm::sin(theta)
                    * (std::f64::consts::PI / nt as f64)
                    * (std::f64::consts::TAU / np as f64);
            }
        }
        assert!(
            (estimate / quadrature - 1.0).abs() < 0.01,
            "{:?}: estimate {estimate}, quadrature {quadrature}",
            desc.model
        );
    }
}

/// A smooth map with a bright spot: 8-bit, `w` x `h`.
fn spotted_map(w: u32, h: u32) -> impl Fn(u32, u32) -> [u8; 3] {
    move |x, y| {
        let (fx, fy) = (x as f32 / w as f32, y as f32 / h as f32);
        let base = 40.0 + 30.0 * libm::sinf(fx * 2.0 * PI) * libm::cosf(fy * PI);
        let (sx, sy) = (x * 64 / w, y * 32 / h);
        let spot = if (20..23).contains(&sx) && (8..10).contains(&sy) {
            200.0
        } else {
            0.0
        };
        [
            (base + spot) as u8,
            (base * 0.5) as u8,
            (spot * 0.9) as u8 + 10,
        ]
    }
}

/// What a diffuse surface facing `n` receives from the lights, ∫ L max(cos, 0), estimated by
/// one light sample (for the side `facing`, or none) and one cosine-weighted sample per round,
/// weighed by the power heuristic as the path tracer weighs them. Returns the estimate, the
/// variance of one round's luminance, and how many samples' densities `pdf_environment`
/// does not reproduce.
fn receives(lights: &Lights, n: Vec3, facing: Option<Vec3>, rounds: u32) -> (DVec3, f64, u32) {
    let frame = Frame::from_normal(n);
    let mut rng = fastrand::Rng::with_seed(3);
    let (mut sum, mut sum_sq, mut mismatches) = (DVec3::ZERO, 0.0f64, 0);
    let heuristic = |a: f32, b: f32| a * a / (a * a + b * b);
    for _ in 0..rounds {
        let mut round = Vec3::ZERO;
        let u = Vec2::new(rng.f32(), rng.f32());
        if let Some(s) = lights.sample(Vec3::ZERO, facing, rng.f32(), u) {
            if rel_err(lights.pdf_environment(s.wi, facing), s.pdf) >= 1e-3 {
                mismatches += 1;
            }
            let cos = s.wi.dot(n);
            if cos > 0.0 {
                round += s.li * cos * heuristic(s.pdf, cos / PI) / s.pdf;
            }
        }
        let (r1, r2) = (rng.f32(), rng.f32());
        let (sin_phi, cos_phi) = libm::sincosf(TAU * r2);
        let r = r1.sqrt();
        let wi = frame.to_world(Vec3::new(r * cos_phi, r * sin_phi, (1.0 - r1).sqrt()));
        let cos = wi.dot(n);
        if cos > 0.0 {
            let (li, pdf_light) = lights.environment_and_pdf(wi, facing);
            round += li * cos * heuristic(cos / PI, pdf_light) / (cos / PI);
        }
        sum += round.as_dvec3();
        sum_sq += f64::from(luminance(round)).powi(2);
    }
    let mean = sum / f64::from(rounds);
    let variance = sum_sq / f64::from(rounds) - f64::from(luminance(mean.as_vec3())).powi(2);
    (mean, variance, mismatches)
}

/// Σ radiance x `weight` x solid angle over the texels of a `w` x `h` map, `weight` taking the
/// light-space direction of a texel's centre in the seed convention (u = (pi + phi) / 2pi).
fn map_integral(
    texel: impl Fn(u32, u32) -> [u8; 3],
    w: u32,
    h: u32,
    weight: impl Fn(Vec3) -> f64,
) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for y in 0..h {
        let (t0, t1) = (
            y as f64 / h as f64 * std::f64::consts::PI,
            (y + 1) as f64 / h as f64 * std::f64::consts::PI,
        );
        let solid_angle = std::f64::consts::TAU / w as f64 * (libm::cos(t0) - libm::cos(t1));
        let theta = (y as f32 + 0.5) / h as f32 * PI;
        for x in 0..w {
            let phi = (x as f32 + 0.5) / w as f32 * TAU - PI;
            let l = DVec3::from_array(texel(x, y).map(|v| f64::from(v) / 255.0));
            sum += l * weight(spherical(theta, phi)) * solid_angle;
        }
    }
    sum
}

#[test]
fn facing_samples_weighed_against_cosine_samples_estimate_what_a_surface_receives() {
    // One distribution cell per texel in one block per cell; and Captain Falcon's size: cells
    // of 4 x 4 texels in blocks of 8 x 8 cells.
    let cases = [
        (
            64,
            32,
            Mat4::from_rotation_y(0.4) * Mat4::from_rotation_z(1.0),
        ),
        (1600, 800, Mat4::IDENTITY),
    ];
    for (w, h, rotation) in cases {
        let texel = spotted_map(w, h);
        let mut source = MemorySource::new();
        source.insert("env.png", png(w, h, &texel));
        let lights = env_lights(
            &source,
            env_light("env.png", rotation),
            LatLongConvention::Seed,
        );
        let mut rng = fastrand::Rng::with_seed(8);
        let mut ratios = Vec::new();
        for i in 0..6 {
            let n = match i {
                0 => Vec3::Z,
                _ => Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5).normalize(),
            };
            // ∫ L max(cos, 0), the map's directions turned into the world.
            let want = map_integral(&texel, w, h, |d| {
                f64::from(rotation.transform_vector3(d).dot(n).max(0.0))
            });
            let rounds = 400_000;
            let (got, variance, mismatches) = receives(&lights, n, Some(n), rounds);
            let (plain, plain_variance, _) = receives(&lights, n, None, rounds);
            assert!(
                mismatches * 1000 < rounds,
                "{mismatches} of {rounds} densities disagree"
            );
            for c in 0..3 {
                for (what, estimate) in [("facing", got), ("plain", plain)] {
                    let err = (estimate[c] / want[c] - 1.0).abs();
                    assert!(
                        err < 5e-3,
                        "{w}x{h}, {n}: {what} {estimate}, integral {want}"
                    );
                }
            }
            // What the tables are for: the map's light samples weigh less noise in.
            let ratio = variance / plain_variance;
            assert!(
                ratio < 0.85,
                "{w}x{h}, {n}: variance {variance} against {plain_variance}"
            );
            ratios.push(ratio);
        }
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        assert!(mean < 0.6, "{w}x{h}: variance ratios {ratios:?}");
    }
}

/// A flat fan of `n` triangles around the origin in the z = 0 plane, facing -z, of uneven
/// sizes (so that the triangles' choice by area is not uniform).
fn fan_facing_down(n: u32) -> Geometry {
    let mut vertices = vec![Vec3::ZERO];
    for k in 0..=n {
        let angle = TAU * k as f32 / (n + 1) as f32;
        let r = 0.3 + 0.1 * k as f32;
        vertices.push(Vec3::new(r * libm::cosf(angle), r * libm::sinf(angle), 0.0));
    }
    let triangles = (1..=n).map(|k| [0, k + 1, k]).collect();
    Geometry::Mesh(Arc::new(mesh(vertices, triangles)))
}

/// Packets sample a few plain triangle lamps in lanes: every lane type gives, lane by lane,
/// the bits of `Lights::sample` (direction, radiance, density, distance; a density of 0 where
/// it finds no sample), from points around and behind the lamps, with choice numbers across
/// [0, 1) and at its ends.
#[test]
fn triangle_lamps_in_lanes_give_the_bits_of_one_sample_at_a_time() {
    use crate::lanes::tests::on_every_lane_type;
    use crate::lanes::OnLanes;
    use crate::lanes::{Lanes, MAX_LANES};

    let lamps = vec![
        emitter(
            square_facing_down(1.0),
            Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0)),
            Vec3::new(3.0, 2.0, 1.0),
        ),
        emitter(
            fan_facing_down(7),
            Mat4::from_translation(Vec3::new(1.5, 0.5, 1.5)) * Mat4::from_rotation_x(0.4),
            Vec3::new(0.5, 4.0, 2.0),
        ),
        emitter(
            fan_facing_down(1),
            Mat4::from_translation(Vec3::new(-1.0, 0.0, 1.0)),
            Vec3::splat(9.0),
        ),
    ];
    let (_, lights) = build(lamps, vec![]);
    struct Agrees<'a>(&'a Lights);
    impl OnLanes for Agrees<'_> {
        type Output = ();
        fn run<L: Lanes>(&self) {
            let lights = self.0;
            let lamps = lights.triangle_lamps().expect("three plain triangle lamps");
            let mut rng = fastrand::Rng::with_seed(5);
            let (mut found, mut none) = (0, 0);
            for round in 0..4000 {
                let mut from = [[0.0; MAX_LANES]; 3];
                let mut u = [[0.0; MAX_LANES]; 3];
                for i in 0..L::N {
                    for c in 0..3 {
                        from[c][i] = rng.f32() * 6.0 - 3.0;
                        u[c][i] = match (round + i) % 16 {
                            0 => 0.0,
                            1 => 1.0 - f32::EPSILON / 2.0,
                            _ => rng.f32(),
                        };
                    }
                }
                let s = lamps.sample(
                    from.map(|c| L::load(&c)),
                    L::load(&u[0]),
                    [L::load(&u[1]), L::load(&u[2])],
                );
                let (pdf, dist) = (s.pdf.values(), s.dist.values());
                let (wi, li) = (s.wi.map(L::values), s.li.map(L::values));
                for i in 0..L::N {
                    let p = Vec3::new(from[0][i], from[1][i], from[2][i]);
                    let one = lights.sample(p, None, u[0][i], Vec2::new(u[1][i], u[2][i]));
                    let Some(one) = one else {
                        assert_eq!(pdf[i], 0.0, "lane {i} from {p}: no sample alone");
                        none += 1;
                        continue;
                    };
                    found += 1;
                    let lane = |v: [[f32; MAX_LANES]; 3]| Vec3::new(v[0][i], v[1][i], v[2][i]);
                    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                    assert_eq!(bits(lane(wi)), bits(one.wi), "lane {i} from {p}");
                    assert_eq!(bits(lane(li)), bits(one.li), "lane {i} from {p}");
                    assert_eq!(pdf[i].to_bits(), one.pdf.to_bits(), "lane {i} from {p}");
                    assert_eq!(dist[i].to_bits(), one.dist.to_bits(), "lane {i} from {p}");
                    assert!(!one.delta);
                }
            }
            assert!(found > 1000 && none > 500, "{found} samples, {none} none");
        }
    }
    on_every_lane_type(&Agrees(&lights));
}

/// Only a few plain triangle lamps are tabulated for lanes: not a point light beside them, a
/// sphere lamp, a lamp of more triangles than a scan covers, or no light at all.
#[test]
fn triangle_lamps_are_only_a_few_plain_triangle_lamps() {
    let square = || emitter(square_facing_down(1.0), Mat4::IDENTITY, Vec3::ONE);
    let tabulated = |shapes: Vec<ShapeDesc>, lights: Vec<LightDesc>| {
        build(shapes, lights).1.triangle_lamps().is_some()
    };
    assert!(tabulated(vec![square(), square()], vec![]));
    assert!(!tabulated(vec![square()], vec![point(Vec3::Z, 1.0)]));
    assert!(!tabulated(
        vec![square(), emitter(sphere(0.5), Mat4::IDENTITY, Vec3::ONE)],
        vec![]
    ));
    assert!(tabulated(
        vec![emitter(fan_facing_down(8), Mat4::IDENTITY, Vec3::ONE)],
        vec![]
    ));
    assert!(!tabulated(
        vec![emitter(fan_facing_down(9), Mat4::IDENTITY, Vec3::ONE)],
        vec![]
    ));
    assert!(!tabulated(vec![], vec![]));
}

mod emission;
