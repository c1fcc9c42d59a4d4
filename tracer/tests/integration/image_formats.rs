//! Image textures in the formats LuxBlend writes besides PNG and JPEG (TGA, TIFF, BMP): counted
//! against the build budget from their headers at parse time (TGA found by its extension, as
//! it has no magic number), refused with the file's name when broken, and rendered by the
//! scene `scenes/textures/formats.lxs`.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::Vec3;
use yat_tracer::assets::{AssetKind, FsSource, MemorySource};
use yat_tracer::budget::{BuildBudget, BuildGuard, Limit};
use yat_tracer::desc::SceneDesc;
use yat_tracer::diag::Severity;
use yat_tracer::image_io::ImageCost;
use yat_tracer::parse::{parse_scene, parse_scene_guarded, ParseError};

use crate::hostile;
use crate::render::render_whole;
use crate::util::workspace_root;

fn encoded(img: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, format).unwrap();
    bytes.into_inner()
}

/// A `width` x `height` 8-bit RGB picture of many colours.
fn picture(width: u32, height: u32) -> image::DynamicImage {
    image::RgbImage::from_fn(width, height, |x, y| {
        image::Rgb([(x * 4) as u8, (y * 8) as u8, ((x + y) * 3) as u8])
    })
    .into()
}

/// A scene whose Kd textures are imagemaps of `files` (name and bytes), one sphere each; the
/// Texture statements are on lines 6, 9, 12, ... of main.lxs.
fn textured_scene(files: &[(&str, Vec<u8>)]) -> MemorySource {
    let body: String = files
        .iter()
        .enumerate()
        .map(|(i, (name, _))| {
            format!(
                "Texture \"t{i}\" \"color\" \"imagemap\" \"string filename\" [\"{name}\"] \
                 \"float gamma\" [2.2]\nMaterial \"matte\" \"texture Kd\" \"t{i}\"\n\
                 Shape \"sphere\"\n"
            )
        })
        .collect();
    let mut source = MemorySource::new();
    source.insert("main.lxs", Arc::from(hostile::scene(&body).as_bytes()));
    for (name, bytes) in files {
        source.insert(*name, Arc::from(bytes.as_slice()));
    }
    source
}

fn parse(source: &MemorySource) -> Result<SceneDesc, ParseError> {
    parse_scene("main.lxs", source)
}

/// The parser reads each file's header (the TGA's by its extension) and counts its texels
/// before anything decodes: exactly width x height per file, and one texel over a limit of
/// their sum is refused at the last file's Texture statement.
#[test]
fn tga_tiff_and_bmp_textures_count_their_header_texels_against_the_budget() {
    let tga = encoded(picture(64, 32), image::ImageFormat::Tga);
    assert!(
        image::guess_format(&tga).is_err(),
        "TGA has no magic number"
    );
    let files = [
        ("maps/wood.TGA", tga),
        (
            "maps/stone.tif",
            encoded(picture(16, 8), image::ImageFormat::Tiff),
        ),
        (
            "maps/paint.bmp",
            encoded(picture(5, 3), image::ImageFormat::Bmp),
        ),
    ];
    let texels = 64 * 32 + 16 * 8 + 5 * 3;
    let source = textured_scene(&files);
    let desc = parse(&source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    assert_eq!(desc.spent.spent(Limit::Texels), texels);
    let images: Vec<&str> = desc
        .assets
        .iter()
        .filter(|a| a.kind == AssetKind::Image)
        .map(|a| a.path.as_str())
        .collect();
    assert_eq!(images, files.map(|(name, _)| name));

    let budget = BuildBudget {
        max_texels: texels - 1,
        ..BuildBudget::DEFAULT
    };
    let guard = BuildGuard {
        budget: &budget,
        ..BuildGuard::default()
    };
    match parse_scene_guarded("main.lxs", &source, guard) {
        Err(ParseError::OverBudget { exceeded, pos }) => {
            assert_eq!(exceeded.limit, Limit::Texels);
            assert_eq!(exceeded.reached, texels);
            assert!(pos.to_string().starts_with("main.lxs:12:"), "{pos}");
        }
        other => panic!("expected the texel limit, got {:?}", other.map(|_| ())),
    }
}

/// A TGA texture's memory is counted from its header as a PNG's is: the scene's estimate
/// gains [`ImageCost::decode`] of its size and colour type and the file's bytes, which the
/// build holds, and no more.
#[test]
fn a_tga_texture_costs_what_its_header_says() {
    let with = |name: &str, img: image::DynamicImage, format| {
        let bytes = encoded(img, format);
        let length = bytes.len() as u64;
        let desc = parse(&textured_scene(&[(name, bytes)])).unwrap();
        desc.spent.spent(Limit::MemoryBytes) - length
    };
    let mut plain = MemorySource::new();
    // The same scene but for the texture, and as long (a comment in the Texture's place).
    let textured = hostile::scene(
        "Texture \"t0\" \"color\" \"imagemap\" \"string filename\" [\"wood.tga\"] \
         \"float gamma\" [2.2]\nMaterial \"matte\" \"texture Kd\" \"t0\"\nShape \"sphere\"\n",
    );
    let body = "Material \"matte\"\nShape \"sphere\"\n";
    let padding = textured.len() - hostile::scene(body).len() - 2;
    let body = format!("#{}\n{body}", "x".repeat(padding));
    assert_eq!(hostile::scene(&body).len(), textured.len());
    plain.insert("main.lxs", Arc::from(hostile::scene(&body).as_bytes()));
    let without = parse(&plain).unwrap().spent.spent(Limit::MemoryBytes);
    let rgba = image::RgbaImage::from_pixel(64, 32, image::Rgba([1, 2, 3, 4])).into();
    for (img, color) in [
        (picture(64, 32), image::ColorType::Rgb8),
        (rgba, image::ColorType::Rgba8),
    ] {
        let cost = ImageCost::decode(64, 32, color);
        let tga = with("wood.tga", img.clone(), image::ImageFormat::Tga);
        assert_eq!(tga - without, cost.kept + cost.transient, "{color:?}");
        let png = with("wood.png", img, image::ImageFormat::Png);
        assert_eq!(tga, png, "{color:?}");
    }
}

/// A TGA header claiming 60 000 x 60 000 texels (18 bytes, no texel) is refused at the texel
/// limit from its header, quickly: nothing is decoded.
#[test]
fn a_tga_header_claiming_billions_of_texels_is_refused_before_decoding() {
    #[rustfmt::skip]
    let header = vec![
        0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x60, 0xea, 0x60, 0xea, 24, 0x20,
    ];
    let source = textured_scene(&[("huge.tga", header)]);
    let started = Instant::now();
    match parse(&source) {
        Err(ParseError::OverBudget { exceeded, pos }) => {
            assert_eq!(exceeded.limit, Limit::Texels);
            assert_eq!(exceeded.reached, 60_000 * 60_000);
            assert!(pos.to_string().starts_with("main.lxs:6:"), "{pos}");
        }
        other => panic!("expected the texel limit, got {:?}", other.map(|_| ())),
    }
    assert!(started.elapsed() < Duration::from_secs(10));
}

/// Garbage in a `.tga` file is an image error naming the file and the statement, not a panic.
#[test]
fn a_garbage_tga_texture_is_an_error_naming_the_file() {
    for bytes in [
        &b"GIF? no, garbage"[..],
        &[0x00, 0x07, 0x0b, 0xff, 0x13][..],
    ] {
        let source = textured_scene(&[("maps/broken.tga", bytes.to_vec())]);
        let err = parse(&source).unwrap_err();
        match &err {
            ParseError::Image { path, pos, .. } => {
                assert_eq!(path, "maps/broken.tga");
                assert!(pos.to_string().starts_with("main.lxs:6:"), "{pos}");
            }
            other => panic!("expected an image error, got {other}"),
        }
        assert!(err.to_string().contains("\"maps/broken.tga\""), "{err}");
    }
}

/// The colours of the quadrants of the picture of `scenes/textures/formats.lxs` (top left,
/// top right, bottom left, bottom right), as tracer/examples/make_scene_assets.rs writes them.
const QUADRANTS: [[u8; 3]; 4] = [[200, 40, 40], [40, 180, 60], [40, 60, 200], [220, 200, 60]];

/// `scenes/textures/formats.lxs`: three matte quads under a uniform white sky, textured by
/// formats.tga, .tif and .bmp (the same picture). A plane under a uniform sky of radiance 1
/// and nothing else reflects its albedo exactly, so the middle of each quadrant of each quad
/// renders as that quadrant's colour through the gamma curve, the right way up.
#[test]
fn the_formats_scene_shows_each_picture_upright_at_its_albedo() {
    let path = workspace_root().join("scenes/textures/formats.lxs");
    let source = FsSource::for_main_file(Path::new(&path));
    let desc = parse_scene("formats.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    // Nothing but the exporter's mip-map settings, which bilinear filtering (LuxRender's
    // default, and YAT's) does not use.
    assert!(
        desc.warnings
            .iter()
            .all(|w| w.severity == Severity::NoEffect),
        "{:?}",
        desc.warnings
    );
    let images: Vec<&str> = desc.assets.iter().map(|a| a.path.as_str()).collect();
    assert_eq!(images, ["formats.tga", "formats.tif", "formats.bmp"]);
    assert_eq!(desc.spent.spent(Limit::Texels), 3 * 64 * 64);

    let (w, h) = (240u32, 90u32);
    let film = render_whole(&desc, &source, 16, Some((w, h)));
    // World (x, y) on the quads' plane z = 0 to pixels: the camera at z = 10 sees
    // y in +-10 tan(8 degrees) over the film's height, x over its width.
    let half_height = 10.0 * libm::tanf(8f32.to_radians());
    let pixel = |x: f32, y: f32| {
        let aspect = w as f32 / h as f32;
        let px = (x / (half_height * aspect) + 1.0) * 0.5 * w as f32;
        let py = (1.0 - y / half_height) * 0.5 * h as f32;
        (px, py)
    };
    // The mean over the pixels within 0.25 world units of (x, y).
    let mean = |x: f32, y: f32| {
        let (x0, y0) = pixel(x - 0.25, y + 0.25);
        let (x1, y1) = pixel(x + 0.25, y - 0.25);
        let (mut sum, mut n) = (Vec3::ZERO, 0);
        for py in y0.ceil() as u32..y1.floor() as u32 {
            for px in x0.ceil() as u32..x1.floor() as u32 {
                sum += film.pixel(px, py);
                n += 1;
            }
        }
        assert!(n >= 60, "{n} pixels around ({x}, {y})");
        sum / n as f32
    };
    // The sky above the quads (their tops are at y = 1, 14 rows from the top).
    let sky = (0..6)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .fold(Vec3::ZERO, |sum, (px, py)| sum + film.pixel(px, py))
        / (6 * w) as f32;
    assert!(sky.abs_diff_eq(Vec3::ONE, 1e-4), "sky {sky}");
    let mut worst = 0.0f32;
    for (quad, centre) in [(0, -2.4f32), (1, 0.0), (2, 2.4)] {
        let corners = [(-0.5, 0.5), (0.5, 0.5), (-0.5, -0.5), (0.5, -0.5)];
        for (colour, (dx, dy)) in QUADRANTS.iter().zip(corners) {
            let want = Vec3::from_array(colour.map(|v| libm::powf(f32::from(v) / 255.0, 2.2)));
            let got = mean(centre + dx, dy);
            let error = ((got - want) / want).abs().max_element();
            worst = worst.max(error);
            assert!(
                error < 0.01,
                "quad {quad} ({}), quadrant ({dx}, {dy}): {got} against {want}",
                images[quad]
            );
        }
    }
    println!("largest relative error of a quadrant's mean: {worst:.5}");
}
