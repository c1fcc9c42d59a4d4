//! Bad input is an error value naming where and what, never a panic.

use std::sync::Arc;

use yat_tracer::assets::MemorySource;
use yat_tracer::desc::SceneDesc;
use yat_tracer::parse::{parse_scene, ParseError, MAX_INCLUDE_DEPTH};

fn parse_files(files: &[(&str, &[u8])]) -> Result<SceneDesc, ParseError> {
    let mut s = MemorySource::new();
    for (name, bytes) in files {
        s.insert(*name, Arc::from(*bytes));
    }
    parse_scene(files[0].0, &s)
}

fn error(text: &str) -> String {
    match parse_files(&[("main.lxs", text.as_bytes())]) {
        Ok(_) => panic!("expected an error for {text:?}"),
        Err(e) => e.to_string(),
    }
}

fn world_error(body: &str) -> String {
    error(&format!("WorldBegin\n{body}\nWorldEnd\n"))
}

#[test]
fn syntax_errors_name_file_line_column_and_expectation() {
    let e = error("Film \"fleximage\"\n  \"integer xresolution\" [640\n");
    assert!(e.starts_with("main.lxs:3:1: syntax error"), "{e}");
    assert!(
        e.contains("expected a number or `]`") && e.contains("end of file"),
        "{e}"
    );
    let e = error("WorldBegin\nShape \"sphere\" 12");
    assert!(
        e.starts_with("main.lxs:2:16:") && e.contains("parameter declaration"),
        "{e}"
    );
    let e = error("LookAt 1 2 3 4\nCamera \"perspective\"");
    assert!(e.contains("LookAt: expected 9 numbers, found 4"), "{e}");
    let e = world_error("Shape \"sphere\" \"float radius\" 1 \"floatradius\" 2");
    assert!(e.contains("\"type name\""), "{e}");
    let e = error("WorldBegin\nShape \"sphere\" \"real radius\" 1");
    assert!(e.contains("unknown parameter type `real`"), "{e}");
    let e = error("[ 1 2 ]");
    assert!(
        e.starts_with("main.lxs:1:1:") && e.contains("expected a statement keyword"),
        "{e}"
    );
}

#[test]
fn truncated_files_are_errors() {
    let full = "Camera \"perspective\" \"float fov\" [45]\nWorldBegin\nShape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\n";
    let mut failures = 0;
    for cut in 1..full.len() {
        if let Err(e) = parse_files(&[("main.lxs", &full.as_bytes()[..cut])]) {
            failures += 1;
            assert!(e.to_string().starts_with("main.lxs:"), "{e}");
        }
    }
    // Cuts inside strings, arrays and meshes fail; cuts between statements load what is there.
    assert!(failures > full.len() / 2, "{failures} of {}", full.len());
}

#[test]
fn binary_garbage_is_an_error() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..200 {
        let bytes: Vec<u8> = (0..64)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                state as u8
            })
            .collect();
        // Must return (Ok or Err) without panicking.
        let _ = parse_files(&[("main.lxs", &bytes)]);
    }
    let e = parse_files(&[("main.lxs", b"\x89PNG\r\n\x1a\n\x00\x00")]).unwrap_err();
    assert!(e.to_string().contains("unexpected character"), "{e}");
}

#[test]
fn huge_numbers_are_errors_naming_the_parameter() {
    let e = error("Camera \"perspective\" \"float fov\" [1e999]");
    assert!(
        e.contains("\"float fov\"") && e.contains("out of range"),
        "{e}"
    );
    let e = error("Camera \"perspective\" \"float fov\" [1e39]");
    assert!(e.contains("out of range"), "{e}");
    let e = error("Film \"fleximage\" \"integer xresolution\" [99999999999999999999]");
    assert!(e.contains("\"integer xresolution\""), "{e}");
    let e = error("Film \"fleximage\" \"integer xresolution\" [0]");
    assert!(e.contains("not a resolution"), "{e}");
    let e = error("Translate 1e999 0 0");
    assert!(e.contains("Translate") && e.contains("out of range"), "{e}");
    let e = world_error(
        "Shape \"mesh\" \"integer indices\" [0 1 4294967298] \"point P\" [0 0 0 1 0 0 0 1 0]",
    );
    assert!(
        e.contains("\"integer indices\"") && e.contains("value 3"),
        "{e}"
    );
}

#[test]
fn wrong_types_and_counts_name_the_parameter() {
    let e = error("Camera \"perspective\" \"string fov\" \"wide\"");
    assert!(
        e.contains("Camera \"perspective\"") && e.contains("\"string fov\""),
        "{e}"
    );
    let e = world_error("Material \"matte\" \"color Kd\" [1 2]");
    assert!(
        e.contains("\"color Kd\"") && e.contains("got 2 values"),
        "{e}"
    );
    let e = world_error("Shape \"sphere\" \"float radius\" [1 2]");
    assert!(e.contains("\"float radius\""), "{e}");
    let e = world_error("Material \"glossy\" \"bool multibounce\" \"yes\"");
    assert!(
        e.contains("\"bool multibounce\"") && e.contains("\"true\" or \"false\""),
        "{e}"
    );
    let e = error("Camera \"perspective\" \"float screenwindow\" [-1 1 -1]");
    assert!(
        e.contains("\"float screenwindow\"") && e.contains("4 floats"),
        "{e}"
    );
}

#[test]
fn invalid_mesh_data_names_the_parameter_and_position() {
    let p = "\"point P\" [0 0 0 1 0 0 0 1 0]";
    let e = world_error(&format!(
        "Shape \"trianglemesh\" \"integer indices\" [0 1 3] {p}"
    ));
    assert!(
        e.contains("\"integer indices\"") && e.contains("index 3 (value 3) is out of range"),
        "{e}"
    );
    assert!(e.starts_with("main.lxs:2:22:"), "{e}");
    let e = world_error(&format!(
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0] {p}"
    ));
    assert!(e.contains("multiple of 3 indices, got 4"), "{e}");
    let e = world_error(&format!(
        "Shape \"trianglemesh\" \"integer indices\" [0 -1 2] {p}"
    ));
    assert!(e.contains("value -1"), "{e}");
    let e = world_error(
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1]",
    );
    assert!(
        e.contains("\"point P\"") && e.contains("multiple of 3 values, got 8"),
        "{e}"
    );
    let e = world_error(&format!(
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2] {p} \"normal N\" [0 0 1]"
    ));
    assert!(
        e.contains("\"normal N\"") && e.contains("one normal per vertex (3), got 1"),
        "{e}"
    );
    let e = world_error(&format!(
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2] {p} \"float uv\" [0 0 1]"
    ));
    assert!(e.contains("\"float uv\""), "{e}");
    let e = world_error("Shape \"trianglemesh\" \"integer indices\" [0 1 2]");
    assert!(e.contains("missing \"point P\""), "{e}");
    let e = world_error(
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1e40 0]",
    );
    assert!(
        e.contains("\"point P\"") && e.contains("out of range"),
        "{e}"
    );
}

#[test]
fn missing_files_name_the_path_as_written_and_the_path_tried() {
    let e = error("WorldBegin\nInclude \"geo/missing.lxo\"\nWorldEnd");
    assert!(e.starts_with("main.lxs:2:1:"), "{e}");
    assert!(
        e.contains("\"geo/missing.lxo\"") && e.contains("tried"),
        "{e}"
    );
    let e = world_error("Shape \"plymesh\" \"string filename\" \"m.ply\"");
    assert!(e.contains("\"m.ply\""), "{e}");
    let e = world_error("Texture \"t\" \"color\" \"imagemap\" \"string filename\" \"t.png\"");
    assert!(e.contains("\"t.png\""), "{e}");
    let e = world_error("LightSource \"infinite\" \"string mapname\" \"sky.hdr\"");
    assert!(e.contains("\"sky.hdr\""), "{e}");
    let e = parse_scene("nothing.lxs", &MemorySource::new())
        .unwrap_err()
        .to_string();
    assert!(e.contains("\"nothing.lxs\""), "{e}");
}

#[test]
fn bad_referenced_files_are_errors() {
    let main =
        "WorldBegin\nTexture \"t\" \"color\" \"imagemap\" \"string filename\" \"t.png\"\nWorldEnd";
    let e = parse_files(&[
        ("main.lxs", main.as_bytes()),
        ("t.png", b"not an image at all"),
    ])
    .unwrap_err();
    assert!(
        matches!(e, ParseError::Image { .. }) && e.to_string().contains("\"t.png\""),
        "{e}"
    );
    let main = "WorldBegin\nShape \"plymesh\" \"string filename\" \"m.ply\"\nWorldEnd";
    let bad_index = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    let e = parse_files(&[
        ("main.lxs", main.as_bytes()),
        ("m.ply", bad_index.as_bytes()),
    ])
    .unwrap_err();
    assert!(
        matches!(e, ParseError::Ply { .. }) && e.to_string().contains("out of range"),
        "{e}"
    );
    let e =
        parse_files(&[("main.lxs", main.as_bytes()), ("m.ply", b"\x00\x01garbage")]).unwrap_err();
    assert!(e.to_string().contains("PLY file \"m.ply\""), "{e}");
}

#[test]
fn include_cycles_and_depth_are_errors() {
    let e = parse_files(&[("main.lxs", b"Include \"main.lxs\"")])
        .unwrap_err()
        .to_string();
    assert!(e.contains("Include cycle: main.lxs -> main.lxs"), "{e}");
    let e = parse_files(&[
        ("main.lxs", b"Include \"a.lxs\""),
        ("a.lxs", b"Include \"b.lxs\""),
        ("b.lxs", b"\n\nInclude \"a.lxs\""),
    ])
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("b.lxs:3:1:") && e.contains("main.lxs -> a.lxs -> b.lxs -> a.lxs"),
        "{e}"
    );
    // A chain of distinct files deeper than the limit.
    let names: Vec<String> = (0..=MAX_INCLUDE_DEPTH + 1)
        .map(|i| format!("f{i}.lxs"))
        .collect();
    let texts: Vec<String> = (0..names.len())
        .map(|i| match names.get(i + 1) {
            Some(next) => format!("Include \"{next}\""),
            None => String::new(),
        })
        .collect();
    let files: Vec<(&str, &[u8])> = names
        .iter()
        .zip(&texts)
        .map(|(n, t)| (n.as_str(), t.as_bytes()))
        .collect();
    let e = parse_files(&files).unwrap_err().to_string();
    assert!(e.contains("deeper than 32"), "{e}");
    // Exactly at the limit is fine.
    let ok = &files[1..];
    assert!(parse_files(ok).is_ok());
}

#[test]
fn invalid_transforms_are_errors() {
    let e = error("Rotate 30 0 0 0");
    assert!(e.contains("Rotate") && e.contains("non-zero"), "{e}");
    let e = error("LookAt 0 0 0  0 0 1  0 0 1\nCamera \"perspective\"");
    assert!(e.contains("LookAt"), "{e}");
    let e = error("Scale 0 1 1\nCamera \"perspective\"\nWorldBegin\nWorldEnd");
    assert!(e.contains("not invertible"), "{e}");
}
