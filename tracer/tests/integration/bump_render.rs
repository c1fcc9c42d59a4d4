//! Bump maps in whole renders: a bump changes the shading of a sphere but not its silhouette,
//! and a closed, strongly bumped surface lets no outside light in.

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{plan_units, RenderScene, RenderSettings};

/// Renders the scene `text` at `spp` samples per pixel (seed 1).
fn render(text: &str, spp: u32) -> Film {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let settings = RenderSettings {
        width: desc.film.xresolution,
        height: desc.film.yresolution,
        spp,
        max_depth: desc.integrator.max_depth,
        seed: 1,
        latlong: Default::default(),
        transport: Default::default(),
        aovs: Default::default(),
    };
    let scene = RenderScene::build(&desc, &source, &settings).expect("scene builds");
    let mut film = Film::new(scene.frame());
    for unit in plan_units(&settings) {
        film.add(&scene.render_unit(&unit).0).unwrap();
    }
    film
}

const SIZE: u32 = 48;

/// A unit sphere seen from -y under a dim sky and a distant light, with `material`.
fn sphere_scene(textures: &str, material: &str) -> String {
    format!(
        "LookAt 0 -5 0  0 0 0  0 0 1\n\
         Camera \"perspective\" \"float fov\" [30]\n\
         Film \"fleximage\" \"integer xresolution\" [{SIZE}] \"integer yresolution\" [{SIZE}]\n\
         PixelFilter \"box\"\n\
         WorldBegin\n\
         LightSource \"infinite\" \"color L\" [0.1 0.1 0.1]\n\
         LightSource \"distant\" \"point from\" [1 -1 1] \"point to\" [0 0 0] \"color L\" [3 3 3]\n\
         {textures}\n\
         {material}\n\
         Shape \"sphere\" \"float radius\" [1]\n\
         WorldEnd\n"
    )
}

const BUMPS: &str = "Texture \"w\" \"float\" \"wrinkled\" \"vector scale\" [0.15 0.15 0.15]\n\
    Texture \"h\" \"float\" \"scale\" \"texture tex1\" \"w\" \"float tex2\" [0.03]";

#[test]
fn a_bump_changes_the_shading_but_not_the_silhouette() {
    let flat = render(
        &sphere_scene(BUMPS, "Material \"matte\" \"color Kd\" [0.7 0.7 0.7]"),
        4,
    );
    let bumped = render(
        &sphere_scene(
            BUMPS,
            "Material \"matte\" \"color Kd\" [0.7 0.7 0.7] \"texture bumpmap\" \"h\"",
        ),
        4,
    );
    // A pixel all of whose samples miss the sphere shows exactly the sky (as the corner does)
    // in both renders.
    let background = flat.pixel(0, 0);
    assert!(
        (background - Vec3::splat(0.1)).abs().max_element() < 1e-4,
        "{background}"
    );
    let sky = |film: &Film, x: u32, y: u32| film.pixel(x, y) == background;
    let (mut sphere, mut diff, mut sum) = (0, 0.0, 0.0);
    for y in 0..SIZE {
        for x in 0..SIZE {
            assert_eq!(
                sky(&flat, x, y),
                sky(&bumped, x, y),
                "silhouette differs at ({x}, {y})"
            );
            if !sky(&flat, x, y) {
                sphere += 1;
                diff += (flat.pixel(x, y) - bumped.pixel(x, y)).abs().x;
                sum += flat.pixel(x, y).x;
            }
        }
    }
    // The sphere covers pi (1 / (5 tan 15 deg))^2 / 4 of the image: about 0.44.
    let share = sphere as f32 / (SIZE * SIZE) as f32;
    assert!((0.38..0.5).contains(&share), "sphere covers {share}");
    // (Without the bump the two renders are bit-identical: same seed, same paths.)
    let relative = diff / sum;
    assert!(relative > 0.05, "mean change of the shading: {relative}");
}

#[test]
fn a_closed_bumped_surface_lets_no_outside_light_in() {
    // The camera inside a closed sphere whose inner side is a strongly bumped matte; the sky
    // and a distant light outside. A shading normal that let a path cross the surface would
    // bring light in.
    let text = "LookAt 0 0 0  0 1 0  0 0 1\n\
         Camera \"perspective\" \"float fov\" [90]\n\
         Film \"fleximage\" \"integer xresolution\" [24] \"integer yresolution\" [24]\n\
         WorldBegin\n\
         LightSource \"infinite\" \"color L\" [1 1 1]\n\
         LightSource \"distant\" \"point from\" [0 1 0] \"point to\" [0 0 0] \"color L\" [10 10 10]\n\
         Texture \"w\" \"float\" \"wrinkled\" \"vector scale\" [0.05 0.05 0.05]\n\
         Texture \"h\" \"float\" \"scale\" \"texture tex1\" \"w\" \"float tex2\" [0.5]\n\
         Material \"matte\" \"color Kd\" [0.9 0.9 0.9] \"texture bumpmap\" \"h\"\n\
         ReverseOrientation\n\
         Shape \"sphere\" \"float radius\" [2]\n\
         WorldEnd\n";
    let film = render(text, 8);
    let mut total = Vec3::ZERO;
    for y in 0..24 {
        for x in 0..24 {
            total += film.pixel(x, y);
        }
    }
    assert_eq!(total, Vec3::ZERO);
}
