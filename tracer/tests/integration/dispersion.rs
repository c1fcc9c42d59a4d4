//! Dispersion on the exporter-written `scenes/exported/dispersion.lxs`: a glass prism with
//! Cauchy's B seen against a narrow white light bar through an orthographic camera. Each
//! wavelength's rays refract by Snell's law at `index + cauchyb / lambda^2`, so the columns that
//! see the bar through the prism are predicted per wavelength in closed form (a 2D trace: the
//! prism's faces are vertical); each channel's image is the spectrum's RGB weights over those
//! columns, times the faces' Fresnel transmission.

use std::sync::Arc;

use glam::{DVec2, DVec3, Vec3};
use yat_tracer::assets::MemorySource;
use yat_tracer::bxdf::fresnel;
use yat_tracer::film::Film;
use yat_tracer::integrator::Transport;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::RenderOverrides;
use yat_tracer::spectra::spectrum_rgb_weights;

use crate::render::render_whole_with;
use crate::util::workspace_root;

/// The scene's figures (see the file).
const INDEX: f64 = 1.5;
const CAUCHY_B_UM2: f64 = 0.02;
/// The prism's cross-section in (x, z): its base on x = 0, its apex at x = 1.1.
const PRISM: [DVec2; 3] = [
    DVec2::new(0.0, -0.4),
    DVec2::new(1.1, 0.0),
    DVec2::new(0.0, 0.4),
];
const BAR_X: f64 = -0.85;
const BAR_HALF_WIDTH: f64 = 0.01;
const BAR_Z: f64 = 3.0;
const CAMERA_Z: f64 = -5.0;
/// The screen window's x range and the film's columns.
const SCREEN: (f64, f64) = (-1.1, 1.1);
const COLUMNS: u32 = 440;
/// Columns right of this one look through the prism; the others see the bar directly.
const PRISM_COLUMNS: u32 = 240;

fn refract(d: DVec2, n: DVec2, eta: f64) -> Option<DVec2> {
    let cos = -d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos * cos);
    (k >= 0.0).then(|| eta * d + (eta * cos - k.sqrt()) * n)
}

/// Where the ray from `o` along `d` crosses the segment `a`-`b`, if it does.
fn cross(o: DVec2, d: DVec2, a: DVec2, b: DVec2) -> Option<DVec2> {
    let e = b - a;
    let den = d.perp_dot(e);
    if den.abs() < 1e-12 {
        return None;
    }
    let r = a - o;
    let t = r.perp_dot(e) / den;
    let s = r.perp_dot(d) / den;
    (t > 1e-9 && (0.0..=1.0).contains(&s)).then(|| o + t * d)
}

/// The outward unit normal of the prism's edge `a`-`b` (the corners of [`PRISM`] run
/// counter-clockwise in (x, z)).
fn outward(a: DVec2, b: DVec2) -> DVec2 {
    let e = (b - a).normalize();
    DVec2::new(e.y, -e.x)
}

/// The camera ray at `x` through the prism at index `n`: its share transmitted (the two faces'
/// Fresnel transmission) if it reaches the bar, else 0.
fn through_prism(x: f64, n: f64) -> f64 {
    let [p1, p3, p2] = PRISM;
    let d = DVec2::new(0.0, 1.0);
    let Some(entry) = cross(DVec2::new(x, CAMERA_Z), d, p1, p3) else {
        return 0.0;
    };
    let n1 = outward(p1, p3);
    let Some(inside) = refract(d, n1, 1.0 / n) else {
        return 0.0;
    };
    let Some(exit) = cross(entry, inside, p3, p2) else {
        return 0.0;
    };
    let n2 = outward(p3, p2);
    let Some(out) = refract(inside, -n2, n) else {
        return 0.0;
    };
    let land = exit.x + (BAR_Z - exit.y) / out.y * out.x;
    if (land - BAR_X).abs() > BAR_HALF_WIDTH {
        return 0.0;
    }
    let t1 = 1.0 - f64::from(fresnel::dielectric(-d.dot(n1) as f32, n as f32));
    let t2 = 1.0 - f64::from(fresnel::dielectric(inside.dot(n2) as f32, (1.0 / n) as f32));
    t1 * t2
}

/// The world x a film column's centre looks along: LuxRender's raster x runs against the
/// world's x for a camera looking down +z with y up.
fn world_x(column: f64) -> f64 {
    SCREEN.1 - column / f64::from(COLUMNS) * (SCREEN.1 - SCREEN.0)
}

/// The predicted image of the prism's columns: each channel's radiance per column, averaged
/// over 16 positions across the column.
fn predicted(cauchy_b_um2: f64) -> Vec<DVec3> {
    let weights = spectrum_rgb_weights(1.0);
    (0..PRISM_COLUMNS)
        .map(|c| {
            let mut sum = DVec3::ZERO;
            for k in 0..16 {
                let x = world_x(f64::from(c) + (f64::from(k) + 0.5) / 16.0);
                for &(nm, w) in &weights {
                    let um = nm * 1e-3;
                    sum += w.as_dvec3() * through_prism(x, INDEX + cauchy_b_um2 / (um * um));
                }
            }
            sum / 16.0
        })
        .collect()
}

/// Each channel's column profile of `film` (rows averaged), the prism's columns only.
fn measured(film: &Film) -> Vec<DVec3> {
    (0..PRISM_COLUMNS)
        .map(|x| {
            let sum: Vec3 = (0..film.height()).map(|y| film.pixel(x, y)).sum();
            (sum / film.height() as f32).as_dvec3()
        })
        .collect()
}

/// Each channel's centroid (in columns) and total.
fn moments(profile: &[DVec3]) -> (DVec3, DVec3) {
    let total: DVec3 = profile.iter().copied().sum();
    let first: DVec3 = profile
        .iter()
        .enumerate()
        .map(|(c, &v)| v * (c as f64 + 0.5))
        .sum();
    (first / total, total)
}

fn render(text: &str, spp: u32, transport: Transport) -> Film {
    let mut source = MemorySource::new();
    source.insert("dispersion.lxs", Arc::from(text.as_bytes()));
    let desc = parse_scene("dispersion.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let overrides = RenderOverrides {
        spp: Some(spp),
        transport: Some(transport),
        ..Default::default()
    };
    render_whole_with(&desc, &source, &overrides)
}

fn scene_text() -> String {
    let path = workspace_root().join("scenes/exported/dispersion.lxs");
    std::fs::read_to_string(&path).expect("scenes/exported/dispersion.lxs")
}

/// Through the prism the bar is a spectrum where Snell's law at Cauchy's indices puts it: each
/// channel's centroid within half a column of the prediction, the spread from red to blue
/// within 3% of it, and each channel's light within 3%; seen directly, the bar is white and
/// where it stands. Path tracing and bidirectional transport alike.
#[test]
fn a_prism_spreads_the_spectrum_where_snell_puts_each_wavelength() {
    let text = scene_text();
    let (want_at, want_total) = moments(&predicted(CAUCHY_B_UM2));
    // Blue is bent the most: toward the apex, the low columns.
    assert!(want_at.z + 10.0 < want_at.x, "{want_at}");
    for (transport, spp) in [(Transport::Path, 64), (Transport::Bidirectional, 32)] {
        let film = render(&text, spp, transport);
        let (got_at, got_total) = moments(&measured(&film));
        let spread = (got_at.x - got_at.z, want_at.x - want_at.z);
        eprintln!("{transport:?}: centroids {got_at}, predicted {want_at} (columns)");
        assert!(
            (got_at - want_at).abs().max_element() < 0.5
                && (spread.0 / spread.1 - 1.0).abs() < 0.03,
            "{transport:?}: centroids {got_at} (columns), predicted {want_at}"
        );
        // The bar seen directly: at its column, in every channel alike.
        let direct: Vec<DVec3> = (PRISM_COLUMNS..COLUMNS)
            .map(|x| film.pixel(x, 0).as_dvec3())
            .collect();
        let (at, direct_total) = moments(&direct);
        let bar_column = (SCREEN.1 - BAR_X) / (SCREEN.1 - SCREEN.0) * f64::from(COLUMNS);
        let at = at + DVec3::splat(f64::from(PRISM_COLUMNS));
        assert!(
            (at - DVec3::splat(bar_column)).abs().max_element() < 0.1,
            "{transport:?}: bar at {at}, placed at column {bar_column}"
        );
        assert!(
            (direct_total / direct_total.x - DVec3::ONE)
                .abs()
                .max_element()
                < 1e-3,
            "{direct_total}"
        );
        // The light through the prism over the light seen directly (the bar's width in
        // columns at radiance 1: the prediction's unit).
        let bar_columns = 2.0 * BAR_HALF_WIDTH / (SCREEN.1 - SCREEN.0) * f64::from(COLUMNS);
        let ratio = (got_total / direct_total) / (want_total / bar_columns);
        assert!(
            (ratio - DVec3::ONE).abs().max_element() < 0.03,
            "{transport:?}: light through the prism {got_total}, directly {direct_total}, \
             predicted {want_total} of {bar_columns}"
        );
    }
}

/// Without Cauchy's B the prism bends every channel alike: one centroid.
#[test]
fn without_cauchyb_the_channels_stay_together() {
    let text = scene_text().replace("\"float cauchyb\" [0.02]", "");
    let (want_at, _) = moments(&predicted(0.0));
    let film = render(&text, 16, Transport::Path);
    let (got_at, _) = moments(&measured(&film));
    assert!(
        (got_at - want_at).abs().max_element() < 0.1 && (got_at.x - got_at.z).abs() < 0.05,
        "centroids {got_at}, predicted {want_at}"
    );
}

/// A dispersive glass under a uniform white sky stays white on average (its wavelength weights
/// average to white), though each sample is coloured: reflecting and refracting glass of Kr =
/// Kt = 1 passes all the sky's light, so every pixel's mean is 1 in every channel.
#[test]
fn dispersive_glass_in_white_light_stays_white() {
    let text = scene_text()
        .replace("\"color Kr\" [0 0 0]", "\"color Kr\" [1 1 1]")
        .replace(
            "WorldBegin\n",
            "WorldBegin\nLightSource \"infinite\" \"color L\" [1 1 1]\n",
        );
    let bar = text.rfind("AttributeBegin").expect("the bar's block");
    let text = &text[..bar];
    let film = render(text, 64, Transport::Path);
    let pixels: Vec<DVec3> = (0..PRISM_COLUMNS)
        .flat_map(|x| (0..film.height()).map(move |y| (x, y)))
        .map(|(x, y)| film.pixel(x, y).as_dvec3())
        .collect();
    let mean = pixels.iter().copied().sum::<DVec3>() / pixels.len() as f64;
    assert!(
        (mean - DVec3::ONE).abs().max_element() < 0.01,
        "mean {mean}"
    );
    // Each sample carries one wavelength's colour: the pixels through the prism are not grey.
    let chroma = pixels.iter().map(|p| (p.x - p.z).abs()).fold(0.0, f64::max);
    assert!(chroma > 0.05, "largest red-blue difference {chroma}");
}
