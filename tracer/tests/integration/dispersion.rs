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

use crate::render::{render_text, render_whole_with};
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

/// The predicted image of the prism's columns, of Cauchy's `index + cauchy_b_um2 / lambda^2`.
fn predicted(index: f64, cauchy_b_um2: f64) -> Vec<DVec3> {
    predicted_with(|um| index + cauchy_b_um2 / (um * um))
}

/// The predicted image of the prism's columns for the index `index(lambda in um)`: each
/// channel's radiance per column, averaged over 16 positions across the column.
fn predicted_with(index: impl Fn(f64) -> f64) -> Vec<DVec3> {
    let weights = spectrum_rgb_weights(1.0);
    (0..PRISM_COLUMNS)
        .map(|c| {
            let mut sum = DVec3::ZERO;
            for k in 0..16 {
                let x = world_x(f64::from(c) + (f64::from(k) + 0.5) / 16.0);
                for &(nm, w) in &weights {
                    sum += w.as_dvec3() * through_prism(x, index(nm * 1e-3));
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
    let overrides = RenderOverrides {
        spp: Some(spp),
        transport: Some(transport),
        ..Default::default()
    };
    render_text(text, &overrides)
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
    let (want_at, want_total) = moments(&predicted(INDEX, CAUCHY_B_UM2));
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
    let (want_at, _) = moments(&predicted(INDEX, 0.0));
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

/// The scene's glass prism as LuxRender's glass2, its index from its Interior: a clear volume
/// whose `fresnel` is a cauchy texture of the glass's figures (`cauchya` the glass's index),
/// with `material`'s parameters (`"bool dispersion" ["true"]` or none).
fn glass2_text(material: &str) -> String {
    let glass = "Material \"glass\" \"color Kr\" [0 0 0] \"color Kt\" [1 1 1] \"float index\" [1.5]\n    \"float cauchyb\" [0.02]";
    let text = scene_text();
    assert!(text.contains(glass), "the scene's glass");
    text.replace(
        "WorldBegin\n",
        &format!(
            "WorldBegin\nTexture \"bk\" \"fresnel\" \"cauchy\" \"float cauchya\" [{INDEX}] \
             \"float cauchyb\" [{CAUCHY_B_UM2}]\n\
             MakeNamedVolume \"prism\" \"clear\" \"texture fresnel\" \"bk\"\n"
        ),
    )
    .replace(
        glass,
        &format!("Material \"glass2\" {material}\n  Interior \"prism\""),
    )
}

/// The scene's glass, reflecting as glass2 does (Kr 1: glass2 has no Kr).
fn reflecting_glass_text() -> String {
    scene_text().replace("\"color Kr\" [0 0 0]", "\"color Kr\" [1 1 1]")
}

/// glass2 with `dispersion` between a cauchy volume and none takes one wavelength as glass
/// with cauchyb does: the prism renders exactly what the same prism of glass renders, path
/// traced and bidirectional, so its spectrum lies where Snell's law puts it (each channel's
/// centroid within half a column of the prediction).
#[test]
fn glass2_disperses_with_its_volumes_cauchy_index() {
    let (want_at, _) = moments(&predicted(INDEX, CAUCHY_B_UM2));
    for (transport, spp) in [(Transport::Path, 64), (Transport::Bidirectional, 32)] {
        let glass2 = render(
            &glass2_text("\"bool dispersion\" [\"true\"]"),
            spp,
            transport,
        );
        let glass = render(&reflecting_glass_text(), spp, transport);
        for y in 0..glass.height() {
            for x in 0..glass.width() {
                assert_eq!(
                    glass2.pixel(x, y),
                    glass.pixel(x, y),
                    "{transport:?} ({x}, {y})"
                );
            }
        }
        let (at, _) = moments(&measured(&glass2));
        eprintln!("{transport:?}: glass2 centroids {at}, predicted {want_at} (columns)");
        assert!(
            (at - want_at).abs().max_element() < 0.5,
            "{transport:?}: centroids {at}, predicted {want_at}"
        );
    }
}

/// Without `dispersion` glass2 refracts every wavelength at its volume's mean index (LuxRender's
/// cauchy texture's: cauchya + cauchyb / (0.38 x 0.72 um^2)): one centroid, where that index
/// puts it.
#[test]
fn glass2_without_dispersion_refracts_at_the_mean_index() {
    let mean = INDEX + CAUCHY_B_UM2 / (0.38 * 0.72);
    let (want_at, _) = moments(&predicted(mean, 0.0));
    let film = render(&glass2_text(""), 16, Transport::Path);
    let (at, _) = moments(&measured(&film));
    assert!(
        (at - want_at).abs().max_element() < 0.1 && (at.x - at.z).abs() < 0.05,
        "centroids {at}, predicted {want_at}"
    );
}

/// BK7's Sellmeier coefficients (C in um^2).
const BK7_B: [f64; 3] = [1.039_612_12, 0.231_792_344, 1.010_469_45];
const BK7_C: [f64; 3] = [0.006_000_698_67, 0.020_017_914_4, 103.560_653];

fn bk7(um: f64) -> f64 {
    let l2 = um * um;
    (1.0 + (0..3).map(|i| BK7_B[i] * l2 / (l2 - BK7_C[i])).sum::<f64>()).sqrt()
}

/// A cauchy index of Cauchy's A and B (um^2).
fn cauchy(a: f64, b: f64) -> impl Fn(f64) -> f64 {
    move |um| a + b / (um * um)
}

/// The prism of glass2 with `dispersion` between volumes of other dispersive fresnel textures:
/// BK7 by Sellmeier's formula (exact); the glass's Cauchy index tabulated in a luxpop file
/// every 20 nm (interpolated between its samples); the glass's Cauchy index inside a dispersive
/// gas's Cauchy exterior (the ratio of the two, tabulated every 20 nm). Each spectrum lies where
/// Snell's law at its relative index puts it: every channel's centroid within half a column of
/// the prediction, the spread from red to blue within 5% of it.
#[test]
fn glass2_disperses_with_sellmeier_tabulated_and_two_dispersive_volumes() {
    let list = |v: [f64; 3]| v.map(|x| x.to_string()).join(" ");
    let sellmeier = format!(
        "Texture \"bk\" \"fresnel\" \"sellmeier\" \"float B\" [{}] \"float C\" [{}]",
        list(BK7_B),
        list(BK7_C)
    );
    // Wavelengths in angstroms, 360 to 800 nm every 20.
    let luxpop: String = (0..=22)
        .map(|i| {
            let nm = 360.0 + 20.0 * f64::from(i);
            let um = nm * 1e-3;
            format!("{} {:.7} 0\n", nm * 10.0, INDEX + CAUCHY_B_UM2 / (um * um))
        })
        .collect();
    let table = |um: f64| {
        // The file's samples, interpolated linearly.
        let nm = um * 1e3;
        let below = 360.0 + 20.0 * ((nm - 360.0) / 20.0).floor();
        let n = |nm: f64| INDEX + CAUCHY_B_UM2 / (nm * nm * 1e-6);
        let t = (nm - below) / 20.0;
        n(below) * (1.0 - t) + n(below + 20.0) * t
    };
    let gas = cauchy(1.02, 0.002);
    let glass = cauchy(INDEX, CAUCHY_B_UM2);
    /// A relative index of refraction over wavelength (micrometres).
    type Index = Box<dyn Fn(f64) -> f64>;
    let cases: [(&str, String, &str, Index); 3] = [
        ("sellmeier", sellmeier, "", Box::new(bk7)),
        (
            "luxpop",
            "Texture \"bk\" \"fresnel\" \"luxpop\" \"string filename\" \"glass.nk\"".into(),
            "",
            Box::new(table),
        ),
        (
            "two cauchy volumes",
            format!(
                "Texture \"bk\" \"fresnel\" \"cauchy\" \"float cauchya\" [{INDEX}] \
                 \"float cauchyb\" [{CAUCHY_B_UM2}]\n\
                 Texture \"gas\" \"fresnel\" \"cauchy\" \"float cauchya\" [1.02] \
                 \"float cauchyb\" [0.002]\n\
                 MakeNamedVolume \"gas\" \"clear\" \"texture fresnel\" \"gas\""
            ),
            "  Exterior \"gas\"\n",
            Box::new(move |um| glass(um) / gas(um)),
        ),
    ];
    for (name, texture, exterior, index) in cases {
        let text = glass2_text("\"bool dispersion\" [\"true\"]");
        let (head, tail) = text.split_at(text.find("Texture \"bk\"").expect("the texture"));
        let tail = &tail[tail.find('\n').expect("one line") + 1..];
        let text = format!("{head}{texture}\n{tail}").replace(
            "  Interior \"prism\"\n",
            &format!("  Interior \"prism\"\n{exterior}"),
        );
        let mut source = MemorySource::new();
        source.insert("dispersion.lxs", Arc::from(text.as_bytes()));
        source.insert("glass.nk", Arc::from(luxpop.as_bytes()));
        let desc = parse_scene("dispersion.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
        assert!(desc.warnings.is_empty(), "{name}: {:?}", desc.warnings);
        let overrides = RenderOverrides {
            spp: Some(64),
            transport: Some(Transport::Path),
            ..Default::default()
        };
        let film = render_whole_with(&desc, &source, &overrides);
        let (want_at, _) = moments(&predicted_with(&*index));
        let (at, _) = moments(&measured(&film));
        let spread = (at.x - at.z, want_at.x - want_at.z);
        eprintln!("{name}: centroids {at}, predicted {want_at} (columns)");
        assert!(
            (at - want_at).abs().max_element() < 0.5 && (spread.0 / spread.1 - 1.0).abs() < 0.05,
            "{name}: centroids {at}, predicted {want_at}"
        );
    }
}

/// The dispersive fresnel textures read as LuxRender's: abbe's curve has index n at its
/// lambda_D and Abbe number V over lambda_F and lambda_C (BK7's defaults and the e lines);
/// cauchy's `index` is its mean over 380-720 nm; sellmeier's B and C go in pairs (else the
/// texture is undefined, with a warning); glass2's index without dispersion is the mean.
#[test]
fn dispersive_fresnel_textures_read_as_luxrender_reads_them() {
    use yat_tracer::wavelength::IndexCurve;
    let volumes = |textures: &str| {
        let text = format!(
            "Camera \"perspective\"\nWorldBegin\n{textures}\nMakeNamedVolume \"v\" \"clear\" \"texture fresnel\" \"t\"\n\
             Material \"glass2\" \"bool dispersion\" [\"true\"]\nInterior \"v\"\n\
             Shape \"sphere\"\nWorldEnd\n"
        );
        let mut source = MemorySource::new();
        source.insert("s.lxs", Arc::from(text.as_bytes()));
        parse_scene("s.lxs", &source).unwrap_or_else(|e| panic!("{e}"))
    };
    let curve = |textures: &str| -> IndexCurve {
        let desc = volumes(textures);
        assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
        desc.volumes.media[0]
            .dispersion()
            .expect("a dispersive index")
            .clone()
    };
    for (ty, lines, n, v) in [
        ("", [587.5618f32, 486.13, 656.28], 1.5168f32, 64.17f32),
        (
            "\"string type\" \"e\" \"float n\" [1.7] \"float V\" [30]",
            [546.07, 479.99, 643.85],
            1.7,
            30.0,
        ),
    ] {
        let c = curve(&format!("Texture \"t\" \"fresnel\" \"abbe\" {ty}"));
        let [d, f, cl] = lines;
        let abbe = (c.at(d) - 1.0) / (c.at(f) - c.at(cl));
        assert!(
            (c.at(d) - n).abs() < 1e-5 && (abbe / v - 1.0).abs() < 1e-3,
            "{ty}: n {} V {abbe}",
            c.at(d)
        );
    }
    let c = curve(
        "Texture \"t\" \"fresnel\" \"cauchy\" \"float index\" [1.6] \"float cauchyb\" [0.01]",
    );
    let mean: f64 = (380..720).map(|nm| f64::from(c.at(nm as f32))).sum::<f64>() / 340.0;
    assert!(
        (c.mean() - 1.6).abs() < 1e-6 && (mean - 1.6).abs() < 1e-4,
        "{c:?}"
    );
    let desc =
        volumes("Texture \"t\" \"fresnel\" \"sellmeier\" \"float B\" [1 0.2] \"float C\" [0.006]");
    assert!(
        desc.warnings
            .iter()
            .any(|w| w.message.contains("2 B and 1 C")),
        "{:?}",
        desc.warnings
    );
}
