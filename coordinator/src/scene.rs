//! Loading a scene, the same way for every subcommand: the main file's folder as the source of
//! the files it references, the parse, its warnings, and errors that name the file.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;
use yat_tracer::assets::FsSource;
use yat_tracer::desc::SceneDesc;
use yat_tracer::parse::parse_scene;

/// A scene file parsed, with where its files come from.
pub struct ParsedScene {
    /// The main file, as given.
    pub path: PathBuf,
    /// The main file's name: what the parse and the workers call it.
    pub main_name: String,
    /// The files the scene references, read from the main file's folder.
    pub source: FsSource,
    pub desc: SceneDesc,
    pub parse_time: Duration,
}

/// What loading does with the parser's warnings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Warnings {
    /// Print them on stderr.
    Print,
    /// Leave them in the description only, for the caller to show its own way or not at all.
    Keep,
}

impl ParsedScene {
    pub fn load(path: &Path, warnings: Warnings) -> anyhow::Result<Self> {
        let main_name = path
            .file_name()
            .and_then(|n| n.to_str())
            .with_context(|| format!("\"{}\" is not a scene file path", path.display()))?
            .to_string();
        let source = FsSource::for_main_file(path);
        let started = Instant::now();
        let desc = parse_scene(&main_name, &source)
            .with_context(|| format!("cannot load scene {}", path.display()))?;
        let parse_time = started.elapsed();
        if warnings == Warnings::Print {
            for w in &desc.warnings {
                eprintln!("{w}");
            }
        }
        Ok(Self {
            path: path.to_path_buf(),
            main_name,
            source,
            desc,
            parse_time,
        })
    }
}
