//! The shapes YAT makes triangle meshes of while parsing: Loop subdivision (with displacement),
//! heightfields and the swept quadrics, through the parser, and the scene of `scenes/shapes`.

use std::f32::consts::PI;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use yat_tracer::assets::{FsSource, MemorySource};
use yat_tracer::desc::{Geometry, SceneDesc, ShapeDesc, TriangleMesh};
use yat_tracer::parse::parse_scene;

use crate::util::workspace_root;

/// The 12-triangle cube [-1, 1]^3, wound outwards.
const CUBE: &str = "\"integer indices\" [0 1 2 0 2 3 4 5 6 4 6 7 0 4 7 0 7 1 2 6 5 2 5 3 0 3 5 0 5 4 1 7 6 1 6 2] \
    \"point P\" [-1 -1 -1 -1 1 -1 1 1 -1 1 -1 -1 -1 -1 1 1 -1 1 1 1 1 -1 1 1]";

fn parse_world(body: &str) -> SceneDesc {
    let text = format!("Camera \"perspective\"\nWorldBegin\n{body}\nWorldEnd\n");
    let mut source = MemorySource::new();
    source.insert("main.lxs", Arc::from(text.as_bytes()));
    parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"))
}

fn mesh(shape: &ShapeDesc) -> &TriangleMesh {
    match &shape.geometry {
        Geometry::Mesh(m) => m,
        other => panic!("expected a mesh, got {}", other.name()),
    }
}

#[test]
fn loopsubdiv_levels_default_to_none_as_in_luxrender_1x() {
    let desc = parse_world(&format!("Shape \"loopsubdiv\" {CUBE}"));
    assert_eq!(mesh(&desc.shapes[0]).indices.len(), 12);
    let desc = parse_world(&format!(
        "Shape \"loopsubdiv\" \"integer nlevels\" [2] {CUBE}"
    ));
    let m = mesh(&desc.shapes[0]);
    assert_eq!((m.indices.len(), m.positions.len()), (12 * 16, 98));
    assert!(m.normals.is_some(), "dmnormalsmooth defaults to true");
    // LuxRender 1.x reads nsubdivlevels on any mesh.
    let desc = parse_world(&format!(
        "Shape \"trianglemesh\" \"integer nsubdivlevels\" [1] \"bool dmnormalsmooth\" [\"false\"] {CUBE}"
    ));
    let m = mesh(&desc.shapes[0]);
    assert_eq!(m.indices.len(), 48);
    assert!(m.normals.is_none());
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
}

#[test]
fn displacement_through_the_parser_is_scale_times_texture_plus_offset_in_world_units() {
    let plain = parse_world(&format!(
        "Scale 2 2 2\nShape \"loopsubdiv\" \"integer nlevels\" [2] {CUBE}"
    ));
    // 0.1 x 2 + 0.05 = 0.25 world units: 0.125 in the object space scaled by 2.
    let displaced = parse_world(&format!(
        "Texture \"h\" \"float\" \"constant\" \"float value\" [2]\n\
         Scale 2 2 2\n\
         Shape \"loopsubdiv\" \"integer nlevels\" [2] \"string displacementmap\" [\"h\"] \
         \"float dmscale\" [0.1] \"float dmoffset\" [0.05] {CUBE}"
    ));
    assert!(displaced.warnings.is_empty(), "{:?}", displaced.warnings);
    let (a, b) = (mesh(&plain.shapes[0]), mesh(&displaced.shapes[0]));
    let normals = a.normals.as_ref().unwrap();
    assert_eq!(a.positions.len(), b.positions.len());
    for ((p, q), n) in a.positions.iter().zip(&b.positions).zip(normals) {
        let expected = *p + *n * 0.125;
        assert!(
            (*q - expected).length() < 1e-5,
            "{p} -> {q}, expected {expected}"
        );
    }
    // The texture given as a texture parameter works the same; an unknown name is a warning.
    let by_texture = parse_world(&format!(
        "Texture \"h\" \"float\" \"constant\" \"float value\" [2]\n\
         Scale 2 2 2\n\
         Shape \"loopsubdiv\" \"integer nlevels\" [2] \"texture displacementmap\" \"h\" \
         \"float dmscale\" [0.1] \"float dmoffset\" [0.05] {CUBE}"
    ));
    assert_eq!(mesh(&by_texture.shapes[0]).positions, b.positions);
    let unknown = parse_world(&format!(
        "Shape \"loopsubdiv\" \"integer nlevels\" [1] \"string displacementmap\" [\"nope\"] {CUBE}"
    ));
    assert!(
        unknown
            .warnings
            .iter()
            .any(|w| w.message.contains("\"nope\"")),
        "{:?}",
        unknown.warnings
    );
}

#[test]
fn a_mesh_loop_cannot_subdivide_is_kept_with_a_warning() {
    // The cube with one triangle wound backwards.
    let flipped = CUBE.replacen("[0 1 2 ", "[0 2 1 ", 1);
    let desc = parse_world(&format!(
        "Shape \"loopsubdiv\" \"integer nlevels\" [2] {flipped}"
    ));
    assert_eq!(mesh(&desc.shapes[0]).indices.len(), 12);
    let w = &desc.warnings[0];
    assert!(
        w.message.contains("inconsistent winding") && w.pos.to_string().starts_with("main.lxs:3:1"),
        "{w:?}"
    );
}

#[test]
fn a_constant_heightfield_is_a_unit_square_at_its_height() {
    let desc = parse_world(
        "Shape \"heightfield\" \"integer nu\" [3] \"integer nv\" [4] \"float Pz\" [0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5]",
    );
    let shape = &desc.shapes[0];
    let m = mesh(shape);
    assert_eq!(m.indices.len(), 2 * 2 * 3);
    assert!(m.positions.iter().all(|p| p.z == 0.5));
    assert!(
        (shape.world_area() - 1.0).abs() < 1e-6,
        "{}",
        shape.world_area()
    );
}

/// Areas of the shapes of `scenes/shapes/shapes.lxs` against their closed forms, and the
/// triangle counts the scene asks for.
#[test]
fn the_shapes_scene_parses_to_meshes_of_the_right_size() {
    let path = workspace_root().join("scenes/shapes/shapes.lxs");
    let source = FsSource::for_main_file(Path::new(&path));
    let desc = parse_scene("shapes.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let counts: Vec<usize> = desc.shapes.iter().map(|s| mesh(s).indices.len()).collect();
    assert_eq!(
        counts,
        [
            2,
            12 * 64,
            12 * 1024,
            12 * 4,
            2 * 39 * 39,
            4032,
            4096,
            4032,
            4096
        ]
    );
    // The displaced blob is bigger than the plain one (dmoffset 0.05 and fbm around 0).
    let extent = |s: &ShapeDesc| {
        let m = mesh(s);
        m.positions
            .iter()
            .map(|p| p.length())
            .fold(0.0f32, f32::max)
    };
    assert!(extent(&desc.shapes[2]) > extent(&desc.shapes[1]) + 0.04);
    let slant = |r: f32, h: f32| (r * r + h * h).sqrt();
    let cone = PI * 0.7 * slant(0.7, 1.6);
    let frustum = PI * (0.7 + 0.35) * slant(0.35, 0.9);
    // x^2 + y^2 = k z, k = r^2 / zmax: pi sqrt(k) / 6 ((4 zmax + k)^(3/2) - k^(3/2)).
    let k: f32 = 0.49 / 1.4;
    let paraboloid = PI * k.sqrt() / 6.0 * (libm::powf(4.0 * 1.4 + k, 1.5) - libm::powf(k, 1.5));
    for (shape, exact) in desc.shapes[5..8].iter().zip([cone, frustum, paraboloid]) {
        let a = shape.world_area();
        assert!((a / exact - 1.0).abs() < 0.01, "{a} vs {exact}");
    }
    // The hyperboloid's segment from (0.7, 0, 0) to (0, 0.7, 1.4) passes the axis at
    // 0.7 / sqrt(2) halfway up: its narrowest ring.
    let waist = mesh(&desc.shapes[8])
        .positions
        .iter()
        .map(|p| p.truncate().length())
        .fold(f32::INFINITY, f32::min);
    assert!((waist - 0.7 / 2f32.sqrt()).abs() < 1e-3, "{waist}");
    // The terrain: the unit square scaled to 6 x 3, hills making it larger.
    let terrain = desc.shapes[4].world_area();
    assert!(terrain > 18.0 && terrain < 24.0, "{terrain}");
    let up = mesh(&desc.shapes[4]).indices.iter().all(|t| {
        let m = mesh(&desc.shapes[4]);
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        (b - a).cross(c - a).dot(Vec3::Z) > 0.0
    });
    assert!(up, "every terrain triangle faces up");
}
