//! The thin lens as LuxRender 1.x has it, on the exporter-written scenes of
//! `scenes/exported/`: the default focal distance (sharp at infinity), autofocus, and the
//! polygonal and weighted apertures of `blades`, `distribution` and `power`, each measured on
//! the rendered image against the pinhole's or the aperture's analytic shape.

use crate::statistics::correlation;
use std::f64::consts::PI;
use std::sync::Arc;

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::desc::SceneDesc;
use yat_tracer::diag::Severity;
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene;

use crate::render::render_whole;
use crate::util::workspace_root;

/// `scenes/exported/<name>`'s text.
fn scene_text(name: &str) -> String {
    let path = workspace_root().join("scenes/exported").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `text` with `from` replaced by `to` (which must be there), parsed.
fn variant(text: &str, from: &str, to: &str) -> SceneDesc {
    assert!(text.contains(from), "the scene has {from}");
    parse(&text.replace(from, to))
}

fn parse(text: &str) -> SceneDesc {
    let mut source = MemorySource::new();
    source.insert("main.lxs", Arc::from(text.as_bytes()));
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    // Nothing but the exporter's shutter times, which change nothing in the image.
    assert!(
        desc.warnings
            .iter()
            .all(|w| w.severity == Severity::NoEffect),
        "{:?}",
        desc.warnings
    );
    desc
}

fn render(desc: &SceneDesc, spp: u32, resolution: Option<(u32, u32)>) -> Film {
    render_whole(desc, &MemorySource::new(), spp, resolution)
}

/// The mean brightness of each `block` x `block` pixel square.
fn block_means(film: &Film, block: u32) -> Vec<f64> {
    let (bw, bh) = (film.width() / block, film.height() / block);
    let mut means = Vec::new();
    for by in 0..bh {
        for bx in 0..bw {
            let mut sum = 0.0;
            for y in by * block..(by + 1) * block {
                for x in bx * block..(bx + 1) * block {
                    let p = film.pixel(x, y);
                    sum += f64::from(p.x + p.y + p.z);
                }
            }
            means.push(sum / f64::from(block * block));
        }
    }
    means
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// LuxBlend's camera with depth of field off: a lens radius and LuxRender's default focal
/// distance of 1e30 (which overflowed YAT's thin-lens arithmetic into a black image). It
/// renders as the pinhole does: the same mean within 1% and 5 x 5 block means correlated at
/// 0.999 (the same samples either way; only the 6 mm lens differs).
#[test]
fn a_lens_without_a_focal_distance_renders_sharp_at_infinity() {
    let text = scene_text("lens-infinity.lxs");
    let lens = parse(&text);
    let pinhole = variant(
        &text,
        "\"float lensradius\" [0.006250000000000]",
        "\"float lensradius\" [0]",
    );
    let resolution = Some((80, 45));
    let lens = block_means(&render(&lens, 16, resolution), 5);
    let pinhole = block_means(&render(&pinhole, 16, resolution), 5);
    let ratio = mean(&lens) / mean(&pinhole);
    assert!((ratio - 1.0).abs() < 0.01, "mean ratio {ratio}");
    let r = correlation(&lens, &pinhole);
    assert!(r > 0.999, "block correlation {r}");
}

/// The bokeh scene's lamp as the camera images it, in pixels: `(circumradius, lamp radius)`.
/// A point at distance D seen through lens point L focused at F crosses the focal plane
/// displaced by L (1 - F / D), which the screen shows divided by F tan(fov / 2); the lamp's
/// sharp image is its angular radius on the same scale. The film's half-width is 32 pixels.
fn bokeh_geometry() -> (f64, f64) {
    let (lens_radius, focus, distance, lamp, tan) =
        (0.15, 1.0, 10.0, 0.15f64, libm::tan(15.0f64.to_radians()));
    let pixels = 32.0 / tan;
    let circumradius = lens_radius * (1.0 - focus / distance) / focus * pixels;
    let lamp_radius = libm::asin(lamp / distance) * pixels;
    (circumradius, lamp_radius)
}

/// Of the pixels the lamp lights, the rows and the columns they span.
fn lit_span(film: &Film) -> (u32, u32) {
    let lit = |x, y| film.pixel(x, y).max_element() > 0.0;
    let rows = (0..film.height())
        .filter(|&y| (0..film.width()).any(|x| lit(x, y)))
        .count();
    let columns = (0..film.width())
        .filter(|&x| (0..film.height()).any(|y| lit(x, y)))
        .count();
    (rows as u32, columns as u32)
}

/// Six blades image a far lamp as a hexagon with a vertex up, as LuxRender's aperture is: as
/// tall as the round bokeh's diameter, as wide as the hexagon's apothem across (both widened
/// by the lamp's own disk), measured on the image to within 2 pixels; the round aperture's
/// bokeh is as wide as it is tall.
#[test]
fn six_blades_image_a_far_lamp_as_a_hexagon() {
    let text = scene_text("bokeh.lxs");
    let (b, e) = bokeh_geometry();
    let (rows, columns) = lit_span(&render(&parse(&text), 1024, None));
    let (tall, wide) = (2.0 * (b + e), 2.0 * (b * libm::cos(PI / 6.0) + e));
    assert!(
        (f64::from(rows) - tall).abs() < 2.0 && (f64::from(columns) - wide).abs() < 2.0,
        "hexagon {rows} x {columns} pixels, want {tall:.1} x {wide:.1}"
    );
    let round = variant(&text, "\"integer blades\" [6]", "\"integer blades\" [0]");
    let (rows, columns) = lit_span(&render(&round, 1024, None));
    let diameter = 2.0 * (b + e);
    assert!(
        (f64::from(rows) - diameter).abs() < 2.0 && (f64::from(columns) - diameter).abs() < 2.0,
        "disk {rows} x {columns} pixels, want {diameter:.1} across"
    );
}

/// The light's second moment about the bokeh's centre, in squared pixels.
fn second_moment(film: &Film) -> f64 {
    let (mut sum, mut sx, mut sy, mut sxx) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for y in 0..film.height() {
        for x in 0..film.width() {
            let w = f64::from(film.pixel(x, y).dot(Vec3::ONE));
            let (px, py) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            sum += w;
            sx += w * px;
            sy += w * py;
            sxx += w * (px * px + py * py);
        }
    }
    let (cx, cy) = (sx / sum, sy / sum);
    sxx / sum - cx * cx - cy * cy
}

/// The distributions weigh the aperture as LuxRender's do: the bokeh's second moment is the
/// hexagon's, E[s] x mean(edge^2) x circumradius^2 with E[s] the distribution's mean squared
/// relative radius (1/2 uniform, (1 - e^-3)/3 exponential at power 3, and one less that
/// inverse) and mean(edge^2) = cos^2(pi/6) tan(pi/6) / (pi/6) the hexagon's, plus the lamp
/// disk's e^2/2 and the pixel's 1/6; each within 2% (measured: 0.3%).
#[test]
fn the_distribution_weighs_the_bokeh_as_luxrenders_does() {
    let text = scene_text("bokeh.lxs");
    let (b, e) = bokeh_geometry();
    let sixth = PI / 6.0;
    let edge_squared = libm::cos(sixth).powi(2) * libm::tan(sixth) / sixth;
    let exponential = (1.0 - libm::exp(-3.0)) / 3.0;
    for (distribution, mean_s) in [
        ("uniform", 0.5),
        ("exponential", exponential),
        ("inverse exponential", 1.0 - exponential),
    ] {
        let desc = variant(
            &text,
            "\"string distribution\" [\"uniform\"]",
            &format!("\"string distribution\" [\"{distribution}\"]"),
        );
        let got = second_moment(&render(&desc, 1024, None));
        let want = mean_s * edge_squared * b * b + e * e / 2.0 + 1.0 / 6.0;
        assert!(
            (got / want - 1.0).abs() < 0.02,
            "{distribution}: second moment {got:.1} px^2, want {want:.1}"
        );
    }
}

/// Autofocus focuses on what the ray through the screen centre meets: the glowing board 4
/// units ahead renders as sharp as the pinhole renders it, and a lens focused at 1.5 instead
/// blurs it. Measured on the bottom half (below the sphere), 2 x 2 block means.
#[test]
fn autofocus_focuses_on_what_the_screen_centre_sees() {
    let text = scene_text("autofocus.lxs");
    let board = |desc: &SceneDesc| {
        let film = render(desc, 64, None);
        let blocks = block_means(&film, 2);
        let per_row = (film.width() / 2) as usize;
        blocks[blocks.len() / 2 / per_row * per_row..].to_vec()
    };
    let pinhole = board(&variant(
        &text,
        "\"float lensradius\" [0.080000000000000]",
        "\"float lensradius\" [0]",
    ));
    let autofocus = board(&parse(&text));
    let near = board(&variant(
        &text,
        "\"bool autofocus\" [\"true\"]",
        "\"bool autofocus\" [\"false\"] \"float focaldistance\" [1.5]",
    ));
    let (sharp, blurred) = (
        correlation(&autofocus, &pinhole),
        correlation(&near, &pinhole),
    );
    assert!(
        sharp > 0.999 && blurred < 0.9,
        "correlation with the pinhole: autofocus {sharp}, focused at 1.5 {blurred}"
    );
}
