//! LuxRender's outlier rejection (`Film "fleximage" "integer outlierrejection_k"`): fireflies go,
//! a smooth image keeps its brightness to a small bias, and k = 0 renders every sample.

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::RenderOverrides;

use crate::render::render_whole_with;

/// A matte floor seen from straight above under a dim sky; out of view, a mirror ball and
/// beyond it a tiny very bright lamp behind a low wall, which hides the lamp from the floor:
/// the floor sees the lamp only in the mirror, when a diffuse bounce happens to find its
/// reflection (no light sample can), so the image is the sky-lit floor and fireflies. `k` is
/// the Film's outlierrejection_k.
fn scene(k: i32) -> String {
    format!(
        "Film \"fleximage\" \"integer xresolution\" [32] \"integer yresolution\" [32]\n\
         \x20 \"integer outlierrejection_k\" [{k}]\n\
         PixelFilter \"box\" \"float xwidth\" [0.5] \"float ywidth\" [0.5]\n\
         LookAt 0 0 5  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" [30]\n\
         WorldBegin\n\
         LightSource \"infinite\" \"color L\" [0.2 0.2 0.2]\n\
         Material \"matte\" \"color Kd\" [0.7 0.7 0.7]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [-6 -6 0  6 -6 0  6 6 0  -6 6 0]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [2.9 -3 0  2.9 3 0  2.9 3 0.58  2.9 -3 0.58]\n\
         AttributeBegin\n\
         Material \"mirror\" \"color Kr\" [0.9 0.9 0.9]\n\
         Translate 2.5 0 0.6\n\
         Shape \"sphere\" \"float radius\" [0.5]\n\
         AttributeEnd\n\
         AttributeBegin\n\
         AreaLightSource \"area\" \"color L\" [1 1 1] \"float gain\" [3000]\n\
         Translate 3.2 0 0.6\n\
         Shape \"sphere\" \"float radius\" [0.05]\n\
         AttributeEnd\n\
         WorldEnd\n"
    )
}

fn render(text: &str, spp: u32) -> Film {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let overrides = RenderOverrides {
        spp: Some(spp),
        ..Default::default()
    };
    render_whole_with(&desc, &source, &overrides)
}

/// Fireflies are single samples far brighter than their neighbours: the floor's pixels more
/// than 10 times the median go with k = 2, the median stays within 1%, and k = 0 renders what
/// no parameter renders, bit for bit.
#[test]
fn outlier_rejection_removes_fireflies() {
    let luminance = |c: Vec3| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    let stats = |film: &Film| {
        let mut y: Vec<f32> = film.radiance().into_iter().map(luminance).collect();
        y.sort_by(f32::total_cmp);
        let median = y[y.len() / 2];
        (median, y.iter().filter(|&&v| v > 10.0 * median).count())
    };
    let (median0, fireflies0) = stats(&render(&scene(0), 256));
    let (median2, fireflies2) = stats(&render(&scene(2), 256));
    assert!(fireflies0 >= 3, "the scene has fireflies: {fireflies0}");
    assert_eq!(fireflies2, 0, "fireflies left with k = 2");
    assert!(
        (median2 / median0 - 1.0).abs() < 0.01,
        "median {median2} with k = 2, {median0} without"
    );
    let plain = scene(0).replace("\x20 \"integer outlierrejection_k\" [0]\n", "");
    assert_eq!(
        render(&plain, 4).radiance(),
        render(&scene(0), 4).radiance()
    );
}
