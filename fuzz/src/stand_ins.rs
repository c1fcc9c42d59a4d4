//! Small asset files made at start-up, so every fuzz input can reference meshes and images
//! whatever scene it grew from: PLY meshes (ASCII and binary), 4x4 images in each format
//! the tracer decodes, and metal index files (`.nk`, both formats). They also stand in for a seed scene's files that are too large to
//! mutate usefully or missing.

use std::io::Cursor;

use image::{ImageFormat, Rgb32FImage, RgbImage};

/// The name a scene uses for each stand-in, and its bytes.
pub fn files() -> Vec<(String, Vec<u8>)> {
    vec![
        ("mesh.ply".into(), ascii_ply()),
        ("mesh-bin.ply".into(), binary_ply()),
        ("tex.png".into(), image_bytes(ImageFormat::Png)),
        ("tex.jpg".into(), image_bytes(ImageFormat::Jpeg)),
        ("tex.exr".into(), image_bytes(ImageFormat::OpenExr)),
        ("env.hdr".into(), image_bytes(ImageFormat::Hdr)),
        ("sopra.nk".into(), SOPRA_NK.to_vec()),
        ("luxpop.nk".into(), LUXPOP_NK.to_vec()),
    ]
}

/// A stand-in for a file named `written`, chosen by its extension: a mesh, an image, a metal
/// index file, or an empty scene file.
pub fn for_name(written: &str) -> Vec<u8> {
    let extension = written
        .rsplit('.')
        .next()
        .unwrap_or_default()
        .to_ascii_lowercase();
    match extension.as_str() {
        "ply" => ascii_ply(),
        "png" => image_bytes(ImageFormat::Png),
        "jpg" | "jpeg" => image_bytes(ImageFormat::Jpeg),
        "exr" => image_bytes(ImageFormat::OpenExr),
        "hdr" => image_bytes(ImageFormat::Hdr),
        "nk" => SOPRA_NK.to_vec(),
        _ => Vec::new(),
    }
}

/// Whether a file of this name is binary (a mesh or an image), not text: scene files and
/// `.nk` files are lines of numbers, mutated as text.
pub fn is_binary(written: &str) -> bool {
    !written.to_ascii_lowercase().ends_with(".nk") && !for_name(written).is_empty()
}

/// A SOPRA `.nk` file: unit 2 (micrometres) from 0.4 to 0.7 in 4 samples, then `n k` lines.
const SOPRA_NK: &[u8] = b"2 0.4 0.7 4
0.47 2.37
0.37 2.82
0.27 3.23
0.18 3.64
";

/// A Luxpop `.nk` file: comments, then `wavelength(angstrom) n k` lines.
const LUXPOP_NK: &[u8] = b"; a stand-in metal, Luxpop format
; wavelength n k
4000 1.5 1.9
5000 0.9 2.4
6000 0.3 3.0
7000 0.2 3.6
";

/// A unit quad as two triangles with normals and uvs, plus a quad face.
fn ascii_ply() -> Vec<u8> {
    b"ply
format ascii 1.0
comment a stand-in mesh
element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float u
property float v
element face 2
property list uchar int vertex_indices
end_header
-1 -1 0 0 0 1 0 0
1 -1 0 0 0 1 1 0
1 1 0 0 0 1 1 1
-1 1 0 0 0 1 0 1
3 0 1 2
4 0 1 2 3
"
    .to_vec()
}

/// A tetrahedron, little-endian binary, with an extra element the reader skips.
fn binary_ply() -> Vec<u8> {
    let mut out = b"ply
format binary_little_endian 1.0
element vertex 4
property float x
property float y
property float z
element face 4
property list uchar uint vertex_indices
element edge 1
property int vertex1
property int vertex2
end_header
"
    .to_vec();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ] {
        for v in p {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    for face in [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
        out.push(3);
        for i in face {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    for i in [0i32, 1] {
        out.extend_from_slice(&i.to_le_bytes());
    }
    out
}

/// A 4x4 gradient in `format`.
fn image_bytes(format: ImageFormat) -> Vec<u8> {
    let mut out = Cursor::new(Vec::new());
    let written = match format {
        ImageFormat::OpenExr | ImageFormat::Hdr => {
            Rgb32FImage::from_fn(4, 4, |x, y| image::Rgb([x as f32, y as f32 * 0.5, 2.0]))
                .write_to(&mut out, format)
        }
        _ => RgbImage::from_fn(4, 4, |x, y| {
            image::Rgb([(x * 60) as u8, (y * 60) as u8, 128])
        })
        .write_to(&mut out, format),
    };
    written.expect("encoding a 4x4 image in memory cannot fail");
    out.into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stand_ins_are_valid_files() {
        assert_eq!(
            yat_tracer::mesh::ply::read_valid_mesh(&ascii_ply())
                .unwrap()
                .indices
                .len(),
            3
        );
        assert_eq!(
            yat_tracer::mesh::ply::read_valid_mesh(&binary_ply())
                .unwrap()
                .indices
                .len(),
            4
        );
        for name in ["sopra.nk", "luxpop.nk"] {
            let bytes = &files().into_iter().find(|(n, _)| n == name).unwrap().1;
            let (eta, k) = yat_tracer::material::nk::read(bytes).unwrap();
            assert!(
                eta.min_element() > 0.0 && k.min_element() > 1.5,
                "{name}: {eta} {k}"
            );
        }
        for (name, bytes) in files() {
            if name.starts_with("tex") || name.ends_with(".hdr") {
                let image = image::load_from_memory(&bytes).unwrap();
                assert_eq!((image.width(), image.height()), (4, 4), "{name}");
            }
        }
    }
}
