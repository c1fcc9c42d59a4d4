//! Thin-film interference on the exporter-written `scenes/exported/thin-film.lxs`: seen from
//! straight above under a uniform white sky, a filmed mirror's radiance is its tint times the
//! RGB of the film's interference spectrum, cos^2(4 pi n d / lambda) at normal incidence.

use glam::Vec3;
use yat_tracer::assets::FsSource;
use yat_tracer::parse::parse_scene;
use yat_tracer::spectra::spectrum_rgb;

use crate::render::render_whole;
use crate::util::workspace_root;

/// The RGB of the interference of a film `thickness` nm thick of index `index` seen head-on,
/// kept within [0, 1] as a reflectance.
fn interference(thickness: f64, index: f64) -> Vec3 {
    spectrum_rgb(|lambda| {
        libm::cos(4.0 * std::f64::consts::PI * index * thickness / lambda).powi(2)
    })
    .clamp(Vec3::ZERO, Vec3::ONE)
}

/// The mirror's 300 nm film of index 1.5 and shinymetal's 500 nm of index 1.33 colour their
/// panels as the interference spectra say, within 1.5% a channel; the first is magenta (green
/// under half of red and blue), so the film is not a grey scale.
#[test]
fn films_colour_mirror_reflections_with_their_interference() {
    let path = workspace_root().join("scenes/exported/thin-film.lxs");
    let source = FsSource::for_main_file(&path);
    let desc = parse_scene("thin-film.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let film = render_whole(&desc, &source, 16, None);
    let panel = |columns: std::ops::Range<u32>| {
        let (mut sum, mut n) = (Vec3::ZERO, 0.0);
        for x in columns {
            for y in 0..film.height() {
                sum += film.pixel(x, y);
                n += 1.0;
            }
        }
        sum / n
    };
    let mirror = panel(4..28);
    let shinymetal = panel(36..60);
    for (name, got, want) in [
        ("mirror", mirror, interference(300.0, 1.5)),
        ("shinymetal", shinymetal, 0.9 * interference(500.0, 1.33)),
    ] {
        assert!(
            (got - want).abs().max_element() < 0.015,
            "{name}: radiance {got}, interference {want}"
        );
    }
    assert!(mirror.y < 0.5 * mirror.x.min(mirror.z), "{mirror}");
}
