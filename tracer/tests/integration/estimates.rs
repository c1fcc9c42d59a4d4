//! What the tests of sampling strategies share: a square render of a scene text, and the
//! numbers they compare (mean, MSE between renders, and whether two means agree).

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{plan_units, RenderScene, RenderSettings};

/// The scene `text` (which must parse without warnings) built for a `size` x `size` render.
pub fn build(text: &str, size: u32, spp: u32, seed: u64) -> (RenderScene, RenderSettings) {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let settings = RenderSettings {
        width: size,
        height: size,
        spp,
        max_depth: desc.integrator.max_depth,
        seed,
        latlong: Default::default(),
    };
    let scene = RenderScene::build(&desc, &source, &settings).expect("scene builds");
    (scene, settings)
}

/// The rendered image's radiance, every unit rendered in process; no sample may be NaN.
pub fn radiance(scene: &RenderScene, settings: &RenderSettings) -> Vec<Vec3> {
    let mut film = Film::new(scene.frame());
    for unit in plan_units(settings) {
        let (buffer, stats) = scene.render_unit(&unit);
        assert_eq!(stats.dropped, 0, "NaN samples");
        film.add(&buffer).unwrap();
    }
    film.radiance()
}

/// The mean of the red channel.
pub fn mean(image: &[Vec3]) -> f64 {
    image.iter().map(|p| f64::from(p.x)).sum::<f64>() / image.len() as f64
}

/// Mean squared difference per channel.
pub fn mse(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| f64::from((*a - *b).length_squared()) / 3.0)
        .sum::<f64>()
        / a.len() as f64
}

/// Two estimators' means from two renders each (different seeds): `(mean a, mean b, standard
/// error of their difference)`. A render's mean has about 1 / pixels of its pixels' variance,
/// which is MSE between the two renders / 2; the mean of two renders half that.
pub fn compare_means(a: &[Vec<Vec3>; 2], b: &[Vec<Vec3>; 2]) -> (f64, f64, f64) {
    let pixels = a[0].len() as f64;
    let mean_of = |r: &[Vec<Vec3>; 2]| (mean(&r[0]) + mean(&r[1])) / 2.0;
    let variance = |r: &[Vec<Vec3>; 2]| mse(&r[0], &r[1]) / 2.0 / pixels / 2.0;
    (mean_of(a), mean_of(b), (variance(a) + variance(b)).sqrt())
}
