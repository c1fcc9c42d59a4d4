//! What the tests of sampling strategies share: a square render of a scene text, and the
//! numbers they compare (mean, MSE between renders, whether two estimators' means agree).

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::diag::Severity;
use yat_tracer::film::Film;
use yat_tracer::integrator::Transport;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{plan_units, RenderScene, RenderSettings};

/// A scene's opening: a camera 5 units above the origin looking down (fov 50), a `size` x
/// `size` film with a box filter, the path integrator with `integrator` parameters, and
/// `WorldBegin`.
pub fn looking_down(size: u32, integrator: &str) -> String {
    format!(
        "LookAt 0 0 5  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" [50]\n\
         Film \"fleximage\" \"integer xresolution\" [{size}] \"integer yresolution\" [{size}]\n\
         PixelFilter \"box\"\n\
         SurfaceIntegrator \"path\" {integrator}\n\
         WorldBegin\n"
    )
}

/// The sampling tests' grey floor (under the camera of [`looking_down`]), half-mirror and lamp.
pub const MATTE_FLOOR: &str = "Material \"matte\" \"color Kd\" [0.5 0.5 0.5]";
pub const FLOOR: [&str; 4] = ["-3 -3 0", "3 -3 0", "3 3 0", "-3 3 0"];
pub const MIRROR: &str = "Material \"mirror\" \"color Kr\" [0.5 0.5 0.5]";
pub const LAMP: &str = "AreaLightSource \"area\" \"color L\" [5 5 5] \"float power\" [0]";

/// A quad (two triangles over its four `points`, "x y z" each, in order) with `material`, a
/// `Material` or `AreaLightSource` statement, in its own attribute block.
pub fn quad(material: &str, points: [&str; 4]) -> String {
    format!(
        "AttributeBegin\n\
         {material}\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [{}]\n\
         AttributeEnd\n",
        points.join("  ")
    )
}

/// The scene `text` (which must parse without a warning that it renders otherwise than
/// LuxRender would) built for a `size` x `size` render.
pub fn build(text: &str, size: u32, spp: u32, seed: u64) -> (RenderScene, RenderSettings) {
    build_with(text, &[], size, spp, seed)
}

/// [`build`], the scene reading `files` (name, bytes) beside it.
pub fn build_with(
    text: &str,
    files: &[(&str, &[u8])],
    size: u32,
    spp: u32,
    seed: u64,
) -> (RenderScene, RenderSettings) {
    build_for(text, files, size, spp, seed, Transport::Path)
}

/// [`build_with`], rendered with `transport`.
pub fn build_for(
    text: &str,
    files: &[(&str, &[u8])],
    size: u32,
    spp: u32,
    seed: u64,
    transport: Transport,
) -> (RenderScene, RenderSettings) {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    for (name, bytes) in files {
        source.insert(*name, (*bytes).into());
    }
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    let differs = desc
        .warnings
        .iter()
        .filter(|w| w.severity == Severity::Differs);
    assert_eq!(differs.count(), 0, "{:?}", desc.warnings);
    let settings = RenderSettings {
        width: size,
        height: size,
        spp,
        max_depth: desc.integrator.max_depth,
        seed,
        latlong: Default::default(),
        transport,
        aovs: Default::default(),
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
fn mean(image: &[Vec3]) -> f64 {
    image.iter().map(|p| f64::from(p.x)).sum::<f64>() / image.len() as f64
}

/// Mean squared difference per channel.
fn mse(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| f64::from((*a - *b).length_squared()) / 3.0)
        .sum::<f64>()
        / a.len() as f64
}

/// Asserts that an estimator keeps a baseline's mean: `render(new, seed)` renders with the new
/// estimator or the baseline; two renders of each (seeds 1 and 2) must agree within three
/// standard errors of the difference of their means, and that error must be below 0.2% of the
/// mean (so a bias that large shows). A render's mean has about 1 / pixels of its pixels'
/// variance, which is the MSE between the two renders / 2; the mean of two renders half that.
pub fn assert_same_mean(render: impl Fn(bool, u64) -> Vec<Vec3>) {
    let (baseline, new) = (
        [1, 2].map(|seed| render(false, seed)),
        [1, 2].map(|seed| render(true, seed)),
    );
    let pixels = baseline[0].len() as f64;
    let mean_of = |r: &[Vec<Vec3>; 2]| (mean(&r[0]) + mean(&r[1])) / 2.0;
    let variance = |r: &[Vec<Vec3>; 2]| mse(&r[0], &r[1]) / 2.0 / pixels / 2.0;
    let (m_baseline, m_new) = (mean_of(&baseline), mean_of(&new));
    let standard_error = (variance(&baseline) + variance(&new)).sqrt();
    assert!(
        (m_new - m_baseline).abs() < 3.0 * standard_error && standard_error < 2e-3 * m_baseline,
        "mean {m_new}, baseline {m_baseline} (standard error {standard_error})"
    );
}

/// How much two renders (seeds 1 and 2) differ: MSE between them, twice a render's noise.
pub fn seed_difference(render: impl Fn(u64) -> Vec<Vec3>) -> f64 {
    mse(&render(1), &render(2))
}
