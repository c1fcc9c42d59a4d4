//! Whole-renderer tests on scenes built in code: analytic values (white furnace), camera
//! properties, environment-map orientation and determinism.

use std::sync::Arc;

use glam::{Mat4, Vec3, Vec4};
use yat_tracer::assets::MemorySource;
use yat_tracer::desc::*;
use yat_tracer::film::Film;
use yat_tracer::filter::PixelFilter;
use yat_tracer::lights::InfiniteLight;
use yat_tracer::material::Matte;
use yat_tracer::render::{plan_units, RenderScene, RenderSettings, WorkUnit};
use yat_tracer::sampler::PixelSampler;
use yat_tracer::texture::{Checkerboard, Checkerboard2D};

use crate::scene::empty_scene as scene;

/// A camera at `eye` looking along +y with z up (camera x = world x, camera y = world z).
fn camera(kind: CameraKind, eye: Vec3, lens_radius: f32, focal_distance: f32) -> CameraDesc {
    CameraDesc {
        kind,
        camera_to_world: Mat4::from_cols(
            Vec3::X.extend(0.0),
            Vec3::Z.extend(0.0),
            Vec3::Y.extend(0.0),
            eye.extend(1.0),
        ),
        screen_window: [-1.0, 1.0, -1.0, 1.0],
        lens_radius,
        focal_distance,
        autofocus: false,
        aperture: Default::default(),
        hither: 1e-3,
        yon: 1e30,
    }
}

fn add_sphere(desc: &mut SceneDesc, centre: Vec3, radius: f32, material: MaterialDesc) {
    desc.materials.push(material);
    desc.shapes.push(ShapeDesc {
        name: "sphere".into(),
        geometry: Geometry::Sphere(Sphere {
            radius,
            zmin: -radius,
            zmax: radius,
            phimax: 360.0,
        }),
        object_to_world: Mat4::from_translation(centre),
        reverse_orientation: false,
        material: MaterialId(desc.materials.len() as u32 - 1),
        area_light: None,
        media: Default::default(),
    });
}

fn constant_sky(desc: &mut SceneDesc, radiance: Vec3) {
    desc.lights.push(LightDesc::Infinite(InfiniteLight {
        radiance,
        map: None,
        light_to_world: Mat4::IDENTITY,
    }));
}

fn settings(desc: &SceneDesc, spp: u32) -> RenderSettings {
    RenderSettings {
        width: desc.film.xresolution,
        height: desc.film.yresolution,
        spp,
        max_depth: desc.integrator.max_depth,
        seed: 1,
        latlong: LatLongConvention::Seed,
        transport: Default::default(),
        aovs: Default::default(),
    }
}

fn render(desc: &SceneDesc, source: &MemorySource, spp: u32) -> Film {
    let settings = settings(desc, spp);
    let scene = RenderScene::build(desc, source, &settings).expect("scene builds");
    let mut film = Film::new(scene.frame());
    for unit in plan_units(&settings) {
        film.add(&scene.render_unit(&unit).0).unwrap();
    }
    film
}

/// Renders every unit of the plan of `desc` at `spp` samples per pixel (at `resolution` when
/// given) into one film, asserting that no sample was NaN: the whole-render helper of the
/// daylight and volume tests.
pub fn render_whole(
    desc: &SceneDesc,
    source: &dyn yat_tracer::assets::AssetSource,
    spp: u32,
    resolution: Option<(u32, u32)>,
) -> Film {
    let overrides = yat_tracer::render::RenderOverrides {
        spp: Some(spp),
        resolution,
        ..Default::default()
    };
    render_whole_with(desc, source, &overrides)
}

/// [`render_whole`] with any overrides (the integrator, the seed, ...).
pub fn render_whole_with(
    desc: &SceneDesc,
    source: &dyn yat_tracer::assets::AssetSource,
    overrides: &yat_tracer::render::RenderOverrides,
) -> Film {
    let settings = RenderSettings::resolve(desc, overrides);
    let scene = RenderScene::build(desc, source, &settings).expect("scene builds");
    let mut film = Film::new(scene.frame());
    for unit in plan_units(&settings) {
        let (buffer, stats) = scene.render_unit(&unit);
        assert_eq!(stats.dropped, 0, "NaN samples");
        film.add(&buffer).unwrap();
    }
    film
}

/// [`render_whole_with`] of the scene `text` (one file, which must parse without a warning).
pub fn render_text(text: &str, overrides: &yat_tracer::render::RenderOverrides) -> Film {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    let desc =
        yat_tracer::parse::parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    render_whole_with(&desc, &source, overrides)
}

fn mean(film: &Film, pixels: impl Iterator<Item = (u32, u32)>) -> Vec3 {
    let (sum, n) = pixels.fold((Vec3::ZERO, 0), |(s, n), (x, y)| {
        (s + film.pixel(x, y), n + 1)
    });
    sum / n as f32
}

/// A convex white Lambertian object under a uniform sky of radiance L reflects exactly L; with
/// albedo 0.5 it reflects L / 2. Every pixel sees either the sky or the sphere. Albedo 0.1 has
/// Russian roulette end most paths at their first vertex (survival 0.3): the survivors' weight
/// must make up for it.
#[test]
fn white_furnace_converges_to_the_sky_radiance() {
    for (albedo, expected) in [(1.0, 0.5), (0.5, 0.25), (0.1, 0.05)] {
        let mut desc = scene(
            camera(
                CameraKind::Perspective { fov: 30.0 },
                Vec3::new(0.0, -4.0, 0.0),
                0.0,
                1e30,
            ),
            16,
        );
        add_sphere(
            &mut desc,
            Vec3::ZERO,
            1.0,
            MaterialDesc::Matte(Matte {
                kd: ConstOrTexture::float(albedo),
                sigma: ConstOrTexture::float(0.0),
            }),
        );
        constant_sky(&mut desc, Vec3::splat(0.5));
        let film = render(&desc, &MemorySource::new(), 64);
        // The centre pixels see the sphere only.
        let centre = mean(&film, (6..10).flat_map(|y| (6..10).map(move |x| (x, y))));
        for c in centre.to_array() {
            assert!(
                (c - expected).abs() < 0.01 * expected.max(0.5),
                "albedo {albedo}: {centre}"
            );
        }
    }
}

/// Inside a closed sphere that emits Le and reflects with albedo a, every path bounces until
/// the depth limit: L = Le (1 + a + ... + a^depth) per channel. A saturated red (0.9, 0.05,
/// 0.05) is where Russian roulette on luminance goes wrong: the red throughput stays high
/// while luminance is small, and the few surviving paths carry fireflies. The mean must hold
/// and the red channel must stay quiet.
#[test]
fn saturated_interreflection_converges_without_fireflies() {
    let albedo = Vec3::new(0.9, 0.05, 0.05);
    let le = Vec3::splat(0.1);
    let mut desc = scene(
        camera(CameraKind::Perspective { fov: 60.0 }, Vec3::ZERO, 0.0, 1e30),
        16,
    );
    desc.integrator.max_depth = 10;
    add_sphere(
        &mut desc,
        Vec3::ZERO,
        2.0,
        MaterialDesc::Matte(Matte {
            kd: ConstOrTexture::color(albedo),
            sigma: ConstOrTexture::float(0.0),
        }),
    );
    let shape = desc.shapes.last_mut().unwrap();
    shape.reverse_orientation = true;
    shape.area_light = Some(AreaLightDesc::constant(le));
    let film = render(&desc, &MemorySource::new(), 16);
    let depth = desc.integrator.max_depth as i32;
    let expected = le * (Vec3::ONE - albedo.powf((depth + 1) as f32)) / (Vec3::ONE - albedo);
    let pixels: Vec<Vec3> = (0..16)
        .flat_map(|y| (0..16).map(move |x| (x, y)))
        .map(|(x, y)| film.pixel(x, y))
        .collect();
    let mean = pixels.iter().sum::<Vec3>() / pixels.len() as f32;
    assert!(
        ((mean - expected) / expected).abs().max_element() < 0.03,
        "mean {mean}, expected {expected}"
    );
    let red_var = pixels.iter().map(|p| (p.x - mean.x).powi(2)).sum::<f32>() / pixels.len() as f32;
    let red_rel_std = red_var.sqrt() / mean.x;
    // Measured: 0.05 with roulette on the largest channel, 0.19 with it on luminance.
    assert!(red_rel_std < 0.1, "red relative std {red_rel_std}");
}

#[test]
fn zero_lens_radius_gives_exactly_the_pinhole_image() {
    let build = |focal_distance| {
        let mut desc = scene(
            camera(
                CameraKind::Perspective { fov: 40.0 },
                Vec3::new(0.0, -4.0, 0.0),
                0.0,
                focal_distance,
            ),
            16,
        );
        add_sphere(
            &mut desc,
            Vec3::ZERO,
            1.0,
            MaterialDesc::Matte(Matte {
                kd: ConstOrTexture::float(0.7),
                sigma: ConstOrTexture::float(0.0),
            }),
        );
        constant_sky(&mut desc, Vec3::ONE);
        render(&desc, &MemorySource::new(), 8).radiance()
    };
    assert_eq!(build(1e30), build(2.5));
}

/// A thin lens blurs what is off the focal plane: the sphere's edge spreads over more pixels.
#[test]
fn thin_lens_blurs_out_of_focus_objects() {
    let edge_width = |lens_radius: f32| {
        let mut desc = scene(
            camera(
                CameraKind::Perspective { fov: 30.0 },
                Vec3::new(0.0, -4.0, 0.0),
                lens_radius,
                12.0,
            ),
            32,
        );
        add_sphere(
            &mut desc,
            Vec3::ZERO,
            1.0,
            MaterialDesc::Matte(Matte {
                kd: ConstOrTexture::float(0.0),
                sigma: ConstOrTexture::float(0.0),
            }),
        );
        constant_sky(&mut desc, Vec3::ONE);
        let film = render(&desc, &MemorySource::new(), 32);
        // Pixels of the middle row that are neither sky (1) nor sphere (0).
        (0..32)
            .filter(|&x| (0.05..0.95).contains(&film.pixel(x, 16).x))
            .count()
    };
    let sharp = edge_width(0.0);
    let blurred = edge_width(0.3);
    assert!(sharp <= 2, "pinhole edge spans {sharp} pixels");
    assert!(blurred >= sharp + 4, "lens 0.3 edge spans {blurred} pixels");
}

#[test]
fn fisheye_corners_are_black_and_centre_is_not() {
    let mut desc = scene(
        camera(CameraKind::Fisheye { fov: 90.0 }, Vec3::ZERO, 0.0, 1e30),
        32,
    );
    constant_sky(&mut desc, Vec3::splat(0.8));
    let film = render(&desc, &MemorySource::new(), 4);
    for (x, y) in [(0, 0), (31, 0), (0, 31), (31, 31)] {
        assert_eq!(film.pixel(x, y), Vec3::ZERO);
    }
    assert!((film.pixel(16, 16) - Vec3::splat(0.8)).length() < 1e-4);
}

/// A LatLong map whose only red texel sits at u = 0.75, v = 0.5: with the seed convention
/// (u = (pi + phi) / 2pi) that is phi = pi / 2, the +y horizon; with LuxRender's (u = phi / 2pi)
/// it is phi = 3pi / 2, the -y horizon.
#[test]
fn environment_marker_shows_up_in_the_convention_direction() {
    let (w, h) = (64u32, 32u32);
    let mut img = image::RgbImage::from_pixel(w, h, image::Rgb([0, 0, 40]));
    for y in h / 2 - 2..h / 2 + 2 {
        for x in 3 * w / 4 - 2..3 * w / 4 + 2 {
            img.put_pixel(x, y, image::Rgb([255, 0, 0]));
        }
    }
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let mut source = MemorySource::new();
    source.insert("marker.png", Arc::from(png.into_boxed_slice()));

    let red_towards = |convention: LatLongConvention, forward: Vec3| {
        let mut cam = camera(CameraKind::Perspective { fov: 10.0 }, Vec3::ZERO, 0.0, 1e30);
        let right = forward.cross(Vec3::Z);
        cam.camera_to_world = Mat4::from_cols(
            right.extend(0.0),
            Vec3::Z.extend(0.0),
            forward.extend(0.0),
            Vec4::W,
        );
        let mut desc = scene(cam, 8);
        desc.lights.push(LightDesc::Infinite(InfiniteLight {
            radiance: Vec3::ONE,
            map: Some(EnvMapDesc {
                filename: "marker.png".into(),
                gamma: 1.0,
            }),
            light_to_world: Mat4::IDENTITY,
        }));
        let mut settings = settings(&desc, 4);
        settings.latlong = convention;
        let scene = RenderScene::build(&desc, &source, &settings).unwrap();
        let mut film = Film::new(scene.frame());
        for unit in plan_units(&settings) {
            film.add(&scene.render_unit(&unit).0).unwrap();
        }
        let c = film.pixel(4, 4);
        c.x > 0.5 && c.z < 0.1
    };
    assert!(red_towards(LatLongConvention::Seed, Vec3::Y));
    assert!(!red_towards(LatLongConvention::Seed, -Vec3::Y));
    assert!(red_towards(LatLongConvention::LuxRender, -Vec3::Y));
    assert!(!red_towards(LatLongConvention::LuxRender, Vec3::Y));
}

/// The same unit gives the same bytes, and merging the plan in any order gives the same film.
#[test]
fn rendering_is_deterministic_in_any_order() {
    let mut desc = scene(
        camera(
            CameraKind::Perspective { fov: 40.0 },
            Vec3::new(0.0, -4.0, 0.5),
            0.2,
            4.0,
        ),
        24,
    );
    add_sphere(
        &mut desc,
        Vec3::ZERO,
        1.0,
        MaterialDesc::Matte(Matte {
            kd: ConstOrTexture::float(0.8),
            sigma: ConstOrTexture::float(0.0),
        }),
    );
    constant_sky(&mut desc, Vec3::new(0.3, 0.5, 0.9));
    let settings = settings(&desc, 8);
    let scene = RenderScene::build(&desc, &MemorySource::new(), &settings).unwrap();
    let units = plan_units(&settings);
    let buffers: Vec<_> = units.iter().map(|u| scene.render_unit(u).0).collect();
    assert_eq!(buffers[0], scene.render_unit(&units[0]).0);
    let mut forward = Film::new(scene.frame());
    let mut backward = Film::new(scene.frame());
    buffers.iter().for_each(|b| forward.add(b).unwrap());
    buffers.iter().rev().for_each(|b| backward.add(b).unwrap());
    assert_eq!(forward.radiance(), backward.radiance());
    assert!(forward.radiance().iter().any(|c| c.x != c.z));
}

/// 3D texture mappings see the shape's object space (the seed scenes' rule): a planar-mapped
/// checkerboard on a unit quad scaled by 5 has checks 5 world units wide, not 1.
#[test]
fn planar_mapping_follows_the_object_space() {
    let mut cam = camera(
        CameraKind::Perspective { fov: 90.0 },
        Vec3::new(0.0, 0.0, 10.0),
        0.0,
        1e30,
    );
    cam.camera_to_world = Mat4::from_cols(
        Vec3::X.extend(0.0),
        Vec3::Y.extend(0.0),
        (-Vec3::Z).extend(0.0),
        Vec3::new(0.0, 0.0, 10.0).extend(1.0),
    );
    let mut desc = scene(cam, 40);
    desc.textures.push(TextureDesc {
        name: "checks".into(),
        is_color: true,
        kind: TextureKind::Checkerboard(Checkerboard::D2(Checkerboard2D {
            tex1: ConstOrTexture::float(1.0),
            tex2: ConstOrTexture::float(0.0),
            mapping: Mapping2D::Planar {
                world_to_texture: Mat4::IDENTITY,
                v1: Vec3::X,
                v2: Vec3::Y,
                udelta: 0.0,
                vdelta: 0.0,
            },
        })),
    });
    desc.materials.push(MaterialDesc::Matte(Matte {
        kd: ConstOrTexture::Texture(TextureId(0)),
        sigma: ConstOrTexture::float(0.0),
    }));
    desc.shapes.push(ShapeDesc {
        name: "quad".into(),
        geometry: Geometry::Mesh(Arc::new(TriangleMesh {
            positions: vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            normals: None,
            uvs: None,
            indices: vec![[0, 1, 2], [0, 2, 3]],
        })),
        object_to_world: Mat4::from_scale(Vec3::new(5.0, 5.0, 1.0)),
        reverse_orientation: false,
        material: MaterialId(0),
        area_light: None,
        media: Default::default(),
    });
    constant_sky(&mut desc, Vec3::ONE);
    let film = render(&desc, &MemorySource::new(), 4);
    // World (1.5, 0.5) is object (0.3, 0.1): check (0, 0), white; world-space mapping would
    // put it in check (1, 0), black. World (-1.5, 0.5) is object (-0.3, 0.1): black.
    assert!(film.pixel(23, 19).x > 0.9, "{}", film.pixel(23, 19));
    assert!(film.pixel(17, 19).x < 0.1, "{}", film.pixel(17, 19));
}

/// A sky of constant radiance seen through a pinhole: every camera sample's radiance is the
/// sky's, whatever the filter.
fn sky_only(size: u32, filter: FilterDesc) -> SceneDesc {
    let mut desc = scene(
        camera(CameraKind::Perspective { fov: 40.0 }, Vec3::ZERO, 0.0, 1e30),
        size,
    );
    desc.film.xresolution = size + 2 * 33;
    desc.filter = filter;
    constant_sky(&mut desc, Vec3::new(0.3, 0.5, 0.9));
    desc
}

fn mitchell(width: f32) -> FilterDesc {
    FilterDesc {
        kind: FilterKind::MITCHELL,
        xwidth: width,
        ywidth: width,
    }
}

fn blackman_harris(width: f32) -> FilterDesc {
    FilterDesc {
        kind: FilterKind::BlackmanHarris,
        xwidth: width,
        ywidth: width,
    }
}

/// Each sample splats its whole filter weight into the unit's buffer: away from the film's
/// edges the buffer's weights add up to every sample's own weights (its taps over the two axes,
/// unclipped), and on average to the filter's integral (Blackman-Harris over [-2, 2], its peak
/// scaled to 1: 0.35875 x 4 per axis).
#[test]
fn a_unit_splats_every_samples_whole_filter_weight() {
    let desc = sky_only(64, blackman_harris(2.0));
    let settings = settings(&desc, 4);
    let scene = RenderScene::build(&desc, &MemorySource::new(), &settings).unwrap();
    let filter = PixelFilter::new(&desc.filter);
    // A unit inside the film: its border is not clipped.
    let unit = WorkUnit {
        index: 0,
        x0: 40,
        y0: 20,
        x1: 60,
        y1: 36,
        sample_start: 1,
        sample_end: 4,
        mask: None,
    };
    let (buffer, stats) = scene.render_unit(&unit);
    assert_eq!(buffer.region.pixel_count(), 24 * 20);
    assert_eq!(stats.samples, 20 * 16 * 3);
    let mut expected = 0.0f64;
    for y in unit.y0..unit.y1 {
        for x in unit.x0..unit.x1 {
            for index in unit.sample_start..unit.sample_end {
                let mut sampler = PixelSampler::new(x, y, index, settings.spp, settings.seed);
                let u = sampler.get_2d();
                let f = filter.footprint((x, y), u, (0, 0), (u32::MAX, u32::MAX));
                for row in 0..f.row_count() {
                    let weights = f.row(row);
                    expected += weights[..f.column_count()]
                        .iter()
                        .map(|&w| f64::from(w))
                        .sum::<f64>();
                }
            }
        }
    }
    let total: f64 = buffer.weight.iter().map(|&w| f64::from(w)).sum();
    assert!(
        (total - expected).abs() < 1e-5 * expected,
        "{total} against {expected}"
    );
    let integral = (0.35875f64 * 4.0).powi(2);
    let per_sample = total / stats.samples as f64;
    assert!(
        (per_sample - integral).abs() < 0.01 * integral,
        "{per_sample} against {integral}"
    );
}

/// A uniform sky renders as exactly its radiance in every pixel, the film's edges (where part of
/// each filter falls outside) and the overlaps of units' borders included, through filters with
/// negative lobes too; the units merge to the same bits in any order.
#[test]
fn a_constant_sky_renders_exactly_constant_through_every_filter() {
    let sky = Vec3::new(0.3, 0.5, 0.9);
    for filter in [
        mitchell(2.0),
        blackman_harris(2.0),
        mitchell(3.3),
        FilterDesc {
            kind: FilterKind::Sinc { tau: 3.0 },
            xwidth: 4.0,
            ywidth: 1.5,
        },
    ] {
        let desc = sky_only(70, filter);
        let settings = settings(&desc, 16);
        let scene = RenderScene::build(&desc, &MemorySource::new(), &settings).unwrap();
        let units = plan_units(&settings);
        assert!(units.len() >= 8, "tiles meet inside the film");
        let buffers: Vec<_> = units.iter().map(|u| scene.render_unit(u).0).collect();
        let mut forward = Film::new(scene.frame());
        let mut backward = Film::new(scene.frame());
        buffers.iter().for_each(|b| forward.add(b).unwrap());
        buffers.iter().rev().for_each(|b| backward.add(b).unwrap());
        assert_eq!(forward.sums(), backward.sums(), "{filter:?}");
        for (i, c) in forward.radiance().into_iter().enumerate() {
            assert!(
                (c - sky).abs().max_element() < 2e-6,
                "{filter:?}: pixel {i} is {c}"
            );
        }
    }
}

/// A box of half-width 0.5 gives each sample to its own pixel with weight 1, as filter
/// importance sampling did: a pixel's weight sum is its sample count.
#[test]
fn a_half_pixel_box_keeps_every_sample_in_its_pixel() {
    let desc = sky_only(
        20,
        FilterDesc {
            kind: FilterKind::Box,
            xwidth: 0.5,
            ywidth: 0.5,
        },
    );
    let settings = settings(&desc, 5);
    let scene = RenderScene::build(&desc, &MemorySource::new(), &settings).unwrap();
    assert_eq!(scene.frame().border, [0, 0]);
    for unit in plan_units(&settings) {
        let buffer = scene.render_unit(&unit).0;
        assert_eq!(buffer.region.pixel_count(), unit.pixel_count());
        let samples = (unit.sample_end - unit.sample_start) as f32;
        assert!(buffer.weight.iter().all(|&w| w == samples));
    }
}
