//! LuxRender's outlier rejection (`Film "fleximage" "integer outlierrejection_k"`): fireflies go,
//! a smooth image keeps its brightness to a small bias, and k = 0 renders every sample.

use glam::Vec3;
use yat_tracer::film::Film;
use yat_tracer::render::RenderOverrides;

use crate::render::render_text;
use crate::util::workspace_root;

/// `scenes/exported/fireflies.lxs` (fireflies of a lamp seen only through a mirror, LuxBlend's
/// `outlierrejection_k` 2) with `k` in its place.
fn scene(k: i32) -> String {
    let path = workspace_root().join("scenes/exported/fireflies.lxs");
    let text = std::fs::read_to_string(&path).expect("scenes/exported/fireflies.lxs");
    let line = "\"integer outlierrejection_k\" [2]";
    assert!(text.contains(line), "{}", path.display());
    text.replace(line, &format!("\"integer outlierrejection_k\" [{k}]"))
}

fn render(text: &str, spp: u32) -> Film {
    let overrides = RenderOverrides {
        spp: Some(spp),
        ..Default::default()
    };
    render_text(text, &overrides)
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
    let plain = scene(0).replace("\t\"integer outlierrejection_k\" [0]\n", "");
    assert_ne!(plain, scene(0), "the parameter's line is gone");
    assert_eq!(
        render(&plain, 4).radiance(),
        render(&scene(0), 4).radiance()
    );
}
