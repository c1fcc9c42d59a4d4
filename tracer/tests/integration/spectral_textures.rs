//! The spectral textures read as colours: `lampspectrum` (named lamps) and `tabulateddata` /
//! `irregulardata` (spectra from a file or inline), checked through a point light's colour.

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::desc::*;
use yat_tracer::lights::PointLight;
use yat_tracer::math::luminance;
use yat_tracer::parse::{blackbody_rgb, parse_scene};

/// The colours of point lights coloured by `textures` (one light per texture name), and the
/// scene's warnings.
fn light_colours(textures: &str, names: &[&str], files: &[(&str, &str)]) -> (Vec<Vec3>, String) {
    let mut source = MemorySource::new();
    for (path, text) in files {
        source.insert(*path, text.as_bytes().into());
    }
    let lights: String = names
        .iter()
        .map(|n| format!("LightSource \"point\" \"texture L\" \"{n}\"\n"))
        .collect();
    source.insert(
        "main.lxs",
        format!("Camera \"perspective\"\nWorldBegin\n{textures}{lights}WorldEnd\n")
            .as_bytes()
            .into(),
    );
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    let colours = desc
        .lights
        .iter()
        .map(|l| match l {
            LightDesc::Point(PointLight { intensity, .. }) => *intensity,
            other => panic!("{other:?}"),
        })
        .collect();
    let warnings = desc
        .warnings
        .iter()
        .map(|w| w.to_string())
        .collect::<Vec<_>>()
        .join("\n");
    (colours, warnings)
}

/// r / (r + g + b).
fn red_share(c: Vec3) -> f32 {
    c.x / c.element_sum()
}

#[test]
fn sodium_lamps_are_orange_and_daylight_is_white() {
    let (c, warnings) = light_colours(
        "Texture \"lps\" \"color\" \"lampspectrum\" \"string name\" \"LPS\"\n\
         Texture \"hps\" \"color\" \"lampspectrum\" \"string name\" \"HPS\"\n\
         Texture \"day\" \"color\" \"lampspectrum\" \"string name\" \"Daylight\"\n\
         Texture \"inc\" \"color\" \"lampspectrum\"\n\
         Texture \"bad\" \"color\" \"lampspectrum\" \"string name\" \"Sodium9000\"\n",
        &["lps", "hps", "day", "inc", "bad"],
        &[],
    );
    let (lps, hps, day, inc, bad) = (c[0], c[1], c[2], c[3], c[4]);
    // Independent computation: the sodium D line (589 nm) has CIE 1931 chromaticity
    // x = 0.5752, y = 0.4242 (the spectral locus); in linear sRGB, clipped to the gamut and
    // scaled to luminance 1, that is about (2.83, 0.56, 0).
    let (x, y) = (0.5752f32, 0.4242f32);
    let xyz = Vec3::new(x / y, 1.0, (1.0 - x - y) / y);
    let d_line = Vec3::new(
        3.2406 * xyz.x - 1.5372 * xyz.y - 0.4986 * xyz.z,
        -0.9689 * xyz.x + 1.8758 * xyz.y + 0.0415 * xyz.z,
        0.0557 * xyz.x - 0.2040 * xyz.y + 1.0570 * xyz.z,
    )
    .max(Vec3::ZERO);
    let d_line = d_line / luminance(d_line);
    println!("LPS {lps}, D line {d_line}, HPS {hps}, Daylight {day}");
    assert!(lps.x > 3.0 * lps.y && lps.y > 0.3 && lps.z < 0.05, "{lps}");
    assert!(
        (red_share(lps) - red_share(d_line)).abs() < 0.05,
        "LPS {lps} against the D line {d_line}"
    );
    // High-pressure sodium is broader: still orange, less saturated.
    assert!(hps.x > 1.5 * hps.y && hps.y > hps.z && hps.z > 0.2, "{hps}");
    assert!(red_share(hps) < red_share(lps), "{hps} {lps}");
    // A hue sets no brightness: every lamp has luminance 1.
    for c in [lps, hps, day] {
        assert!((luminance(c) - 1.0).abs() < 2e-3, "{c}");
    }
    assert!(day.max_element() / day.min_element() < 1.3, "{day}");
    // The default and an unknown name are LuxRender's Incandescent2: a 2900 K blackbody.
    assert!(
        (inc - blackbody_rgb(2900.0)).abs().max_element() < 1e-6,
        "{inc}"
    );
    assert_eq!(bad, inc);
    assert!(warnings.contains("Sodium9000"), "{warnings}");
}

#[test]
fn tabulated_spectra_from_files_and_inline() {
    let flat: String = (0..=40)
        .map(|i| format!("{} 0.6\n", 380 + 10 * i))
        .collect();
    // A step at 600 nm written in micrometres, decreasing, with a header and a comment.
    let step = "# measured somewhere\nwavelength: um data: T\n0.80; 1\n0.601, 1\n0.599 0\n0.38 0\nend\n0.5 7\n";
    let (c, warnings) = light_colours(
        "Texture \"flat\" \"color\" \"tabulateddata\" \"string filename\" \"flat.txt\"\n\
         Texture \"step\" \"color\" \"tabulateddata\" \"string filename\" \"data/step.txt\"\n\
         Texture \"inline\" \"color\" \"irregulardata\" \"float wavelengths\" [380 780] \"float data\" [0.25 0.25]\n\
         Texture \"short\" \"color\" \"tabulateddata\" \"string filename\" \"short.txt\"\n",
        &["flat", "step", "inline", "short"],
        &[
            ("flat.txt", flat.as_str()),
            ("data/step.txt", step),
            ("short.txt", "500 1\n"),
        ],
    );
    println!("flat {} step {} inline {} short {}", c[0], c[1], c[2], c[3]);
    for (v, expected) in [(c[0], 0.6), (c[2], 0.25)] {
        assert!(
            (v - Vec3::splat(expected)).abs().max_element() < 0.01 * expected,
            "{v} against grey {expected}"
        );
    }
    // Only long wavelengths pass: red, little green, no blue.
    let step = c[1];
    assert!(
        step.x > 0.8 && step.y < 0.5 && step.z < 0.05 && step.min_element() >= 0.0,
        "{step}"
    );
    // One sample is too few: a flat spectrum of 1, with a warning naming the file.
    assert_eq!(c[3], Vec3::ONE);
    assert!(warnings.contains("short.txt"), "{warnings}");
}

#[test]
fn an_unreadable_spectrum_file_is_an_error_naming_it() {
    let mut source = MemorySource::new();
    source.insert(
        "main.lxs",
        b"WorldBegin\nTexture \"t\" \"color\" \"tabulateddata\" \"string filename\" \"spectra/missing.spd\"\nWorldEnd\n".as_slice().into(),
    );
    let e = parse_scene("main.lxs", &source).expect_err("a missing file");
    let message = e.to_string();
    assert!(
        message.contains("spectra/missing.spd") && message.contains("main.lxs:2"),
        "{message}"
    );
}
