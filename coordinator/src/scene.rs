//! Loading a scene, the same way for every subcommand: the main file's folder as the source of
//! the files it references, the parse under the build budget, its warnings, and errors that
//! name the file; and building it for an in-process render under the same budget.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;
use yat_tracer::assets::FsSource;
use yat_tracer::budget::{BuildBudget, BuildGuard, Limit};
use yat_tracer::desc::SceneDesc;
use yat_tracer::diag::{Severity, Warning};
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene_guarded;
use yat_tracer::render::convergence::ConvergenceHalt;
use yat_tracer::render::sampling::Sampling;
use yat_tracer::render::{RenderScene, RenderSettings};

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
    /// What the scene may cost to parse and build here.
    pub budget: BuildBudget,
}

/// The differences from LuxRender's image on stderr, each at its position; of the warnings that
/// leave the image as LuxRender's (accepted differences, parameters without effect, notes) only
/// how many there are, which `yat check` lists.
fn print_warnings(path: &Path, warnings: &[Warning]) {
    let mut quiet = 0u64;
    for w in warnings {
        if w.severity == Severity::Differs {
            eprintln!("{w}");
        } else {
            quiet += w.occurrences();
        }
    }
    if quiet > 0 {
        eprintln!(
            "{}: {quiet} more statements or parameters that render as LuxRender's or are \
             documented differences: `yat check {}` lists them",
            path.display(),
            path.display()
        );
    }
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
    /// Loads the scene under the default build budget.
    pub fn load(path: &Path, warnings: Warnings) -> anyhow::Result<Self> {
        Self::load_within(path, warnings, BuildBudget::default())
    }

    /// Loads the scene, refusing it once it exceeds `budget`.
    pub fn load_within(
        path: &Path,
        warnings: Warnings,
        budget: BuildBudget,
    ) -> anyhow::Result<Self> {
        let main_name = path
            .file_name()
            .and_then(|n| n.to_str())
            .with_context(|| format!("\"{}\" is not a scene file path", path.display()))?
            .to_string();
        let source = FsSource::for_main_file(path);
        let started = Instant::now();
        let guard = BuildGuard {
            budget: &budget,
            ..BuildGuard::default()
        };
        let desc = parse_scene_guarded(&main_name, &source, guard)
            .with_context(|| format!("cannot load scene {}", path.display()))?;
        let parse_time = started.elapsed();
        if warnings == Warnings::Print {
            print_warnings(path, &desc.warnings);
        }
        Ok(Self {
            path: path.to_path_buf(),
            main_name,
            source,
            desc,
            parse_time,
            budget,
        })
    }

    /// Bytes the film of a render of `settings` sampled so takes here (a converging render's
    /// tests included): the coordinator's, whether it renders in-process or merges workers'
    /// units.
    pub fn film_bytes(&self, settings: &RenderSettings, sampling: &Sampling) -> u64 {
        let frame = settings.film_frame(&self.desc);
        let film = Film::memory_bytes(frame, sampling.adaptive().is_some());
        match sampling {
            Sampling::Converging(_) => film + ConvergenceHalt::memory_bytes(settings),
            _ => film,
        }
    }

    /// Fails unless the film of [`Self::film_bytes`] fits the memory budget with what the
    /// parse estimated for the scene.
    pub fn check_film(&self, settings: &RenderSettings, sampling: &Sampling) -> anyhow::Result<()> {
        let film = self.film_bytes(settings, sampling);
        self.desc
            .spent
            .clone()
            .spend(&self.budget, Limit::MemoryBytes, film)
            .with_context(|| {
                format!(
                    "cannot render {}: its {}x{} film ({}) with the scene",
                    self.path.display(),
                    settings.width,
                    settings.height,
                    Limit::MemoryBytes.amount(film)
                )
            })
    }

    /// Builds the scene for an in-process render, under the budget it was parsed with.
    pub fn build(&self, settings: &RenderSettings) -> anyhow::Result<RenderScene> {
        let guard = BuildGuard {
            budget: &self.budget,
            ..BuildGuard::default()
        };
        RenderScene::build_guarded(&self.desc, &self.source, settings, guard)
            .with_context(|| format!("cannot build {}", self.path.display()))
    }
}
