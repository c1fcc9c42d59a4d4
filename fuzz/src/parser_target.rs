//! The parser target: a scene (a main `.lxs` file and the files it may reference, held in
//! memory) mutated at byte and token level, parsed by the real parser through a
//! [`MemorySource`], its analytic shapes tessellated (the exporter's path), built with
//! [`RenderScene::build`] when it parses and is small, and one 8x8 unit of it rendered.
//!
//! Seeds: every `.lxs` in the project's `scenes/`, the hand-written snippets in
//! `fuzz/corpus/` (every statement kind), and the seed project's scenes when given, all read
//! at run time with the files they reference. Referenced files over [`MAX_FILE_BYTES`] are
//! cut at a statement boundary (scene text) or replaced by a small stand-in (meshes, images);
//! missing ones get a stand-in. Every input also carries the stand-in meshes and images of
//! [`crate::stand_ins`], so mutations that name them reach the PLY reader and image decoders.

use std::cell::Cell;
use std::collections::hash_map::DefaultHasher;
use std::collections::HashSet;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use fastrand::Rng;
use yat_tracer::assets::{AssetError, AssetSource, FsSource, MemorySource};
use yat_tracer::desc::{LatLongConvention, LightDesc, SceneDesc};
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{RenderScene, RenderSettings, WorkUnit};

use crate::campaign::{Outcome, Target};
use crate::mutate::{tokens, Mutator};
use crate::stand_ins;

/// Largest file in an input: seeds are cut to it, mutations never grow past it.
pub const MAX_FILE_BYTES: usize = 32 << 10;

/// Inputs kept besides the seeds because they parsed and reached a new outcome.
const MAX_GROWN_CORPUS: usize = 4096;
/// Inputs kept because they failed to parse in a new way (deeper errors are worth a base),
/// picked as a base one time in [`ERROR_POOL_ODDS`].
const MAX_ERROR_POOL: usize = 512;
const ERROR_POOL_ODDS: u32 = 16;

/// Scenes with more triangles or shapes than this are parsed but not built: building them is
/// slow without finding more (H4's build budgets bound them in the tracer).
const MAX_BUILD_TRIANGLES: u64 = 200_000;
const MAX_BUILD_SHAPES: usize = 20_000;
/// Sky lights a built input may hold: each is a 1024x512 table (about 0.1 s of CPU), and the
/// tracer's texel budget admits a thousand, so inputs that repeat a sky line would spend the
/// run tabulating skies; their parse is still fuzzed, and one or two skies are built.
const MAX_BUILD_SKIES: usize = 2;

/// Shapes tessellated per input, and how finely.
const MAX_TESSELLATED_SHAPES: usize = 64;
const TESSELLATION_SEGMENTS: u32 = 12;

/// The settings every input is built and rendered with: small and fast.
pub(crate) fn render_settings() -> RenderSettings {
    RenderSettings {
        width: 8,
        height: 8,
        spp: 2,
        max_depth: 4,
        seed: 1,
        latlong: LatLongConvention::LuxRender,
        transport: Default::default(),
        aovs: Default::default(),
    }
}

pub(crate) const UNIT: WorkUnit = WorkUnit {
    index: 0,
    x0: 0,
    y0: 0,
    x1: 8,
    y1: 8,
    sample_start: 0,
    sample_end: 2,
    mask: None,
};

/// Words the mutator inserts: statement keywords, type names, parameter declarations, the
/// input's file names, and PLY header lines.
const DICTIONARY: &[&str] = &[
    "Identity",
    "Translate 1 2 3",
    "Scale 0 0 0",
    "Rotate 90 0 0 1",
    "LookAt",
    "Transform",
    "ConcatTransform",
    "CoordinateSystem \"a\"",
    "CoordSysTransform \"a\"",
    "MotionBegin [0 1]",
    "MotionEnd",
    "AttributeBegin",
    "AttributeEnd",
    "TransformBegin",
    "TransformEnd",
    "WorldBegin",
    "WorldEnd",
    "Include",
    "Camera",
    "Film",
    "PixelFilter",
    "Sampler",
    "SurfaceIntegrator",
    "Accelerator",
    "Renderer",
    "VolumeIntegrator",
    "Volume",
    "Exterior",
    "Texture",
    "Material",
    "MakeNamedMaterial",
    "NamedMaterial",
    "LightSource",
    "AreaLightSource",
    "Shape",
    "ReverseOrientation",
    "ObjectBegin \"o\"",
    "ObjectEnd",
    "ObjectInstance \"o\"",
    "\"matte\"",
    "\"glossy\"",
    "\"glass\"",
    "\"metal\"",
    "\"mix\"",
    "\"null\"",
    "\"mirror\"",
    "\"mattetranslucent\"",
    "\"roughglass\"",
    "\"metal2\"",
    "\"imagemap\"",
    "\"checkerboard\"",
    "\"constant\"",
    "\"scale\"",
    "\"blackbody\"",
    "\"fresnel\"",
    "\"color\"",
    "\"float\"",
    "\"point\"",
    "\"spot\"",
    "\"distant\"",
    "\"infinite\"",
    "\"area\"",
    "\"sphere\"",
    "\"disk\"",
    "\"cylinder\"",
    "\"plane\"",
    "\"trianglemesh\"",
    "\"plymesh\"",
    "\"perspective\"",
    "\"orthographic\"",
    "\"fisheye\"",
    "\"fleximage\"",
    "\"mitchell\"",
    "\"gaussian\"",
    "\"sinc\"",
    "\"path\"",
    "\"float radius\"",
    "\"integer indices\"",
    "\"point P\"",
    "\"normal N\"",
    "\"float uv\"",
    "\"color Kd\"",
    "\"texture Kd\"",
    "\"float fov\"",
    "\"integer xresolution\"",
    "\"integer yresolution\"",
    "\"string filename\"",
    "\"string mapname\"",
    "\"string mapping\"",
    "\"float screenwindow\"",
    "\"integer dimension\"",
    "\"string namedmaterial1\"",
    "\"texture amount\"",
    "\"bool architectural\"",
    "\"integer maxdepth\"",
    "\"integer pixelsamples\"",
    "\"float coneangle\"",
    "\"color L\"",
    "\"float gain\"",
    "\"float power\"",
    "\"spectrum Kd\"",
    "\"vector v1\"",
    "\"integer quadindices\"",
    "\"string type\"",
    "\"float uroughness\"",
    "\"string wrap\"",
    "\"float gamma\"",
    "\"float temperature\"",
    "\"string name\"",
    "\"bool\"",
    "\"true\"",
    "\"false\"",
    "\"mesh.ply\"",
    "\"mesh-bin.ply\"",
    "\"tex.png\"",
    "\"tex.jpg\"",
    "\"tex.exr\"",
    "\"env.hdr\"",
    "\"inc.lxo\"",
    "\"main.lxs\"",
    "\"\"",
    "\"../../etc/passwd\"",
    "\"/\"",
    "element vertex 4294967295",
    "element face 1000000000",
    "property float x",
    "property list uchar int vertex_indices",
    "property list uint uint vertex_indices",
    "format binary_big_endian 1.0",
    "format ascii 1.0",
    "end_header",
];

/// A scene input: the main file first, then every other file it may reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    pub files: Vec<(String, Vec<u8>)>,
}

impl Case {
    fn main(&self) -> &str {
        &self.files[0].0
    }

    fn is_binary(&self, i: usize) -> bool {
        stand_ins::is_binary(&self.files[i].0)
    }

    /// The main file and the files whose names appear in the case's scene text.
    fn used_files(&self) -> Vec<usize> {
        let text: Vec<&[u8]> = (0..self.files.len())
            .filter(|&i| !self.is_binary(i))
            .map(|i| &self.files[i].1[..])
            .collect();
        let named = |name: &[u8]| {
            text.iter()
                .any(|t| t.windows(name.len()).any(|w| w == name))
        };
        (0..self.files.len())
            .filter(|&i| i == 0 || named(self.files[i].0.as_bytes()))
            .collect()
    }

    /// The case as one text, readable when it is scene text: each file after a header line
    /// `=== <name> <length>`; [`Case::decode`] reads it back.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for (name, bytes) in &self.files {
            out.extend_from_slice(format!("=== {name} {}\n", bytes.len()).as_bytes());
            out.extend_from_slice(bytes);
            out.push(b'\n');
        }
        out
    }

    pub fn decode(mut data: &[u8]) -> Option<Self> {
        let mut files = Vec::new();
        while !data.is_empty() {
            let end = data.iter().position(|&b| b == b'\n')?;
            let header = std::str::from_utf8(&data[..end])
                .ok()?
                .strip_prefix("=== ")?;
            let (name, len) = header.rsplit_once(' ')?;
            let len: usize = len.parse().ok()?;
            let body = data.get(end + 1..end + 1 + len)?;
            files.push((name.to_string(), body.to_vec()));
            data = data.get(end + 2 + len..)?;
        }
        (!files.is_empty()).then_some(Self { files })
    }
}

/// Where the seeds come from.
#[derive(Clone, Debug, Default)]
pub struct SeedFolders {
    /// Folders searched (recursively) for `.lxs` files.
    pub scenes: Vec<PathBuf>,
    /// Hand-written snippets: every `.lxs` here is a seed, and every other file is given to
    /// every input under its own name (e.g. `inc.lxo`).
    pub snippets: Option<PathBuf>,
}

/// Inputs counted by how far they got.
#[derive(Default)]
struct Reached {
    parse_errors: Cell<u64>,
    parsed: Cell<u64>,
    too_big: Cell<u64>,
    build_errors: Cell<u64>,
    rendered: Cell<u64>,
}

fn bump(counter: &Cell<u64>) {
    counter.set(counter.get() + 1);
}

pub struct ParserTarget {
    reached: Reached,
    corpus: Vec<Case>,
    error_pool: Vec<Case>,
    seeds: usize,
    seen: HashSet<u64>,
    mutator: Mutator,
}

impl ParserTarget {
    /// A target seeded from `folders`; fails if no seed is found.
    pub fn new(folders: &SeedFolders) -> std::io::Result<Self> {
        let mut shared = stand_ins::files();
        let mut seeds = Vec::new();
        if let Some(dir) = &folders.snippets {
            for path in files_in(dir)? {
                let name = path.file_name().unwrap_or_default().to_string_lossy();
                if name.ends_with(".lxs") {
                    seeds.push(path);
                } else {
                    shared.push((name.into_owned(), std::fs::read(&path)?));
                }
            }
        }
        for dir in &folders.scenes {
            seeds.extend(
                files_in(dir)?
                    .into_iter()
                    .filter(|p| p.extension().is_some_and(|e| e == "lxs")),
            );
        }
        seeds.sort();
        let mut corpus = Vec::with_capacity(seeds.len());
        for path in &seeds {
            let mut case = load_seed(path)?;
            for (name, bytes) in &shared {
                if !case.files.iter().any(|(n, _)| n == name) {
                    case.files.push((name.clone(), bytes.clone()));
                }
            }
            corpus.push(case);
        }
        if corpus.is_empty() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "no .lxs seed found in the seed folders",
            ));
        }
        Ok(Self {
            reached: Reached::default(),
            error_pool: Vec::new(),
            seeds: corpus.len(),
            corpus,
            seen: HashSet::new(),
            mutator: Mutator::new(MAX_FILE_BYTES, DICTIONARY),
        })
    }

    pub fn seed_count(&self) -> usize {
        self.seeds
    }
}

impl Target for ParserTarget {
    type Input = Case;

    fn name(&self) -> &'static str {
        "parser"
    }

    fn generate(&mut self, rng: &mut Rng) -> Case {
        let mut case = if !self.error_pool.is_empty() && rng.u32(0..ERROR_POOL_ODDS) == 0 {
            self.error_pool[rng.usize(0..self.error_pool.len())].clone()
        } else {
            self.corpus[rng.usize(0..self.corpus.len())].clone()
        };
        // A file the scene uses: the main file, or one its text names (an include, a mesh,
        // an image); scene text three times as often as meshes and images.
        let used = case.used_files();
        let text: Vec<usize> = used
            .iter()
            .copied()
            .filter(|&i| !case.is_binary(i))
            .collect();
        let binary: Vec<usize> = used
            .iter()
            .copied()
            .filter(|&i| case.is_binary(i))
            .collect();
        let target = if binary.is_empty() || rng.u8(0..4) > 0 {
            text[rng.usize(0..text.len())]
        } else {
            binary[rng.usize(0..binary.len())]
        };
        // Splice from a file of the same sort in another input.
        let other = &self.corpus[rng.usize(0..self.corpus.len())];
        let same_sort: Vec<&(String, Vec<u8>)> = other
            .files
            .iter()
            .filter(|(n, _)| stand_ins::is_binary(n) == case.is_binary(target))
            .collect();
        let other: &[u8] = match same_sort.len() {
            0 => &[],
            n => &same_sort[rng.usize(0..n)].1,
        };
        self.mutator.mutate(rng, &mut case.files[target].1, other);
        case
    }

    fn execute(&self, case: &Case) -> Outcome {
        let mut source = MemorySource::new();
        for (name, bytes) in &case.files {
            source.insert(name.clone(), Arc::from(&bytes[..]));
        }
        let mut features = Vec::new();
        let desc = match parse_scene(case.main(), &source) {
            Ok(desc) => desc,
            Err(e) => {
                bump(&self.reached.parse_errors);
                features.push(skeleton_hash("parse error", &e.to_string()));
                return Outcome {
                    features,
                    parsed: false,
                };
            }
        };
        bump(&self.reached.parsed);
        features.extend(
            desc.warnings
                .iter()
                .map(|w| skeleton_hash("warning", &w.message)),
        );
        // The exporter's path: analytic shapes as triangles.
        for shape in desc.shapes.iter().take(MAX_TESSELLATED_SHAPES) {
            if let Some(mesh) = shape.geometry.tessellate(TESSELLATION_SEGMENTS) {
                features.push(skeleton_hash(
                    "tessellated",
                    &format!("{}", mesh.indices.is_empty()),
                ));
            }
        }
        if is_too_big_to_build(&desc) {
            bump(&self.reached.too_big);
            features.push(skeleton_hash("not built", ""));
            return Outcome {
                features,
                parsed: true,
            };
        }
        match RenderScene::build(&desc, &source, &render_settings()) {
            Ok(scene) => {
                bump(&self.reached.rendered);
                let (buffer, stats) = scene.render_unit(&UNIT);
                let finite = buffer.rgb.iter().flatten().all(|v| v.is_finite());
                features.push(skeleton_hash(
                    "rendered",
                    &format!("finite {finite} dropped {}", stats.dropped > 0),
                ));
            }
            Err(e) => {
                bump(&self.reached.build_errors);
                features.push(skeleton_hash("build error", &e.to_string()));
            }
        }
        Outcome {
            features,
            parsed: true,
        }
    }

    fn learn(&mut self, case: Case, outcome: Outcome) {
        let mut new = false;
        for f in outcome.features {
            new |= self.seen.insert(f);
        }
        if !new {
            return;
        }
        if !outcome.parsed {
            if self.error_pool.len() < MAX_ERROR_POOL {
                self.error_pool.push(case);
            } else {
                let slot = self.seen.len() % MAX_ERROR_POOL;
                self.error_pool[slot] = case;
            }
        } else if self.corpus.len() < self.seeds + MAX_GROWN_CORPUS {
            self.corpus.push(case);
        } else {
            // Replace a grown input chosen by the feature hash: deterministic, no RNG needed.
            let slot = self.seeds + (self.seen.len() % MAX_GROWN_CORPUS);
            self.corpus[slot] = case;
        }
    }

    fn shrink(&self, case: &Case) -> Vec<Case> {
        let mut out = Vec::new();
        for i in 1..case.files.len() {
            let mut smaller = case.clone();
            smaller.files.remove(i);
            out.push(smaller);
        }
        for (i, (name, bytes)) in case.files.iter().enumerate() {
            let pieces = if stand_ins::is_binary(name) {
                byte_chunks(bytes)
            } else {
                let mut pieces = line_chunks(bytes);
                let t = tokens(bytes);
                if t.len() <= 400 {
                    pieces.extend(t);
                }
                pieces
            };
            for piece in pieces {
                let mut smaller = case.clone();
                smaller.files[i].1.drain(piece);
                out.push(smaller);
            }
        }
        out
    }

    fn save(&self, case: &Case, path: &Path) -> std::io::Result<PathBuf> {
        let path = path.with_extension("case");
        std::fs::write(&path, case.encode())?;
        Ok(path)
    }

    fn progress(&self) -> String {
        let r = &self.reached;
        format!(
            "{} parse errors, {} parsed ({} too big to build, {} build errors, {} built and \
             rendered); corpus {} ({} seeds), {} distinct outcomes",
            r.parse_errors.get(),
            r.parsed.get(),
            r.too_big.get(),
            r.build_errors.get(),
            r.rendered.get(),
            self.corpus.len(),
            self.seeds,
            self.seen.len()
        )
    }
}

fn is_too_big_to_build(desc: &SceneDesc) -> bool {
    let triangles: u64 = desc
        .shapes
        .iter()
        .map(|s| s.geometry.primitive_count())
        .sum();
    let skies = desc
        .lights
        .iter()
        .filter(|l| matches!(l, LightDesc::Sky(_)))
        .count();
    triangles > MAX_BUILD_TRIANGLES
        || desc.shapes.len() > MAX_BUILD_SHAPES
        || skies > MAX_BUILD_SKIES
}

/// A hash of what a message says: its first letters outside quotes and backticks, so
/// messages that differ only in positions, numbers, names, quoted tokens and the details a
/// decoder library appends count as one outcome.
fn skeleton_hash(kind: &str, message: &str) -> u64 {
    const SKELETON_CHARS: usize = 48;
    let mut hasher = DefaultHasher::new();
    kind.hash(&mut hasher);
    let mut quote = None;
    let mut hashed = 0;
    for c in message.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == '"' || c == '`' => quote = Some(c),
            None if c.is_ascii_alphabetic() || c == ' ' => {
                c.hash(&mut hasher);
                hashed += 1;
                if hashed == SKELETON_CHARS {
                    break;
                }
            }
            None => {}
        }
    }
    hasher.finish()
}

/// Ranges of whole lines to try deleting: halves, quarters, ... down to single lines.
fn line_chunks(bytes: &[u8]) -> Vec<std::ops::Range<usize>> {
    let mut starts: Vec<usize> = std::iter::once(0)
        .chain(
            bytes
                .iter()
                .enumerate()
                .filter(|(_, &b)| b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .filter(|&s| s < bytes.len())
        .collect();
    starts.push(bytes.len());
    let lines = starts.len() - 1;
    let mut out = Vec::new();
    let mut size = lines.div_ceil(2).max(1);
    loop {
        for first in (0..lines).step_by(size) {
            let last = (first + size).min(lines);
            out.push(starts[first]..starts[last]);
        }
        if size == 1 {
            break;
        }
        size = size.div_ceil(2);
    }
    out
}

/// Ranges of bytes of a binary file to try deleting, from the end (payload) backwards.
fn byte_chunks(bytes: &[u8]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut size = bytes.len().div_ceil(2).max(1);
    while size >= 4 {
        let mut end = bytes.len();
        while end >= size {
            out.push(end - size..end);
            end -= size;
        }
        size /= 2;
    }
    out
}

/// Every file under `dir`, recursively, sorted.
fn files_in(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d)? {
            let path = entry?.path();
            if path.is_dir() {
                pending.push(path);
            } else {
                out.push(path);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// A seed scene with every file its parse reads, each cut or replaced to stay small.
fn load_seed(main: &Path) -> std::io::Result<Case> {
    let name = main
        .file_name()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned();
    let source = RecordingSource {
        fs: FsSource::for_main_file(main),
        read: Mutex::new(Vec::new()),
    };
    // Errors are fine: the seed is what the parser read, whatever it thought of it.
    let _ = parse_scene(&name, &source);
    let mut files = source.read.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(i) = files.iter().position(|(n, _)| *n == name) {
        let main_file = files.remove(i);
        files.insert(0, main_file);
    } else {
        files.insert(0, (name, std::fs::read(main)?));
    }
    Ok(Case { files })
}

/// Reads files from disk and records what was read, small: large scene text cut at a
/// statement, large or missing meshes and images replaced by stand-ins.
struct RecordingSource {
    fs: FsSource,
    read: Mutex<Vec<(String, Vec<u8>)>>,
}

impl AssetSource for RecordingSource {
    fn read(&self, written: &str) -> Result<Arc<[u8]>, AssetError> {
        let binary = stand_ins::is_binary(written);
        let bytes = match self.fs.read(written) {
            Ok(bytes) if bytes.len() <= MAX_FILE_BYTES => bytes.to_vec(),
            Ok(bytes) if !binary => cut_at_statement(&bytes, MAX_FILE_BYTES).to_vec(),
            Ok(_) | Err(AssetError::NotFound { .. }) => stand_ins::for_name(written),
            Err(e) => return Err(e),
        };
        let mut read = self.read.lock().unwrap_or_else(|e| e.into_inner());
        if !read.iter().any(|(n, _)| n == written) {
            read.push((written.to_string(), bytes.clone()));
        }
        Ok(bytes.into())
    }
}

/// The longest prefix of scene text up to `max` bytes that ends before a statement (a line
/// starting with a capital letter).
fn cut_at_statement(text: &[u8], max: usize) -> &[u8] {
    let limit = max.min(text.len());
    let cut = (1..=limit)
        .rev()
        .find(|&i| text[i - 1] == b'\n' && text.get(i).is_some_and(u8::is_ascii_uppercase))
        .unwrap_or(0);
    &text[..cut]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_case_encodes_and_decodes_to_itself() {
        let case = Case {
            files: vec![
                ("main.lxs".into(), b"WorldBegin\n=== x 3\n".to_vec()),
                ("dir/a b.ply".into(), vec![0, 10, 255]),
                ("empty".into(), Vec::new()),
            ],
        };
        assert_eq!(Case::decode(&case.encode()), Some(case));
        assert_eq!(Case::decode(b"=== x 10\nshort"), None);
    }

    #[test]
    fn scene_text_is_cut_before_a_statement() {
        let text = b"Shape \"x\"\n  \"point P\" [1 2 3]\nShape \"y\"\n 4 5\n";
        assert_eq!(
            cut_at_statement(text, 30),
            b"Shape \"x\"\n  \"point P\" [1 2 3]\n"
        );
        assert_eq!(cut_at_statement(text, 5), b"");
    }

    #[test]
    fn line_chunks_cover_halves_then_single_lines() {
        let chunks = line_chunks(b"a\nb\nc\n");
        assert_eq!(chunks, [0..4, 4..6, 0..2, 2..4, 4..6]);
    }
}
