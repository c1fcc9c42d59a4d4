//! The seed scenes render as their authors composed them: a small render of each scene that has
//! a published render is compared with that render (`../shared/seed-project/renders`) on a
//! coarse grid of luminance. Tone mapping and light handling differ between the two tracers, so
//! the test compares structure (correlation of the block means: framing, orientation, where the
//! bright and dark parts are), not absolute values. Skipped when the seed project is absent.

use crate::statistics::correlation;
use std::path::{Path, PathBuf};

use yat_tracer::assets::FsSource;
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{plan_units, RenderOverrides, RenderScene, RenderSettings};

use crate::util::seed_scenes;

/// The seed project (its `renders/` beside the scene folder).
fn seed_project() -> Option<PathBuf> {
    let dir = seed_scenes()?.join("..");
    if dir.join("renders").is_dir() {
        Some(dir)
    } else {
        println!("seed renders not found at {}; skipping", dir.display());
        None
    }
}

const GRID: (u32, u32) = (12, 8);

/// Mean luminance of each cell of a `GRID` over an 8-bit RGB image.
fn block_means(img: &image::RgbImage) -> Vec<f64> {
    let (gw, gh) = GRID;
    let (w, h) = img.dimensions();
    let mut sums = vec![(0.0f64, 0u32); (gw * gh) as usize];
    for (x, y, p) in img.enumerate_pixels() {
        let cell = ((y * gh / h) * gw + x * gw / w) as usize;
        let l = 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
        sums[cell].0 += l;
        sums[cell].1 += 1;
    }
    sums.iter().map(|&(s, n)| s / f64::from(n.max(1))).collect()
}

fn render_small(scene: &Path, width: u32, height: u32) -> image::RgbImage {
    let name = scene.file_name().unwrap().to_str().unwrap();
    let source = FsSource::for_main_file(scene);
    let desc = parse_scene(name, &source).expect("seed scene parses");
    let settings = RenderSettings::resolve(
        &desc,
        &RenderOverrides {
            spp: Some(16),
            max_depth: Some(10),
            resolution: Some((width, height)),
            ..Default::default()
        },
    );
    let built = RenderScene::build(&desc, &source, &settings).expect("seed scene builds");
    let mut film = Film::new(built.frame());
    for unit in plan_units(&settings) {
        let (buffer, stats) = built.render_unit(&unit);
        assert_eq!(stats.dropped, 0, "{name}: NaN samples");
        film.add(&buffer).unwrap();
    }
    film.to_display(&desc.film)
}

#[test]
fn seed_scenes_look_like_their_published_renders() {
    let Some(seed) = seed_project() else { return };
    // (scene, published render, minimum correlation of the block luminances). DepthOfField is
    // left out: its checks have the seed render's size and place but the opposite phase (the
    // seed tracer reads planar t the other way up), which a coarse luminance grid cannot forgive.
    let cases = [
        (
            "CornellBoxFisheye/cornell-box-fisheye.lxs",
            "cornell-box1000.png",
            0.95,
        ),
        (
            "CornellBoxFisheye/cornell-box-fisheye-high-fov.lxs",
            "cornell-box-high1000.png",
            0.95,
        ),
        (
            "MetalMario/metal-mario-bg1.lxs",
            "metal-mario-bg1-1000.png",
            0.8,
        ),
        (
            "CaptainFalcon/captainfalcon.lxs",
            "captain-falcon1000.png",
            0.7,
        ),
        ("GokuSelfie/goku-selfie.lxs", "goku-selfie1000.png", 0.75),
        ("Ornstein/ornstein.lxs", "ornstein1000.png", 0.75),
    ];
    let mut failures = Vec::new();
    for (scene, render, min) in cases {
        let reference = image::open(seed.join("renders").join(render))
            .expect("published render decodes")
            .to_rgb8();
        let (w, h) = reference.dimensions();
        let ours = render_small(&seed.join("scenes").join(scene), w / 8, h / 8);
        let r = correlation(&block_means(&ours), &block_means(&reference));
        println!("{scene}: correlation {r:.3} (minimum {min})");
        if r < min {
            failures.push(format!("{scene}: {r:.3} < {min}"));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}
