//! Generates the binary assets of the project's own scenes (`scenes/`): the LatLong sky
//! (`scenes/envmap/sky.hdr` and `sky.png`), the picture of the image-format scene in the three
//! formats LuxBlend writes besides PNG and JPEG (`scenes/textures/formats.tga`, `.tif` and
//! `.bmp`) and the heavy scene's mesh (`scenes/heavy/heavy.ply`, about 2 M triangles, not
//! committed).
//!
//! `cargo run --release -p yat-tracer --example make_scene_assets [-- SCENES_DIR]`

use std::f32::consts::PI;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use glam::Vec3;

const SKY_WIDTH: u32 = 512;
const SKY_HEIGHT: u32 = 256;
/// Rows x columns of the rock's vertex grid: 2 x 1000 x 1000 triangles.
const ROCK_RESOLUTION: u32 = 1000;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes"));
    write_sky(&dir.join("envmap"))?;
    write_formats(&dir.join("textures"))?;
    write_rock(&dir.join("heavy/heavy.ply"))?;
    Ok(())
}

fn sun_direction() -> Vec3 {
    Vec3::new(-0.5, -0.6, 0.6).normalize()
}

/// Sky radiance towards `d` (z up): a blue gradient, a warm sun of about 3 degrees, dark ground.
fn sky(d: Vec3) -> Vec3 {
    let sun = sun_direction();
    if d.dot(sun) > libm::cosf((1.5f32).to_radians()) {
        return Vec3::new(900.0, 800.0, 600.0);
    }
    if d.z < 0.0 {
        return Vec3::new(0.12, 0.1, 0.08) * (1.0 + d.z * 0.5);
    }
    let horizon = Vec3::new(0.9, 0.95, 1.0);
    let zenith = Vec3::new(0.25, 0.45, 0.9);
    let glow = d.dot(sun).max(0.0).powi(64) * 0.6;
    horizon.lerp(zenith, d.z.sqrt()) + Vec3::new(1.0, 0.8, 0.5) * glow
}

/// Pixel centres to directions with the seed tracer's LatLong rule (the default convention):
/// u = (pi + phi) / 2pi, v = theta / pi.
fn latlong_direction(x: u32, y: u32) -> Vec3 {
    let u = (x as f32 + 0.5) / SKY_WIDTH as f32;
    let v = (y as f32 + 0.5) / SKY_HEIGHT as f32;
    let phi = 2.0 * PI * u - PI;
    let theta = PI * v;
    Vec3::new(
        libm::sinf(theta) * libm::cosf(phi),
        libm::sinf(theta) * libm::sinf(phi),
        libm::cosf(theta),
    )
}

fn write_sky(dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all(dir)?;
    let mut hdr = image::Rgb32FImage::new(SKY_WIDTH, SKY_HEIGHT);
    let mut ldr = image::RgbImage::new(SKY_WIDTH, SKY_HEIGHT);
    for (x, y, px) in hdr.enumerate_pixels_mut() {
        let c = sky(latlong_direction(x, y));
        *px = image::Rgb(c.to_array());
        let encode = |v: f32| (libm::powf(v.clamp(0.0, 1.0), 1.0 / 2.2) * 255.0 + 0.5) as u8;
        ldr.put_pixel(x, y, image::Rgb([encode(c.x), encode(c.y), encode(c.z)]));
    }
    image::DynamicImage::ImageRgb32F(hdr).save(dir.join("sky.hdr"))?;
    ldr.save(dir.join("sky.png"))?;
    println!("wrote {}/sky.hdr and sky.png", dir.display());
    Ok(())
}

/// Side of the image-format scene's picture, in texels.
const FORMATS_SIZE: u32 = 64;

/// The image-format scene's picture (`scenes/textures/formats.lxs`): four flat quadrants, top
/// left to bottom right red, green, blue and yellow, so that a render shows whether each file
/// is read the right way up and the right way round. `tracer/tests/integration/image_formats.rs`
/// holds the same colours.
fn formats_texel(x: u32, y: u32) -> [u8; 3] {
    let half = FORMATS_SIZE / 2;
    match (x < half, y < half) {
        (true, true) => [200, 40, 40],
        (false, true) => [40, 180, 60],
        (true, false) => [40, 60, 200],
        (false, false) => [220, 200, 60],
    }
}

/// The picture as 8-bit RGB TGA (run-length encoded, as the `image` crate's encoder and
/// Blender's "Targa" write it), TIFF and 24-bit BMP.
fn write_formats(dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all(dir)?;
    let picture = image::RgbImage::from_fn(FORMATS_SIZE, FORMATS_SIZE, |x, y| {
        image::Rgb(formats_texel(x, y))
    });
    for extension in ["tga", "tif", "bmp"] {
        let path = dir.join(format!("formats.{extension}"));
        picture.save(&path)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// A lumpy rock: a sphere of radius 1 displaced by a few octaves of sines.
fn rock_point(theta: f32, phi: f32) -> Vec3 {
    let d = Vec3::new(
        libm::sinf(theta) * libm::cosf(phi),
        libm::sinf(theta) * libm::sinf(phi),
        libm::cosf(theta),
    );
    let bumps = 0.12 * libm::sinf(3.0 * d.x + 1.0) * libm::cosf(4.0 * d.y)
        + 0.05 * libm::sinf(11.0 * d.z + 2.0 * d.x)
        + 0.02 * libm::sinf(29.0 * d.y) * libm::cosf(31.0 * d.x)
        + 0.006 * libm::sinf(97.0 * d.z);
    d * (1.0 + bumps)
}

fn write_rock(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let n = ROCK_RESOLUTION;
    // Rows from pole to pole (inclusive), columns around (the seam shares vertices).
    let rows = n + 1;
    let vertex = |r: u32, c: u32| r * n + (c % n);
    let mut positions = Vec::with_capacity((rows * n) as usize);
    for r in 0..rows {
        let theta = PI * r as f32 / n as f32;
        for c in 0..n {
            positions.push(rock_point(theta, 2.0 * PI * c as f32 / n as f32));
        }
    }
    let mut faces = Vec::with_capacity((2 * n * n) as usize);
    for r in 0..n {
        for c in 0..n {
            let (a, b) = (vertex(r, c), vertex(r, c + 1));
            let (d, e) = (vertex(r + 1, c), vertex(r + 1, c + 1));
            faces.push([a, d, e]);
            faces.push([a, e, b]);
        }
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for f in &faces {
        let [p0, p1, p2] = f.map(|i| positions[i as usize]);
        let n = (p1 - p0).cross(p2 - p0);
        for &i in f {
            normals[i as usize] += n;
        }
    }

    std::fs::create_dir_all(path.parent().unwrap_or(Path::new(".")))?;
    let mut out = BufWriter::new(std::fs::File::create(path)?);
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment YAT heavy scene rock\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        faces.len()
    )?;
    for (p, n) in positions.iter().zip(&normals) {
        let n = n.normalize_or(Vec3::Z);
        for v in [p.x, p.y, p.z, n.x, n.y, n.z] {
            out.write_all(&v.to_le_bytes())?;
        }
    }
    for f in &faces {
        out.write_all(&[3u8])?;
        for i in f {
            out.write_all(&(*i as i32).to_le_bytes())?;
        }
    }
    out.flush()?;
    println!("wrote {} ({} triangles)", path.display(), faces.len());
    Ok(())
}
