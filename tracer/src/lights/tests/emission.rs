//! Emission sampling ([`Lights::sample_emission`], [`Lights::emission_pdf`]) and the light
//! points of [`Lights::sample_light_point`], for each kind of light.
//!
//! A ray's weight `le |cos| / (pdf_pos pdf_dir)` estimates the light's flux. For light from a
//! direction, whose rays start on a disc of radius r (the scene sphere's) perpendicular to
//! them, that is the flux through the disc from each direction: pi r^2 x the integral of the
//! radiance over the sphere (pi r^2 E for a distant light of irradiance E; 4 pi^2 r^2 L for a
//! constant environment of radiance L).

use std::f64::consts::PI as PI64;

use super::*;

/// Mean and standard error (of luminance) of the emission weights of `n` samples, and the
/// largest relative difference of `emission_pdf` from a sample's own densities.
struct Estimate {
    mean: DVec3,
    stderr: f64,
    pdf_err: f32,
    samples: u32,
}

fn estimate_emission(lights: &Lights, n: u32, seed: u64) -> Estimate {
    let mut rng = fastrand::Rng::with_seed(seed);
    let (mut sum, mut sum2, mut pdf_err, mut samples) = (DVec3::ZERO, 0.0f64, 0.0f32, 0);
    for _ in 0..n {
        let (u_pos, u_dir) = (
            Vec2::new(rng.f32(), rng.f32()),
            Vec2::new(rng.f32(), rng.f32()),
        );
        let Some(s) = lights.sample_emission(rng.f32(), u_pos, u_dir) else {
            continue;
        };
        samples += 1;
        assert!((s.ray.dir.length() - 1.0).abs() < 1e-4, "{s:?}");
        let cos = s.ray.normal.map_or(1.0, |n| n.dot(s.ray.dir).abs());
        let w = (s.ray.le * cos / (s.ray.pdf_pos * s.ray.pdf_dir)).as_dvec3();
        assert!(w.is_finite(), "{s:?}");
        sum += w;
        sum2 += luminance(w.as_vec3()) as f64 * luminance(w.as_vec3()) as f64;
        let (pos, dir) = lights.emission_pdf(s.emitter, s.ray.origin, s.ray.normal, s.ray.dir);
        pdf_err = pdf_err
            .max(rel_err(pos, s.ray.pdf_pos))
            .max(rel_err(dir, s.ray.pdf_dir));
    }
    let mean = sum / f64::from(n);
    let mean_y = f64::from(luminance(mean.as_vec3()));
    let var = (sum2 / f64::from(n) - mean_y * mean_y).max(0.0);
    Estimate {
        mean,
        stderr: (var / f64::from(n)).sqrt(),
        pdf_err,
        samples,
    }
}

/// A non-emitting sphere of radius 2 at (1, 0, 0): the scene sphere is its box's, centre
/// (1, 0, 0) and radius 2 sqrt 3.
fn bystander() -> ShapeDesc {
    shape(sphere(2.0), Mat4::from_translation(Vec3::X))
}

fn spot_desc(position: Vec3, direction: Vec3) -> LightDesc {
    LightDesc::Spot(SpotLight {
        position,
        direction,
        intensity: Vec3::new(3.0, 2.0, 1.0),
        cone_angle: 30.0,
        cone_delta_angle: 10.0,
    })
}

/// 2 pi x the integral of the spot's smoothstep falloff over cos theta (midpoint rule in f64).
fn spot_cone_integral(cone: f64, delta: f64) -> f64 {
    let cos_total = libm::cos(cone.to_radians());
    let cos_start = libm::cos((cone - delta).to_radians());
    let steps = 100_000;
    let dc = (1.0 - cos_total) / f64::from(steps);
    let sum: f64 = (0..steps)
        .map(|i| {
            let c = cos_total + (f64::from(i) + 0.5) * dc;
            let t = ((c - cos_total) / (cos_start - cos_total)).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        })
        .sum();
    2.0 * PI64 * sum * dc
}

fn constant_sky(l: f32) -> LightDesc {
    LightDesc::Infinite(InfiniteLight {
        radiance: Vec3::splat(l),
        map: None,
        light_to_world: Mat4::IDENTITY,
    })
}

/// The integral over the sphere of `f` (midpoint rule in theta and phi about z).
fn sphere_quadrature(f: impl Fn(Vec3) -> DVec3, nt: u32, np: u32) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for i in 0..nt {
        let theta = (f64::from(i) + 0.5) / f64::from(nt) * PI64;
        let cell = libm::sin(theta) * (PI64 / f64::from(nt)) * (2.0 * PI64 / f64::from(np));
        for j in 0..np {
            let phi = (f64::from(j) + 0.5) / f64::from(np) * 2.0 * PI64;
            let d = Vec3::new(
                (libm::sin(theta) * libm::cos(phi)) as f32,
                (libm::sin(theta) * libm::sin(phi)) as f32,
                libm::cos(theta) as f32,
            );
            sum += f(d) * cell;
        }
    }
    sum
}

fn sun_to(to_sun: Vec3) -> (SunLight, DVec3) {
    let s = sun(to_sun, 1.0);
    let sin2 = f64::from(s.sin2_max());
    let solid_angle = 2.0 * PI64 * sin2 / (1.0 + (1.0 - sin2).sqrt());
    let flux_density = s.radiance().as_dvec3() * solid_angle;
    (s, flux_density)
}

const MAP: &str = "env.png";

fn map_source() -> (MemorySource, DVec3) {
    let (w, h) = (64, 32);
    let texel = spotted_map(w, h);
    let mut source = MemorySource::new();
    source.insert(MAP, png(w, h, &texel));
    (source, map_integral(&texel, w, h, |_| 1.0))
}

/// Each kind alone in a scene (with the bystander, for a scene sphere that is not the unit
/// one; the lamps lie inside its box) and its expected flux.
fn each_kind() -> Vec<(&'static str, Lights, DVec3)> {
    let radiance = Vec3::new(2.0, 1.0, 0.5);
    let l = radiance.as_dvec3();
    let lamp = |g: Geometry, m: Mat4| build(vec![bystander(), emitter(g, m, radiance)], vec![]).1;
    let lone = |light: LightDesc| build(vec![bystander()], vec![light]).1;
    let r = 2.0 * 3f64.sqrt();
    let disc = PI64 * r * r;
    let (source, map_flux) = map_source();
    let map = build_with(
        vec![bystander()],
        vec![env_light(MAP, Mat4::from_rotation_y(0.4))],
        &source,
        LatLongConvention::Seed,
    )
    .1;
    let sky_desc = sky(PREETHAM, Vec3::new(-0.4, 0.1, 0.9), 4.0, Mat4::IDENTITY);
    let sky = lone(LightDesc::Sky(sky_desc));
    let sky_flux = sphere_quadrature(|d| sky.environment(d).as_dvec3(), 200, 400);
    let (sun, sun_flux) = sun_to(Vec3::new(0.3, -0.4, 0.8).normalize());
    let tilted = Mat4::from_translation(Vec3::new(1.0, 0.5, 0.5)) * Mat4::from_rotation_x(0.7);
    vec![
        (
            "triangle quad",
            lamp(square_facing_down(1.5), tilted),
            PI64 * l * 1.5 * 1.5,
        ),
        (
            "sphere",
            lamp(sphere(0.5), tilted),
            PI64 * l * 4.0 * PI64 * 0.25,
        ),
        ("disk", lamp(disk(0.8), tilted), PI64 * l * PI64 * 0.64),
        (
            "point",
            lone(point(Vec3::new(0.0, 1.0, 0.0), 3.0)),
            DVec3::splat(4.0 * PI64 * 3.0),
        ),
        (
            "spot",
            lone(spot_desc(Vec3::X, Vec3::new(1.0, -1.0, 0.5).normalize())),
            DVec3::new(3.0, 2.0, 1.0) * spot_cone_integral(30.0, 10.0),
        ),
        (
            "distant",
            lone(LightDesc::Distant(DistantLight {
                to_light: Vec3::new(0.2, 0.3, 1.0).normalize(),
                radiance,
            })),
            l * disc,
        ),
        (
            "constant infinite",
            lone(constant_sky(0.5)),
            DVec3::splat(0.5 * 4.0 * PI64 * disc),
        ),
        ("sun", lone(LightDesc::Sun(sun)), sun_flux * disc),
        ("sky", sky, sky_flux * disc),
        ("latlong map", map, map_flux * disc),
    ]
}

#[test]
fn emission_weights_estimate_each_lights_flux() {
    for (name, lights, expected) in each_kind() {
        assert_eq!(lights.scene_sphere().0, Vec3::X, "{name}");
        assert!(rel_err(lights.scene_sphere().1, 2.0 * 3f32.sqrt()) < 1e-6);
        let e = estimate_emission(&lights, 200_000, 31);
        let expected_y = f64::from(luminance(expected.as_vec3()));
        let got_y = f64::from(luminance(e.mean.as_vec3()));
        println!(
            "{name}: flux {got_y:.6} expected {expected_y:.6} (rel err {:.2e}, rel stderr {:.2e}), \
             {} of 200000 sampled",
            got_y / expected_y - 1.0,
            e.stderr / expected_y,
            e.samples
        );
        assert!(
            (got_y - expected_y).abs() < (4.0 * e.stderr).max(1e-4 * expected_y)
                && (got_y / expected_y - 1.0).abs() < 0.01,
            "{name}: flux {} expected {expected} (stderr {})",
            e.mean,
            e.stderr
        );
        for c in 0..3 {
            assert!(
                (e.mean[c] / expected[c] - 1.0).abs() < 0.01,
                "{name}: flux {} expected {expected}",
                e.mean
            );
        }
    }
}

#[test]
fn a_mixture_of_lights_estimates_the_sum_of_their_fluxes() {
    // A point light beside a sun and a sky: the mixture at infinity is chosen with less than
    // probability 1, and its direction comes from either member.
    let sky_desc = sky(
        SkyModel::Hosek,
        Vec3::new(0.2, 0.5, 0.3),
        2.2,
        Mat4::IDENTITY,
    );
    let (sun, sun_flux) = sun_to(sky_desc.sundir);
    let sky_alone = build(vec![bystander()], vec![LightDesc::Sky(sky_desc.clone())]).1;
    let sky_flux = sphere_quadrature(|d| sky_alone.environment(d).as_dvec3(), 200, 400);
    let r = 2.0 * 3f64.sqrt();
    let env_flux = (sky_flux + sun_flux) * (PI64 * r * r);
    // The point light's flux as large as the mixture's: an error in either shows.
    let intensity = luminance(env_flux.as_vec3()) / (4.0 * PI);
    let (_, lights) = build(
        vec![bystander()],
        vec![
            LightDesc::Sky(sky_desc),
            LightDesc::Sun(sun),
            point(Vec3::ZERO, intensity),
        ],
    );
    let env_share = lights
        .emission_pdf(Emitter::Environment, Vec3::ZERO, None, -Vec3::Z)
        .0
        / lights.sphere.pdf_area();
    assert!(env_share > 0.05 && env_share < 0.95, "{env_share}");
    let expected = env_flux + DVec3::splat(4.0 * PI64 * f64::from(intensity));
    let e = estimate_emission(&lights, 400_000, 5);
    println!(
        "sun + sky + point: flux {} expected {expected}, environment chosen with {env_share}, \
         pdf rel err {:.2e}",
        e.mean, e.pdf_err
    );
    for c in 0..3 {
        assert!(
            (e.mean[c] / expected[c] - 1.0).abs() < 0.01,
            "flux {} expected {expected}",
            e.mean
        );
    }
    assert!(e.pdf_err < 1e-4, "{}", e.pdf_err);
}

#[test]
fn emission_pdf_gives_the_densities_a_sample_had() {
    for (name, lights, _) in each_kind() {
        let e = estimate_emission(&lights, 20_000, 9);
        println!("{name}: largest relative pdf difference {:.2e}", e.pdf_err);
        assert!(e.samples > 10_000, "{name}: {} samples", e.samples);
        assert!(e.pdf_err < 1e-4, "{name}: {}", e.pdf_err);
    }
}

#[test]
fn emission_pdf_is_zero_where_no_sample_goes() {
    let (_, lights) = build(
        vec![emitter(square_facing_down(1.0), Mat4::IDENTITY, Vec3::ONE)],
        vec![spot_desc(Vec3::ZERO, Vec3::Z)],
    );
    assert_eq!(lights.emitter_of_shape(0), Some(Emitter::Light(0)));
    assert_eq!(lights.emitter_of_shape(1), None);
    let lamp = Emitter::Light(0);
    let (pos, dir) = lights.emission_pdf(lamp, Vec3::ZERO, Some(-Vec3::Z), Vec3::Z);
    assert!(pos > 0.0 && dir == 0.0, "behind the lamp: {pos} {dir}");
    let (_, dir) = lights.emission_pdf(lamp, Vec3::ZERO, Some(-Vec3::Z), -Vec3::Z);
    assert!(rel_err(dir, 1.0 / PI) < 1e-6, "along the normal: {dir}");
    let spot = Emitter::Light(1);
    let off_axis = Vec3::new(libm::sinf(0.6), 0.0, libm::cosf(0.6));
    assert_eq!(lights.emission_pdf(spot, Vec3::ZERO, None, off_axis).1, 0.0);
    // Nothing at infinity: the environment has no density.
    assert_eq!(
        lights.emission_pdf(Emitter::Environment, Vec3::ZERO, None, Vec3::Z),
        (0.0, 0.0)
    );
}

#[test]
fn emission_direction_densities_integrate_to_one() {
    let (source, _) = map_source();
    let beside = point(Vec3::new(0.0, 0.0, 5.0), 50.0);
    let tilted = Mat4::from_rotation_x(0.7);
    let lamp_normal = tilted.transform_vector3(-Vec3::Z);
    let (_, lamp) = build(
        vec![emitter(square_facing_down(1.0), tilted, Vec3::ONE)],
        vec![beside.clone()],
    );
    let (_, spot) = build(vec![], vec![spot_desc(Vec3::ZERO, Vec3::Z)]);
    let map = build_with(
        vec![],
        vec![env_light(MAP, Mat4::from_rotation_y(0.4)), beside.clone()],
        &source,
        LatLongConvention::LuxRender,
    )
    .1;
    let sky_desc = sky(PREETHAM, Vec3::new(-0.4, 0.1, 0.9), 4.0, Mat4::IDENTITY);
    let (_, sky) = build(vec![], vec![LightDesc::Sky(sky_desc), beside]);
    let cases: [(&str, &Lights, Emitter, Option<Vec3>); 4] = [
        (
            "area light point",
            &lamp,
            Emitter::Light(0),
            Some(lamp_normal),
        ),
        ("spot", &spot, Emitter::Light(0), None),
        ("latlong map", &map, Emitter::Environment, None),
        ("sky", &sky, Emitter::Environment, None),
    ];
    for (name, lights, emitter, normal) in cases {
        // The spot's axis is z, so its cone's edge (30 degrees) falls on a row boundary.
        let total = sphere_quadrature(
            |d| {
                DVec3::splat(f64::from(
                    lights.emission_pdf(emitter, Vec3::ZERO, normal, d).1,
                ))
            },
            1800,
            1200,
        )
        .x;
        println!("{name}: integral of pdf_dir {total:.6}");
        assert!((total - 1.0).abs() < 2e-3, "{name}: {total}");
    }
}

#[test]
fn light_points_are_on_the_lights_their_samples_reached() {
    let sphere_centre = Vec3::new(-2.0, 0.0, 1.0);
    let disk_m = Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)) * Mat4::from_rotation_x(PI);
    let shapes = vec![
        emitter(
            square_facing_down(1.0),
            Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0)),
            Vec3::ONE,
        ),
        emitter(
            sphere(0.5),
            Mat4::from_translation(sphere_centre),
            Vec3::ONE,
        ),
        emitter(disk(0.7), disk_m, Vec3::ONE),
    ];
    let spot_at = Vec3::new(0.5, 0.0, 2.0);
    let lights_desc = vec![
        point(Vec3::new(1.0, 1.0, 2.0), 0.2),
        spot_desc(spot_at, -Vec3::Z),
        LightDesc::Distant(DistantLight {
            to_light: Vec3::new(0.2, 0.3, 1.0).normalize(),
            radiance: Vec3::ONE,
        }),
        // Dim enough to leave the other lights their share of the samples.
        LightDesc::Sun(SunLight {
            gain: 1e-6,
            ..sun(Vec3::new(0.3, -0.4, 0.8).normalize(), 1.0)
        }),
        LightDesc::Sky(SkyLight {
            gain: 1e-4,
            ..sky(PREETHAM, Vec3::new(0.3, -0.4, 0.8), 3.0, Mat4::IDENTITY)
        }),
    ];
    let (_, lights) = build(shapes, lights_desc);
    let (_, r) = lights.scene_sphere();
    let mut rng = fastrand::Rng::with_seed(13);
    let mut seen = [0u32; 7];
    for _ in 0..50_000 {
        let p = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * 2.0;
        let (us, u) = (rng.f32(), Vec2::new(rng.f32(), rng.f32()));
        let plain = lights.sample(p, None, us, u);
        let with_point = lights.sample_light_point(p, us, u);
        let (Some(s), Some((t, at))) = (plain, with_point) else {
            assert!(plain.is_none() && with_point.is_none());
            continue;
        };
        let bits = |s: LightSample| {
            (
                s.wi.to_array().map(f32::to_bits),
                s.li.to_array().map(f32::to_bits),
                s.pdf.to_bits(),
                s.dist.to_bits(),
                s.delta,
            )
        };
        assert_eq!(bits(s), bits(t));
        let index = match at.emitter {
            Emitter::Light(i) => i as usize,
            Emitter::Environment => 6,
        };
        seen[index] += 1;
        assert_eq!(at.at_infinity, index >= 5);
        assert_eq!(at.delta_position, index == 3 || index == 4);
        assert_eq!(at.delta_direction, index == 5);
        assert_eq!(at.normal.is_some(), index < 3);
        if index < 5 {
            assert!(rel_err(at.p.distance(p), s.dist) < 1e-4, "{at:?} {s:?}");
        } else {
            assert_eq!(at.p, p + s.wi * 2.0 * r);
        }
        match index {
            0 => {
                assert!((at.p.z - 3.0).abs() < 1e-5 && at.p.x.abs().max(at.p.y.abs()) <= 0.5);
                assert!(at.normal.unwrap().abs_diff_eq(-Vec3::Z, 1e-6));
            }
            1 => {
                assert!((at.p.distance(sphere_centre) - 0.5).abs() < 1e-4, "{at:?}");
                let outward = (at.p - sphere_centre) / 0.5;
                assert!(at.normal.unwrap().abs_diff_eq(outward, 1e-3), "{at:?}");
            }
            2 => {
                assert!((at.p.z - 4.0).abs() < 1e-5 && at.p.truncate().length() <= 0.7 + 1e-5);
                assert!(at.normal.unwrap().abs_diff_eq(-Vec3::Z, 1e-5));
            }
            3 => assert_eq!(at.p, Vec3::new(1.0, 1.0, 2.0)),
            4 => assert_eq!(at.p, spot_at),
            _ => {}
        }
        // The light point emits towards p, as far as emission sampling is concerned.
        let (pos, dir) = lights.emission_pdf(at.emitter, at.p, at.normal, -s.wi);
        assert!(pos > 0.0 && dir > 0.0, "{at:?} {s:?}: {pos} {dir}");
    }
    println!("light points per emitter: {seen:?}");
    assert!(seen.iter().all(|&n| n > 100), "{seen:?}");
}

#[test]
fn a_textured_lamp_emits_its_texture_where_its_rays_start() {
    // A unit quad under a world-space checkerboard of cells of side 1/3, three by three cells
    // in an odd layer: 4 of the 9 emit `bright`, so its flux is pi A bright 4/9 when each ray
    // carries the texture at its own origin (the texture's mean over the uv square, which
    // an untextured lamp would emit, is 5/9 of it).
    use crate::refs::{ConstOrTexture, TextureId};
    use crate::texture::{Checkerboard, Checkerboard3D, Mapping3D, TextureDesc, TextureKind};
    let bright = Vec3::new(2.0, 1.0, 0.5);
    let checker = TextureDesc {
        name: "checks".into(),
        is_color: true,
        kind: TextureKind::Checkerboard(Checkerboard::D3(Checkerboard3D {
            tex1: ConstOrTexture::color(bright),
            tex2: ConstOrTexture::color(Vec3::ZERO),
            mapping: Mapping3D::global(Mat4::from_scale(Vec3::splat(3.0))),
        })),
    };
    let textures = Arc::new(Textures::new(&[checker], &MemorySource::new()).unwrap());
    let lamp = ShapeDesc {
        area_light: Some(AreaLightDesc {
            l: ConstOrTexture::Texture(TextureId(0)),
            ..AreaLightDesc::constant(Vec3::ZERO)
        }),
        media: Default::default(),
        ..shape(
            square_facing_down(1.0),
            Mat4::from_translation(Vec3::new(1.0 / 6.0, 1.0 / 6.0, 0.4)),
        )
    };
    let desc = scene_desc(vec![lamp], vec![]);
    let geometry = SceneGeometry::build(&desc.shapes);
    let lights = Lights::build(
        &desc.shapes,
        &desc.lights,
        &geometry,
        &textures,
        &MemorySource::new(),
        LatLongConvention::Seed,
    )
    .unwrap();
    let e = estimate_emission(&lights, 200_000, 17);
    let expected = (PI * bright * 4.0 / 9.0).as_dvec3();
    println!(
        "textured quad: flux {} expected {expected} (stderr {:.2e})",
        e.mean, e.stderr
    );
    for c in 0..3 {
        assert!(
            (e.mean[c] / expected[c] - 1.0).abs() < 0.01,
            "flux {} expected {expected}",
            e.mean
        );
    }
    assert!(e.pdf_err < 1e-4);
}

/// A portal: the unit square facing down at height `z` (light passes it going down), for the
/// lights of `lights`.
fn portal_facing_down(z: f32, lights: std::ops::Range<u32>) -> PortalDesc {
    PortalDesc {
        geometry: square_facing_down(1.0),
        object_to_world: Mat4::from_translation(Vec3::new(1.0, 0.0, z)),
        reverse_orientation: false,
        lights,
    }
}

/// With a portal, light from a direction starts its rays behind the portal: every ray crosses
/// it going the way its front faces, the weights estimate the flux through the portal alone
/// (pi L A for a constant environment of radiance L, E A cos for a distant light and a sun of
/// irradiance E), and `emission_pdf` and `pdf_from_infinity` anywhere along the ray give the
/// density the sample had. Light that crosses no portal has no density; a portal facing away
/// from a distant light lets none of it start.
#[test]
fn portals_start_light_from_a_direction_behind_them() {
    let to_light = Vec3::new(0.2, 0.3, 1.0).normalize();
    let radiance = Vec3::new(2.0, 1.0, 0.5);
    let (sun, sun_flux) = sun_to(Vec3::new(0.3, -0.4, 0.8).normalize());
    let cases = [
        (
            "constant infinite",
            constant_sky(0.5),
            DVec3::splat(0.5 * PI64),
        ),
        (
            "distant",
            LightDesc::Distant(DistantLight { to_light, radiance }),
            radiance.as_dvec3() * f64::from(to_light.z),
        ),
        (
            "sun",
            LightDesc::Sun(sun),
            sun_flux * f64::from(Vec3::new(0.3, -0.4, 0.8).normalize().z),
        ),
    ];
    for (name, light, expected) in cases {
        let emitter = if matches!(light, LightDesc::Distant(_)) {
            Emitter::Light(0)
        } else {
            Emitter::Environment
        };
        let (_, lights) = build(vec![bystander()], vec![light.clone()]);
        let lights = lights.with_portals(&[portal_facing_down(0.5, 0..1)]);
        let e = estimate_emission(&lights, 200_000, 23);
        println!(
            "{name} through a portal: flux {} expected {expected} (stderr {:.2e}), pdf rel err \
             {:.2e}, {} sampled",
            e.mean, e.stderr, e.pdf_err, e.samples
        );
        for c in 0..3 {
            assert!(
                (e.mean[c] / expected[c] - 1.0).abs() < 0.01,
                "{name}: flux {} expected {expected}",
                e.mean
            );
        }
        assert!(e.pdf_err < 1e-4, "{name}: {}", e.pdf_err);
        let mut rng = fastrand::Rng::with_seed(3);
        for _ in 0..2000 {
            let u = |rng: &mut fastrand::Rng| Vec2::new(rng.f32(), rng.f32());
            let Some(s) = lights.sample_emission(rng.f32(), u(&mut rng), u(&mut rng)) else {
                continue;
            };
            let ray = s.ray;
            assert!(ray.dir.z < 0.0, "{name}: {ray:?}");
            let t = (0.5 - ray.origin.z) / ray.dir.z;
            let at = ray.origin + ray.dir * t;
            assert!(
                t > 0.0 && (at.x - 1.0).abs() <= 0.5 + 1e-4 && at.y.abs() <= 0.5 + 1e-4,
                "{name}: the ray crosses the portal at {at}"
            );
            // Behind the scene's sphere: the ray crosses everything between.
            assert!(ray.origin.distance(Vec3::X) >= 2.0 * 3f32.sqrt() - 1e-3);
            // The light alone is chosen with probability 1.
            let beyond = lights.pdf_from_infinity(emitter, ray.dir, at + ray.dir * 2.0);
            assert!(
                rel_err(beyond, ray.pdf_pos) < 1e-4,
                "{name}: {beyond} against {}",
                ray.pdf_pos
            );
            let beside = at + Vec3::new(3.0, 0.0, 0.0);
            assert_eq!(lights.pdf_from_infinity(emitter, ray.dir, beside), 0.0);
        }
    }
    // A portal that faces up: no light of a distant light going down starts there.
    let (_, lights) = build(
        vec![bystander()],
        vec![LightDesc::Distant(DistantLight { to_light, radiance })],
    );
    let mut up = portal_facing_down(0.5, 0..1);
    up.reverse_orientation = true;
    let lights = lights.with_portals(&[up]);
    let e = estimate_emission(&lights, 1000, 1);
    assert_eq!(e.samples, 0);
}
