//! A render job as the executors see it (made by [`crate::render::render`]): the scene, the
//! settings that decide the image, and the outputs (the final image, the interim preview and
//! checkpoint); and what rendering it yields, whoever renders it.

use std::path::{Component, Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;
use yat_tracer::film::{Film, OutputFile};
use yat_tracer::render::adaptive::{self, Round};
use yat_tracer::render::sampling::{RoundsEnd, Sampling};
use yat_tracer::render::unit::FilmFrame;
use yat_tracer::render::{RenderSettings, UnitStats, WorkUnit};

use crate::checkpoint::Checkpoint;
use crate::exec::progress_log::ProgressLog;
use crate::interim::InterimOutputs;
use crate::scene::ParsedScene;
use crate::shutdown::{Interrupt, Interrupted};

/// What a render needs, whoever renders it.
pub struct RenderJob {
    pub scene: ParsedScene,
    pub settings: RenderSettings,
    /// Every pixel spp samples, or rounds until the noise is under a threshold (adaptive) or
    /// the image stops changing (converging); settings.spp is then the most any pixel gets.
    pub sampling: Sampling,
    /// Where to write the sample map of an adaptive render, at the end.
    pub sample_map: Option<PathBuf>,
    /// The image's path: the PNG's, when the Film writes one; the TGA and the EXR it asks for
    /// go beside it (its extension replaced by theirs), as do the preview and the checkpoint.
    pub output_png: PathBuf,
    /// `--exr`: also write an EXR where the Film writes none (`FilmOutputs::files`).
    pub exr: bool,
    pub quiet: bool,
    /// Progress lines for logs and machines (the bar aside).
    pub progress_log: ProgressLog,
    /// The preview and the checkpoint, written as the render goes.
    pub interim: InterimOutputs,
    /// Once set (by Ctrl-C, SIGTERM or the caller), the render stops, saving what it can (the
    /// checkpoint, the preview) and saying what is lost.
    pub interrupt: Interrupt,
    /// `--time-limit` or the scene's `halttime`: when the render stops (an adaptive one at a
    /// round boundary).
    pub deadline: Option<Deadline>,
}

/// When a render stops, and what set that time (for the messages).
#[derive(Clone, Debug)]
pub struct Deadline {
    pub at: Instant,
    /// `--time-limit` or the scene's `halttime`.
    pub set_by: String,
}

impl Deadline {
    /// `seconds` from now, set by `set_by`; None for 0 (no limit) or a time too far ahead to
    /// represent.
    pub fn after(seconds: Duration, set_by: impl Into<String>) -> Option<Self> {
        if seconds.is_zero() {
            return None;
        }
        Some(Self {
            at: Instant::now().checked_add(seconds)?,
            set_by: set_by.into(),
        })
    }
}

/// What a render that stops short says when nothing was merged.
const NOTHING_RENDERED: &str = "nothing had been rendered yet";

/// Why a render with a time limit stopped short (its executor's error, turned into an outcome
/// by [`RenderJob::timed_out`]).
#[derive(Debug, thiserror::Error)]
#[error("the time limit was reached")]
pub struct TimeLimitReached;

/// An adaptive render's last completed round, kept when the render has a time limit: the image
/// it writes if the limit comes in the middle of the next round.
pub struct CompletedRound {
    film: Film,
    round: Round,
}

/// The endings of the files a render writes beside its output `X.png`: `X.preview.png`,
/// `X.resume`, `X.tga`, `X.exr`. An output named so would be overwritten by, or overwrite, the
/// side file of another output (or its own: `-o x.resume` is its own checkpoint).
const SIDE_FILE_ENDINGS: [&str; 4] = [".preview.png", ".resume", ".tga", ".exr"];

/// Refuses an output path that collides with the side files of a render.
pub fn check_output_path(output_png: &Path) -> anyhow::Result<()> {
    let name = output_png
        .file_name()
        .map(|n| n.to_string_lossy())
        .with_context(|| format!("the output {} names no file", output_png.display()))?;
    if let Some(ending) = SIDE_FILE_ENDINGS.iter().find(|e| name.ends_with(*e)) {
        anyhow::bail!(
            "the output {} ends in \"{ending}\", the name a render gives the preview, the \
             checkpoint, the TGA or the EXR it writes beside its image: choose a name ending in \
             .png",
            output_png.display()
        );
    }
    Ok(())
}

/// The output a scene's `Film "string filename"` asks for when `-o` is absent: its file name
/// plus `.png`, in the current folder (and its TGA and EXR beside it, as LuxRender names them:
/// the file name plus `.tga`, `.exr`). A scene is not trusted to choose a folder: a filename
/// with one (`../../x`, `/etc/x`) keeps only its last part, with the warning returned.
pub fn film_output_path(filename: &str) -> anyhow::Result<(PathBuf, Option<String>)> {
    let path = Path::new(filename);
    let Some(Component::Normal(name)) = path.components().next_back() else {
        anyhow::bail!(
            "the scene's Film filename \"{filename}\" names no file: give the output with -o"
        );
    };
    let output = PathBuf::from(format!("{}.png", name.to_string_lossy()));
    let warning = (path.components().count() > 1).then(|| {
        format!(
            "the scene's Film filename \"{filename}\" names a folder; a scene may only write to \
             the current folder: writing {} (-o chooses another path)",
            output.display()
        )
    });
    Ok((output, warning))
}

/// The merged result of a render.
pub struct RenderOutcome {
    pub film: Film,
    pub stats: UnitStats,
    /// Building the scene in this process, if it was (workers build their own).
    pub build: Option<SceneBuild>,
    /// An adaptive render's last round: each block's samples per pixel.
    pub round: Option<Round>,
    /// How a complete render's rounds ended (a converging one's last test).
    pub ended: Option<RoundsEnd>,
    /// False for a render stopped by its time limit: its checkpoint stays for the rest.
    pub complete: bool,
}

/// What building the scene cost.
pub struct SceneBuild {
    pub time: Duration,
    pub triangles: usize,
    /// The continuations camera paths take at their first broad vertex (the build's pilot
    /// chose them, its time in `time`).
    pub first_vertex_branches: usize,
}

impl RenderJob {
    /// The frame of the render's film (its size, the border of every unit's sample buffer,
    /// whether units carry light splats), as every node derives it.
    pub fn frame(&self) -> FilmFrame {
        self.settings.film_frame(&self.scene.desc)
    }

    /// The render to start from: the checkpoint a previous run of this render left, or nothing.
    pub fn resume(&self) -> Checkpoint {
        let sampling = &self.sampling;
        match &self.interim.checkpoint {
            Some(file) => file.resume(&self.settings, self.frame(), sampling, self.quiet),
            None => Checkpoint::new(&self.settings, self.frame(), sampling),
        }
    }

    /// Whether the render's time limit has passed.
    pub fn out_of_time(&self) -> bool {
        self.deadline
            .as_ref()
            .is_some_and(|d| Instant::now() >= d.at)
    }

    /// At a round boundary (every unit of the checkpoint's round merged) of a render with a time
    /// limit: the round's film and samples, to write if the limit comes before the next one is
    /// complete.
    pub fn keep_round(&self, checkpoint: &Checkpoint) -> Option<CompletedRound> {
        let round = checkpoint.adaptive_round()?;
        (self.deadline.is_some() && checkpoint.is_complete()).then(|| CompletedRound {
            film: checkpoint.film().clone(),
            round: round.clone(),
        })
    }

    /// The outcome of a render its time limit stopped: the checkpoint saved with everything
    /// merged, and the image of the last round completed (an error when none was); a uniform
    /// render's image holds every sample merged, which its message lists.
    pub fn timed_out(
        &self,
        checkpoint: &Checkpoint,
        completed: Option<CompletedRound>,
        stats: UnitStats,
        build: Option<SceneBuild>,
    ) -> anyhow::Result<RenderOutcome> {
        let set_by = self
            .deadline
            .as_ref()
            .map_or("the time limit", |d| d.set_by.as_str());
        let kept = self.keep(checkpoint);
        // Every pixel alike (one plan, or converging rounds): the image of every sample merged.
        let uniform = checkpoint.adaptive_round().is_none();
        if uniform && kept.is_some() {
            let held = self.merged_samples(checkpoint);
            if !self.quiet {
                eprintln!(
                    "{set_by} reached: writing the image of the samples merged: {held}; {}",
                    kept.as_deref().unwrap_or_default()
                );
            }
            return Ok(RenderOutcome {
                film: checkpoint.film().clone(),
                stats,
                build,
                round: None,
                ended: None,
                complete: false,
            });
        }
        let kept = kept.unwrap_or_else(|| NOTHING_RENDERED.into());
        let Some(completed) = completed else {
            let unit = if uniform { "any unit" } else { "a round" };
            anyhow::bail!("{set_by} reached before {unit} was complete: no image; {kept}");
        };
        if !self.quiet {
            eprintln!(
                "{set_by} reached: writing the image of round {} (the render ending there); \
                 {kept}",
                completed.round.index
            );
        }
        Ok(RenderOutcome {
            film: completed.film,
            stats,
            build,
            round: Some(completed.round),
            ended: None,
            complete: false,
        })
    }

    /// The error of a render that stopped short, after saving what it merged and saying how to
    /// resume it.
    pub fn stopped(&self, checkpoint: &Checkpoint, why: anyhow::Error) -> anyhow::Error {
        let kept = self.keep(checkpoint);
        match (self.interrupt.is_set(), kept) {
            (true, kept) => Interrupted {
                cause: self.interrupt.cause(),
                kept: kept.unwrap_or_else(|| NOTHING_RENDERED.into()),
            }
            .into(),
            (false, Some(kept)) => anyhow::anyhow!("{why:#}\n{kept}"),
            (false, None) => why,
        }
    }

    /// Saves what a render that stops short merged: the checkpoint, for the same command to
    /// resume, and the preview (every merged unit in it); says where, or, with checkpoints off,
    /// that the merged samples are lost to the next run (and which preview shows them). None
    /// when nothing was merged.
    fn keep(&self, checkpoint: &Checkpoint) -> Option<String> {
        let something =
            checkpoint.done_count() > 0 || checkpoint.rounds().index().is_some_and(|i| i > 0);
        if !something {
            return None;
        }
        // The best image so far, every merged unit in it: the preview, when previews are on.
        let preview = crate::interim::DueOutputs {
            preview: true,
            checkpoint: false,
            status_image: self.interim.status.serving(),
        };
        let failed = self
            .interim
            .stage(preview, checkpoint, &self.scene.desc.film)
            .finish();
        let preview = self.interim.preview.as_ref().filter(|_| failed.is_empty());
        for e in failed {
            eprintln!("{e:#}");
        }
        let (done, total) = checkpoint.samples(&self.settings);
        let share = format!(
            "{:.1}% of the samples{}",
            100.0 * done as f64 / total.max(1) as f64,
            if self.sampling.has_rounds() {
                " (at most)"
            } else {
                ""
            },
        );
        Some(match &self.interim.checkpoint {
            Some(file) => match file.save(checkpoint) {
                Ok(()) => format!(
                    "{share} are kept in {}; the same command resumes the render",
                    file.path().display()
                ),
                Err(e) => format!("{e:#}"),
            },
            None => format!(
                "checkpoints are off (--checkpoint-every 0), so the {share} merged ({done} \
                 samples) are lost: the same command starts over{}",
                preview.map_or(String::new(), |p| format!(
                    "; {} shows them",
                    p.path().display()
                ))
            ),
        })
    }

    /// The files the render writes at the end and where: those the Film's `write_*` ask for
    /// (and `--exr`'s), the PNG at [`Self::output_png`], the others beside it.
    pub fn output_files(&self) -> Vec<(OutputFile, PathBuf)> {
        output_files(
            &self.output_png,
            &self.scene.desc.film.outputs.files(self.exr),
        )
    }

    /// Writes the final image, every file the Film asks for (and the EXR of `--exr`) exactly
    /// the same way for every executor, and the sample map when asked; then removes the
    /// interim outputs they replace (but the checkpoint of a render its time limit stopped).
    pub fn write_final(&self, outcome: &RenderOutcome) -> anyhow::Result<()> {
        let image = outcome.film.image(&self.scene.desc.film);
        for (file, path) in self.output_files() {
            image
                .write(&file, &path)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let (Some(path), Some(round)) = (&self.sample_map, &outcome.round) {
            let (map, least, most) = adaptive::sample_map(round, &self.settings);
            map.save_with_format(path, image::ImageFormat::Png)
                .with_context(|| format!("cannot write {}", path.display()))?;
            if !self.quiet {
                println!(
                    "wrote the sample map {}: samples per pixel on a log scale, from {least} \
                     (darkest grey) to {most} (white), one grey step per doubling",
                    path.display()
                );
            }
        }
        if outcome.complete {
            self.interim.remove();
        }
        Ok(())
    }
}

impl RenderJob {
    /// Which samples the merged units of a render of every pixel alike hold, exactly: of a
    /// uniform plan, or of the converging rounds before the one under way and its units.
    fn merged_samples(&self, checkpoint: &Checkpoint) -> String {
        let units = checkpoint.units(&self.settings);
        let is_done = |u: &WorkUnit| checkpoint.is_done(u);
        match (&self.sampling, checkpoint.rounds().index()) {
            (Sampling::Converging(halt), Some(round)) if round > 0 => {
                let before = halt
                    .round_range(round, self.settings.spp)
                    .map_or(0, |r| r.0);
                let this_round = merged_samples(&units, is_done);
                match this_round.strip_prefix("no sample of every pixel") {
                    Some(rest) => format!("samples 0..{before} of every pixel{rest}"),
                    None => this_round,
                }
            }
            _ => merged_samples(&units, is_done),
        }
    }
}

/// Where each of `files` goes for an image at `output_png`: the PNG there, the others beside
/// it with their own extensions.
pub fn output_files(output_png: &Path, files: &[OutputFile]) -> Vec<(OutputFile, PathBuf)> {
    files
        .iter()
        .map(|&file| {
            let path = match file {
                OutputFile::Png { .. } => output_png.to_path_buf(),
                _ => output_png.with_extension(file.extension()),
            };
            (file, path)
        })
        .collect()
}

/// Which samples the merged units of a uniform plan hold, exactly: the sample ranges every
/// pixel has, then each later range some tiles have, with how many of its tiles ("samples
/// 0..64 of every pixel; 64..128 in 12 of 40 tiles"). The plan orders units by sample range.
pub fn merged_samples(units: &[WorkUnit], is_done: impl Fn(&WorkUnit) -> bool) -> String {
    // (sample range, its tiles, of them merged), in the plan's order.
    let mut ranges: Vec<((u32, u32), usize, usize)> = Vec::new();
    for unit in units {
        let range = (unit.sample_start, unit.sample_end);
        let merged = usize::from(is_done(unit));
        match ranges.last_mut() {
            Some((last, tiles, done)) if *last == range => {
                *tiles += 1;
                *done += merged;
            }
            _ => ranges.push((range, 1, merged)),
        }
    }
    let whole = ranges
        .iter()
        .take_while(|(_, tiles, done)| done == tiles)
        .count();
    let mut parts = vec![match whole {
        0 => "no sample of every pixel".to_string(),
        n => format!("samples 0..{} of every pixel", ranges[n - 1].0 .1),
    }];
    for ((start, end), tiles, done) in &ranges[whole..] {
        if *done > 0 {
            parts.push(format!("{start}..{end} in {done} of {tiles} tiles"));
        }
    }
    parts.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_named_like_side_files_are_refused() {
        for bad in [
            "x.resume",
            "a/x.preview.png",
            "x.exr",
            "x.tga",
            "/tmp/y.resume",
        ] {
            let err = check_output_path(Path::new(bad)).unwrap_err().to_string();
            assert!(err.contains("choose a name"), "{bad}: {err}");
        }
        for good in ["x.png", "dir/x.png", "x", "resume.png", "x.preview"] {
            check_output_path(Path::new(good)).unwrap();
        }
        assert!(check_output_path(Path::new("/")).is_err());
    }

    #[test]
    fn a_film_filename_is_confined_to_the_current_folder() {
        assert_eq!(
            film_output_path("render").unwrap(),
            (PathBuf::from("render.png"), None)
        );
        for hostile in ["../../x", "/etc/x", "a/b/x", "./x/"] {
            let (path, warning) = film_output_path(hostile).unwrap();
            assert_eq!(path, PathBuf::from("x.png"), "{hostile}");
            assert!(warning.unwrap().contains("current folder"), "{hostile}");
        }
        for nothing in ["", "..", "/", "a/.."] {
            assert!(film_output_path(nothing).is_err(), "{nothing:?}");
        }
    }

    /// The merged units of a plan of 3 sample ranges over 4 tiles, said exactly: the ranges
    /// every pixel has, then the tiles of each later range merged.
    #[test]
    fn merged_samples_name_the_ranges_and_tiles_held() {
        let units: Vec<WorkUnit> = (0..12u32)
            .map(|index| WorkUnit {
                index,
                x0: (index % 4) * 16,
                y0: 0,
                x1: (index % 4) * 16 + 16,
                y1: 16,
                sample_start: index / 4 * 32,
                sample_end: index / 4 * 32 + 32,
                mask: None,
            })
            .collect();
        let held = |done: &dyn Fn(u32) -> bool| merged_samples(&units, |u| done(u.index));
        assert_eq!(held(&|_| false), "no sample of every pixel");
        assert_eq!(held(&|i| i < 4), "samples 0..32 of every pixel");
        assert_eq!(
            held(&|i| i < 5 || (9..12).contains(&i)),
            "samples 0..32 of every pixel; 32..64 in 1 of 4 tiles; 64..96 in 3 of 4 tiles"
        );
        assert_eq!(
            held(&|i| i != 0),
            "no sample of every pixel; 0..32 in 3 of 4 tiles; 32..64 in 4 of 4 tiles; 64..96 \
             in 4 of 4 tiles"
        );
    }
}
