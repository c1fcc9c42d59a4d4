//! Hostile scenes: expansion bombs are refused at the build budget's limits, quickly and with
//! the file:line:col that reached the limit; huge or degenerate coordinates are refused or
//! skipped, never a panic.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use yat_tracer::assets::MemorySource;
use yat_tracer::budget::{BuildBudget, BuildGuard, Cancelled, Limit, OverBudget};
use yat_tracer::desc::{LatLongConvention, SceneDesc};
use yat_tracer::film::Film;
use yat_tracer::parse::{parse_scene, parse_scene_guarded, ParseError};
use yat_tracer::render::{plan_units, BuildError, RenderScene, RenderSettings};

use crate::hostile::{self, Files};

/// Generous for a debug build on a loaded machine; each refusal takes milliseconds.
const QUICKLY: Duration = Duration::from_secs(10);

fn source(files: &Files) -> MemorySource {
    let mut source = MemorySource::new();
    for (name, bytes) in files {
        source.insert(name.clone(), Arc::from(bytes.as_slice()));
    }
    source
}

/// Parses `files` under the default budget; the error must come quickly.
fn refused(files: &Files) -> ParseError {
    let started = Instant::now();
    let err = parse_scene(&files[0].0, &source(files)).expect_err("a bomb is refused");
    assert!(started.elapsed() < QUICKLY, "{:?}", started.elapsed());
    err
}

fn over_budget(err: &ParseError) -> (&OverBudget, String) {
    match err {
        ParseError::OverBudget { exceeded, pos } => (exceeded, pos.to_string()),
        other => panic!("expected a budget error, got {other}"),
    }
}

#[test]
fn an_include_fan_out_stops_at_the_include_limit() {
    let err = refused(&hostile::include_fan_out());
    let (over, pos) = over_budget(&err);
    assert_eq!(over.limit, Limit::IncludeVisits);
    assert_eq!(over.max, BuildBudget::DEFAULT.max_include_visits);
    assert_eq!(over.reached, over.max + 1);
    assert!(pos.starts_with("level") && pos.contains(".lxo:"), "{pos}");
    let message = err.to_string();
    assert!(
        message.contains("Include visits") && message.contains("--max-include-visits"),
        "{message}"
    );
}

#[test]
fn an_instancing_bomb_stops_at_the_primitive_limit() {
    let files = hostile::instancing_bomb();
    let text: usize = files.iter().map(|(_, bytes)| bytes.len()).sum();
    assert!(text < 64 << 10, "the bomb is {text} bytes");
    let err = refused(&files);
    let (over, pos) = over_budget(&err);
    assert_eq!(over.limit, Limit::Primitives);
    assert_eq!(over.max, BuildBudget::DEFAULT.max_primitives);
    assert!(over.reached > over.max && over.reached <= over.max + 512);
    assert!(pos.starts_with("level3.lxo:"), "{pos}");
    assert!(err.to_string().contains("--max-primitives"), "{err}");
}

#[test]
fn an_image_header_claiming_billions_of_texels_is_refused_before_decoding() {
    let err = refused(&hostile::huge_image());
    let (over, pos) = over_budget(&err);
    assert_eq!(over.limit, Limit::Texels);
    assert_eq!(over.reached, 60_000 * 60_000);
    assert!(pos.starts_with("main.lxs:6:"), "{pos}");
    assert!(err.to_string().contains("--max-texels"), "{err}");
}

#[test]
fn parsed_bytes_count_every_include_visit() {
    let files: Files = vec![
        (
            "main.lxs".into(),
            hostile::scene(&"Include \"big.lxo\"\n".repeat(100)).into_bytes(),
        ),
        (
            "big.lxo".into(),
            format!("# {}\n", "x".repeat(1000)).into_bytes(),
        ),
    ];
    let budget = BuildBudget {
        max_parsed_bytes: 50_000,
        ..BuildBudget::DEFAULT
    };
    let guard = BuildGuard {
        budget: &budget,
        ..BuildGuard::default()
    };
    let err = parse_scene_guarded("main.lxs", &source(&files), guard).unwrap_err();
    let (over, pos) = over_budget(&err);
    assert_eq!(over.limit, Limit::ParsedBytes);
    assert!(over.reached > 50_000 && over.reached < 52_000, "{over}");
    assert!(pos.starts_with("main.lxs:"), "{pos}");
    // The same scene is fine under the default budget.
    parse_scene("main.lxs", &source(&files)).unwrap();
}

#[test]
fn a_cancelled_parse_or_build_stops_with_cancelled() {
    let files = hostile::include_fan_out();
    let cancel = AtomicBool::new(true);
    let guard = BuildGuard {
        cancel: &cancel,
        ..BuildGuard::default()
    };
    let err = parse_scene_guarded("main.lxs", &source(&files), guard).unwrap_err();
    assert!(matches!(err, ParseError::Cancelled { .. }), "{err}");

    let files: Files = vec![(
        "main.lxs".into(),
        hostile::scene("Shape \"sphere\"").into_bytes(),
    )];
    let desc = parse_scene("main.lxs", &source(&files)).unwrap();
    let err = RenderScene::build_guarded(&desc, &source(&files), &settings(&desc), guard)
        .err()
        .expect("cancelled");
    assert!(matches!(err, BuildError::Cancelled(Cancelled)), "{err}");
}

#[test]
fn the_build_counts_primitives_of_a_description_it_is_handed() {
    let files: Files = vec![(
        "main.lxs".into(),
        hostile::scene(&"Shape \"sphere\"\n".repeat(20)).into_bytes(),
    )];
    let desc = parse_scene("main.lxs", &source(&files)).unwrap();
    let budget = BuildBudget {
        max_primitives: 19,
        ..BuildBudget::DEFAULT
    };
    let guard = BuildGuard {
        budget: &budget,
        ..BuildGuard::default()
    };
    let err = RenderScene::build_guarded(&desc, &source(&files), &settings(&desc), guard)
        .err()
        .expect("over budget");
    assert!(
        matches!(&err, BuildError::OverBudget(o) if o.limit == Limit::Primitives && o.reached == 20),
        "{err}"
    );
}

/// A budget of `mib` MiB of memory, the counts' defaults.
fn memory_guard(budget: &BuildBudget) -> BuildGuard<'_> {
    BuildGuard {
        budget,
        ..BuildGuard::default()
    }
}

fn memory_budget(mib: u64) -> BuildBudget {
    BuildBudget {
        max_memory_bytes: mib << 20,
        ..BuildBudget::DEFAULT
    }
}

/// An object instanced so often that its triangles stay far under the primitive limit but its
/// built copies do not fit the memory budget: refused at the ObjectInstance that goes over,
/// each instance counted, with the figure and the flag.
#[test]
fn instances_under_the_primitive_limit_are_refused_at_the_memory_budget() {
    let files = hostile::instanced_strips(2000);
    let budget = memory_budget(64);
    let err = parse_scene_guarded("main.lxs", &source(&files), memory_guard(&budget)).unwrap_err();
    let (over, pos) = over_budget(&err);
    assert_eq!(over.limit, Limit::MemoryBytes);
    assert_eq!(over.max, 64 << 20);
    // Some 300 of the 2000 instances fit (512 triangles each, hundreds of bytes a triangle
    // once built): the instance that went over is named, not the object.
    let line: u32 = pos.split(':').nth(1).unwrap().parse().unwrap();
    assert!(
        pos.starts_with("main.lxs:") && (100..1000).contains(&line),
        "{pos}"
    );
    let message = err.to_string();
    assert!(
        message.contains("--max-memory-mib") && message.contains("64.0 MiB"),
        "{message}"
    );
    const { assert!(512 * 2000 < BuildBudget::DEFAULT.max_primitives) };
    // Within a larger budget, the same scene parses, and its estimate is what it was refused on.
    let desc = parse_scene("main.lxs", &source(&files)).unwrap();
    assert!(desc.spent.spent(Limit::MemoryBytes) > 64 << 20);
}

/// A small PNG whose image is large (under the texel limit): refused from its header at the
/// Texture statement, before it is decoded.
#[test]
fn a_small_png_of_a_large_image_is_refused_at_the_memory_budget() {
    let png = hostile::uniform_png(4096, 4096);
    assert!(png.len() < 256 << 10, "{} bytes", png.len());
    const { assert!(4096 * 4096 < BuildBudget::DEFAULT.max_texels) };
    let files = hostile::image_texture(png);
    let budget = memory_budget(128);
    let started = Instant::now();
    let err = parse_scene_guarded("main.lxs", &source(&files), memory_guard(&budget)).unwrap_err();
    assert!(started.elapsed() < QUICKLY);
    let (over, pos) = over_budget(&err);
    assert_eq!(over.limit, Limit::MemoryBytes);
    assert!(pos.starts_with("main.lxs:6:"), "{pos}");
    // 4 bytes a texel kept, 11 more while decoding.
    assert!(over.reached >= 15 * 4096 * 4096, "{over}");
    assert!(err.to_string().contains("--max-memory-mib"), "{err}");
    // Within a budget that holds its estimate, it is decoded and built.
    let budget = memory_budget(512);
    let desc = parse_scene_guarded("main.lxs", &source(&files), memory_guard(&budget)).unwrap();
    RenderScene::build_guarded(
        &desc,
        &source(&files),
        &settings(&desc),
        memory_guard(&budget),
    )
    .unwrap();
}

/// A description not made by the parser has counted nothing: the build counts its shapes'
/// memory itself before placing them.
#[test]
fn the_build_counts_memory_of_a_description_it_is_handed() {
    let files = hostile::instanced_strips(400);
    let mut desc = parse_scene("main.lxs", &source(&files)).unwrap();
    let estimate = desc.spent.spent(Limit::MemoryBytes);
    desc.spent = Default::default();
    let budget = BuildBudget {
        max_memory_bytes: estimate / 2,
        ..BuildBudget::DEFAULT
    };
    let err = RenderScene::build_guarded(
        &desc,
        &source(&files),
        &settings(&desc),
        memory_guard(&budget),
    )
    .err()
    .expect("over budget");
    assert!(
        matches!(&err, BuildError::OverBudget(o) if o.limit == Limit::MemoryBytes),
        "{err}"
    );
}

fn settings(desc: &SceneDesc) -> RenderSettings {
    RenderSettings {
        width: desc.film.xresolution,
        height: desc.film.yresolution,
        spp: 1,
        max_depth: 3,
        seed: 0,
        latlong: LatLongConvention::Seed,
        transport: Default::default(),
        aovs: Default::default(),
    }
}

/// Parses, builds and renders `body`; returns the parse error's text if it is refused.
fn render(body: &str) -> Result<Film, String> {
    let files: Files = vec![("main.lxs".into(), hostile::scene(body).into_bytes())];
    let source = source(&files);
    let desc = parse_scene("main.lxs", &source).map_err(|e| e.to_string())?;
    let settings = settings(&desc);
    let scene = RenderScene::build(&desc, &source, &settings).map_err(|e| e.to_string())?;
    let mut film = Film::new(scene.frame());
    for unit in plan_units(&settings) {
        film.add(&scene.render_unit(&unit).0).unwrap();
    }
    Ok(film)
}

/// Huge but finite shapes are left out of the world (a warning), and the rest renders.
#[test]
fn huge_coordinates_are_skipped_not_a_panic() {
    let huge = [
        "Shape \"sphere\" \"float radius\" [3e38]",
        "Translate 1e38 0 0\nShape \"sphere\"",
        "Scale 1e30 1e30 1e30\nShape \"sphere\"\nShape \"disk\"\nShape \"cylinder\"",
        "Translate 3e38 0 0\nShape \"plane\"",
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [-3e38 0 0 3e38 0 0 0 3e38 0]",
        "AreaLightSource \"area\" \"color L\" [1 1 1]\nShape \"sphere\" \"float radius\" [3e38]",
        "AreaLightSource \"area\" \"color L\" [1 1 1] \"float power\" [100]\nShape \"disk\" \"float radius\" [1e20]",
        "Scale 0 0 0\nShape \"sphere\"\nShape \"disk\"\nShape \"plane\"",
    ];
    for body in huge {
        let body = format!("{body}\nShape \"sphere\" \"float radius\" [0.5]");
        let film = render(&body).unwrap_or_else(|e| panic!("{body}: {e}"));
        assert!(
            (0..8).all(|y| (0..8).all(|x| film.pixel(x, y).is_finite())),
            "{body}"
        );
    }
}

/// Transforms whose product leaves the range of 32-bit floats, and meshes that cannot be, are
/// errors naming the statement.
#[test]
fn overflowing_transforms_and_bad_meshes_are_errors_with_positions() {
    let cases = [
        ("Scale 1e30 1e30 1e30\nScale 1e30 1e30 1e30", "main.lxs:7:1:", "overflows"),
        (
            "Scale 1e30 1e30 1e30\nTranslate 1e38 1e38 1e38",
            "main.lxs:7:1:",
            "overflows",
        ),
        (
            "ConcatTransform [3e38 0 0 0  0 3e38 0 0  0 0 3e38 0  0 0 0 1]\nConcatTransform [3e38 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1]",
            "main.lxs:7:1:",
            "overflows",
        ),
        (
            "ObjectBegin \"o\"\nScale 1e30 1 1\nShape \"sphere\"\nObjectEnd\nScale 1e30 1 1\nObjectInstance \"o\"",
            "main.lxs:11:1:",
            "overflows",
        ),
        (
            "Shape \"trianglemesh\" \"integer indices\" [0 1 7] \"point P\" [0 0 0 1 0 0 2 0 0]",
            "main.lxs:6:",
            "out of range",
        ),
    ];
    for (body, pos, what) in cases {
        let err = render(body)
            .err()
            .unwrap_or_else(|| panic!("{body}: accepted"));
        assert!(err.starts_with(pos) && err.contains(what), "{body}: {err}");
    }
}

/// Degenerate triangles (zero area, repeated vertices) are skipped; the scene renders.
#[test]
fn degenerate_triangles_are_skipped() {
    let body = "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 0 0 0 1 1] \"point P\" [0 0 0 1 0 0 2 0 0]";
    render(body).unwrap();
}

/// Shapes that multiply their input: a subdivision asking for more triangles than the budget
/// is refused before any is made, naming the statement; heightfield and subdivision counts
/// that do not match their data are errors naming the parameter. Never a panic, never a
/// 4^30-triangle allocation.
#[test]
fn subdivision_and_heightfield_bombs_are_refused_with_their_position() {
    const CUBE: &str = "\"integer indices\" [0 1 2 0 2 3 4 5 6 4 6 7 0 4 7 0 7 1 2 6 5 2 5 3 0 3 5 0 5 4 1 7 6 1 6 2] \
        \"point P\" [-1 -1 -1 -1 1 -1 1 1 -1 1 -1 -1 -1 -1 1 1 -1 1 1 1 1 -1 1 1]";
    let refuse = |body: String| -> ParseError {
        refused(&vec![(
            "main.lxs".into(),
            hostile::scene(&body).into_bytes(),
        )])
    };
    // 12 x 4^12 = 201 million triangles: over the default 2^26, counted before subdividing.
    let err = refuse(format!(
        "Shape \"loopsubdiv\" \"integer nlevels\" [12] {CUBE}"
    ));
    let (over, pos) = over_budget(&err);
    assert_eq!(over.limit, Limit::Primitives);
    assert_eq!(over.reached, 12 * 4u64.pow(12));
    assert!(pos.starts_with("main.lxs:6:1"), "{pos}");
    // 30 levels: refused at the parameter before anything is counted.
    let e = refuse(format!(
        "Shape \"loopsubdiv\" \"integer nlevels\" [30] {CUBE}"
    ))
    .to_string();
    assert!(
        e.starts_with("main.lxs:6:")
            && e.contains("\"integer nlevels\"")
            && e.contains("at most 16"),
        "{e}"
    );
    // The same through a plain mesh's nsubdivlevels, as LuxRender 1.x reads it.
    let e = refuse(format!(
        "Shape \"trianglemesh\" \"integer nsubdivlevels\" [14] {CUBE}"
    ));
    assert_eq!(over_budget(&e).0.limit, Limit::Primitives);
    // nu x nv overflows 32 bits: an error about the count, not an allocation.
    let e = refuse(
        "Shape \"heightfield\" \"integer nu\" [2147483647] \"integer nv\" [2147483647] \"float Pz\" [0 0 0 0]".into(),
    )
    .to_string();
    assert!(
        e.starts_with("main.lxs:6:")
            && e.contains("\"float Pz\"")
            && e.contains("4611686014132420609"),
        "{e}"
    );
    let e = refuse(
        "Shape \"heightfield\" \"integer nu\" [1] \"integer nv\" [2] \"float Pz\" [0 0]".into(),
    )
    .to_string();
    assert!(
        e.contains("\"integer nu\"") && e.contains("at least 2"),
        "{e}"
    );
    let e =
        refuse("Shape \"heightfield\" \"integer nu\" [2] \"float Pz\" [0 0]".into()).to_string();
    assert!(
        e.starts_with("main.lxs:6:1") && e.contains("missing \"integer nv\""),
        "{e}"
    );
    // A P list that is not whole points.
    let e = refuse(
        "Shape \"loopsubdiv\" \"integer nlevels\" [2] \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1]".into(),
    )
    .to_string();
    assert!(
        e.starts_with("main.lxs:6:") && e.contains("\"point P\"") && e.contains("multiple of 3"),
        "{e}"
    );
    let e = refuse("Shape \"paraboloid\" \"float zmax\" [0]".into()).to_string();
    assert!(
        e.starts_with("main.lxs:6:") && e.contains("\"float zmax\""),
        "{e}"
    );
}
