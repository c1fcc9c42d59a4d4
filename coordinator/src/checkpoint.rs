//! Checkpoints: a render's merged film and the units it holds, kept on disk every so often so
//! that a render stopped by a crash, a reboot, a lost coordinator machine or Ctrl-C resumes
//! where it was. The film's sums are exact integers, so a resumed render is bit-identical to
//! one never stopped, whichever way (in-process or on workers) each part was rendered.
//!
//! File layout (little-endian): magic, format version, render identity (64 hex bytes), width,
//! height, unit count, a bit per unit of the plan, the film's four i64 sums per pixel, and the
//! SHA-256 of everything before it. An adaptive render (whose identity says so) keeps its
//! round's units in the bitmap, which has room for the largest round
//! ([`adaptive::max_round_units`]) so the file's size is known before it is read; its film has
//! the four sums per pixel once per source plane (`FilmFrame::source_planes`), then come the
//! half sums (four i64 per pixel), each block's samples so far as the film counted them (u32),
//! the round's number and each block's planned samples (u32): all the decisions so far, so the
//! next ones are the same on resume. A converging render (LuxRender's `haltthreshold`, whose
//! identity says so) keeps its round's units in a bitmap with room for a round's tiles, and
//! after its sums (and light splats) the round's number (u32), the pixels that failed the last
//! test (u32, `u32::MAX` before the first) and the last test's image (three f32 per pixel,
//! zeros before round 1). A render whose units carry light splats
//! (`FilmFrame::light_splats`, never adaptive) has after its sums the light splats' three i64
//! sums per pixel and the light paths they are over (u64). A render whose units carry layers
//! (`FilmFrame::layers`: alpha) has next the layers' sums, one i64 per layer for each pixel of
//! each plane of the film's sums. Like the adaptive layout, these are the render's own, so the
//! format's version stays: checkpoints of every other render read as they always did.
//!
//! The file is only written through an exclusive temporary file renamed over it, and only read
//! when it is a regular file of exactly the size this render's checkpoint has
//! ([`yat_tracer::private_file`]): a symlink, a FIFO or a device put in its place is neither followed
//! nor read.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context;
use prost::Message;
use yat_proto::hash::Sha256Stream;
use yat_proto::pb;
use yat_tracer::film::FilmDesc;
use yat_tracer::film::{BufferMismatch, Film, FilmSplats, SampleBuffer};
use yat_tracer::render::adaptive::{BlockGrid, Round};
use yat_tracer::render::convergence::{ConvergenceRound, CONVERGENCE_VERSION};
use yat_tracer::render::sampling::{Rounds, RoundsEnd, Sampling};
use yat_tracer::render::unit::FilmFrame;
use yat_tracer::render::{RenderSettings, WorkUnit, PLAN_VERSION};

use yat_tracer::private_file::{read_regular_file, ReadFileError, StagedFile};

const MAGIC: &[u8; 8] = b"YATRESUM";
const FORMAT_VERSION: u32 = 1;
const IDENTITY_LEN: usize = 64;
const DIGEST_LEN: usize = 64;
const HEADER_LEN: usize = MAGIC.len() + 4 + IDENTITY_LEN + 3 * 4;

/// What a checkpoint belongs to: the SHA-256 of the renderer's version, the unit plan's version
/// and the scene as a worker is asked to load it (every file by content hash, and the
/// settings), and for an adaptive or converging render its settings. Anything that changes the
/// image changes it; threads, workers and output paths do not.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderIdentity(String);

impl RenderIdentity {
    /// The identity as 64 hex digits.
    pub fn hex(&self) -> &str {
        &self.0
    }

    pub fn of(load_request: &pb::LoadSceneRequest, sampling: &Sampling) -> Self {
        let mut digest = Sha256Stream::default();
        digest.update(b"yat render ");
        digest.update(env!("CARGO_PKG_VERSION").as_bytes());
        digest.update(format!(" plan {PLAN_VERSION} ").as_bytes());
        digest.update(&load_request.encode_to_vec());
        // A uniform render's identity is what it always was: its checkpoints still resume.
        match sampling {
            Sampling::Uniform => {}
            Sampling::Adaptive(a) => digest.update(
                format!(
                    " adaptive {ADAPTIVE_VERSION} {:#010x} {}",
                    a.threshold.to_bits(),
                    a.min_spp
                )
                .as_bytes(),
            ),
            Sampling::Converging(halt) => digest.update(
                format!(
                    " converging {CONVERGENCE_VERSION} {:#010x} {}",
                    halt.threshold.to_bits(),
                    halt.step
                )
                .as_bytes(),
            ),
        }
        Self(digest.finish_hex())
    }
}

/// Changes whenever the same adaptive settings would decide other rounds (the error estimate,
/// the decision, the units of a round): part of an adaptive render's identity.
const ADAPTIVE_VERSION: u32 = 4;

/// The render so far: the merged film and which units of the plan it holds; for a render in
/// rounds, the round under way (whose units `done` counts), and for an adaptive one the half
/// sums in the film.
#[derive(Clone)]
pub struct Checkpoint {
    film: Film,
    done: Vec<bool>,
    done_count: usize,
    rounds: Rounds,
    /// How the last round ended, once the render is done.
    ended: Option<RoundsEnd>,
    /// Bits of the done bitmap in the file: one per unit of the plan, or room for the largest
    /// round.
    bitmap_bits: usize,
}

impl Checkpoint {
    /// Nothing rendered yet: the plan's units to do, or an adaptive render's round 0; the film
    /// is of `frame` (`RenderSettings::film_frame`: the settings' size, the scene filter's
    /// border, whether units carry light splats).
    pub fn new(settings: &RenderSettings, frame: FilmFrame, sampling: &Sampling) -> Self {
        let film = match sampling {
            Sampling::Adaptive(_) => Film::adaptive(frame),
            _ => Film::new(frame),
        };
        let rounds = Rounds::first(settings, sampling);
        Self {
            film,
            done: vec![false; rounds.units(settings).len()],
            done_count: 0,
            rounds,
            ended: None,
            bitmap_bits: sampling.max_units(settings),
        }
    }

    /// The units of the plan (uniform) or of the round under way.
    pub fn units(&self, settings: &RenderSettings) -> Vec<WorkUnit> {
        self.rounds.units(settings)
    }

    /// Where the render's rounds are.
    pub fn rounds(&self) -> &Rounds {
        &self.rounds
    }

    /// The adaptive render's round under way.
    pub fn adaptive_round(&self) -> Option<&Round> {
        self.rounds.adaptive_round()
    }

    /// How the render's last round ended, once [`Self::advance`] found no next one.
    pub fn ended(&self) -> Option<RoundsEnd> {
        self.ended
    }

    /// Once every unit is in, moves a render in rounds to its next round, decided from the
    /// merged film alone (`desc`: the scene's film, as a converging render's images are
    /// compared displayed); false when there is none (or the render is uniform, or units are
    /// missing): the render is done, and [`Self::ended`] says how.
    pub fn advance(&mut self, settings: &RenderSettings, desc: &FilmDesc) -> bool {
        if !self.is_complete() {
            return false;
        }
        match self.rounds.advance(&self.film, desc, settings) {
            Ok(()) => {
                self.done = vec![false; self.rounds.units(settings).len()];
                self.done_count = 0;
                true
            }
            Err(end) => {
                self.ended = Some(end);
                false
            }
        }
    }

    /// Merges a unit's result. A unit already merged is not added again (false); a buffer that
    /// fits neither the film nor the plan is refused.
    pub fn add(&mut self, buffer: &SampleBuffer) -> Result<bool, BufferMismatch> {
        let index = buffer.unit.index as usize;
        let Some(done) = self.done.get_mut(index) else {
            return Err(BufferMismatch {
                index: buffer.unit.index,
                width: self.film.width(),
                height: self.film.height(),
                reason: format!("the plan has {} units", self.done.len()),
            });
        };
        if *done {
            return Ok(false);
        }
        self.film.add(buffer)?;
        *done = true;
        self.done_count += 1;
        Ok(true)
    }

    pub fn is_done(&self, unit: &WorkUnit) -> bool {
        self.done.get(unit.index as usize) == Some(&true)
    }

    pub fn done_count(&self) -> usize {
        self.done_count
    }

    /// Units of the plan, or of the round under way.
    pub fn unit_count(&self) -> usize {
        self.done.len()
    }

    pub fn is_complete(&self) -> bool {
        self.done_count == self.done.len()
    }

    /// Camera samples merged, and all the render will take: for a render in rounds, the most
    /// it may take (as if every block active now stayed so to the end, or the image never
    /// converged), an estimate that each round brings down.
    pub fn samples(&self, settings: &RenderSettings) -> (u64, u64) {
        let this_round = self.done_samples(&self.units(settings));
        self.rounds.samples(settings, this_round)
    }

    /// Camera samples of the units merged, out of `units` (the plan).
    pub fn done_samples(&self, units: &[WorkUnit]) -> u64 {
        units
            .iter()
            .filter(|u| self.is_done(u))
            .map(WorkUnit::sample_count)
            .sum()
    }

    pub fn film(&self) -> &Film {
        &self.film
    }

    pub fn into_film(self) -> Film {
        self.film
    }

    /// Writes the checkpoint in the file layout, its digest computed on the way.
    fn encode_to(&self, identity: &RenderIdentity, out: impl Write) -> std::io::Result<()> {
        let mut out = DigestingWriter {
            out,
            digest: Sha256Stream::default(),
        };
        out.write_all(MAGIC)?;
        out.write_all(&FORMAT_VERSION.to_le_bytes())?;
        out.write_all(identity.0.as_bytes())?;
        for v in [
            self.film.width(),
            self.film.height(),
            self.done.len() as u32,
        ] {
            out.write_all(&v.to_le_bytes())?;
        }
        let mut bitmap: Vec<u8> = self
            .done
            .chunks(8)
            .map(|bits| {
                bits.iter()
                    .enumerate()
                    .fold(0u8, |byte, (i, &done)| byte | (u8::from(done) << i))
            })
            .collect();
        bitmap.resize(self.bitmap_bits.div_ceil(8), 0);
        out.write_all(&bitmap)?;
        for sum in self.film.sums().iter().chain(self.film.half_sums()) {
            let mut pixel = [0u8; 32];
            for (bytes, v) in pixel.chunks_exact_mut(8).zip(sum) {
                bytes.copy_from_slice(&v.to_le_bytes());
            }
            out.write_all(&pixel)?;
        }
        if let Some(splats) = self.film.splats() {
            for sum in &splats.sums {
                for v in sum {
                    out.write_all(&v.to_le_bytes())?;
                }
            }
            out.write_all(&splats.light_paths.to_le_bytes())?;
        }
        for sum in self.film.layer_sums() {
            out.write_all(&sum.to_le_bytes())?;
        }
        for samples in self.film.block_samples() {
            out.write_all(&samples.to_le_bytes())?;
        }
        match &self.rounds {
            Rounds::Uniform => {}
            Rounds::Adaptive(_, round) => {
                out.write_all(&round.index.to_le_bytes())?;
                for planned in &round.planned {
                    out.write_all(&planned.to_le_bytes())?;
                }
            }
            Rounds::Converging(_, round) => {
                out.write_all(&round.index.to_le_bytes())?;
                let unconverged = round.unconverged.map_or(u32::MAX, |n| n as u32);
                out.write_all(&unconverged.to_le_bytes())?;
                let pixels = self.film.width() as usize * self.film.height() as usize;
                match &round.reference {
                    Some(image) => {
                        for v in image.iter().flatten() {
                            out.write_all(&v.to_le_bytes())?;
                        }
                    }
                    None => out.write_all(&vec![0u8; pixels * 12])?,
                }
            }
        }
        let digest = out.digest.finish_hex();
        out.out.write_all(digest.as_bytes())
    }

    /// The size of the file of a checkpoint with these settings.
    fn file_len(settings: &RenderSettings, frame: FilmFrame, sampling: &Sampling) -> u64 {
        let pixels = u64::from(settings.width) * u64::from(settings.height);
        let fixed =
            (HEADER_LEN + DIGEST_LEN) as u64 + (sampling.max_units(settings) as u64).div_ceil(8);
        let layers = frame.layers.len() as u64 * 8;
        match sampling {
            Sampling::Uniform => fixed + pixels * (32 + layers) + splats_len(&frame) as u64,
            Sampling::Adaptive(_) => {
                let blocks = BlockGrid::of(settings).len() as u64;
                let planes = frame.source_planes() as u64;
                fixed
                    + pixels * 32 * (planes + 1)
                    + pixels * layers * planes
                    + adaptive_rounds_len(blocks as usize) as u64
            }
            Sampling::Converging(_) => {
                fixed
                    + pixels * (32 + layers)
                    + splats_len(&frame) as u64
                    + converging_rounds_len(pixels as usize) as u64
            }
        }
    }

    /// Reads a checkpoint of the render `identity` with these settings.
    fn decode(
        bytes: &[u8],
        identity: &RenderIdentity,
        settings: &RenderSettings,
        frame: FilmFrame,
        sampling: &Sampling,
    ) -> Result<Self, CheckpointError> {
        if bytes.len() < HEADER_LEN + DIGEST_LEN || &bytes[..MAGIC.len()] != MAGIC {
            return Err(CheckpointError::NotACheckpoint);
        }
        let (body, digest) = bytes.split_at(bytes.len() - DIGEST_LEN);
        let mut check = Sha256Stream::default();
        check.update(body);
        if check.finish_hex().as_bytes() != digest {
            return Err(CheckpointError::Corrupt);
        }
        let u32_at = |at: usize| u32::from_le_bytes(body[at..at + 4].try_into().expect("4 bytes"));
        let version = u32_at(MAGIC.len());
        if version != FORMAT_VERSION {
            return Err(CheckpointError::OtherFormat(version));
        }
        let stored_identity = &body[MAGIC.len() + 4..MAGIC.len() + 4 + IDENTITY_LEN];
        let dims_at = MAGIC.len() + 4 + IDENTITY_LEN;
        let (width, height, units) = (u32_at(dims_at), u32_at(dims_at + 4), u32_at(dims_at + 8));
        if stored_identity != identity.0.as_bytes()
            || (width, height) != (settings.width, settings.height)
        {
            return Err(CheckpointError::OtherRender);
        }
        let mut checkpoint = Self::new(settings, frame, sampling);
        let pixels = width as usize * height as usize;
        let bitmap_len = checkpoint.bitmap_bits.div_ceil(8);
        let blocks = BlockGrid::of(settings).len();
        let planes = checkpoint.film.frame().source_planes();
        let (sum_count, round_len) = match sampling {
            Sampling::Uniform => (pixels, 0),
            Sampling::Adaptive(_) => ((planes + 1) * pixels, adaptive_rounds_len(blocks)),
            Sampling::Converging(_) => (pixels, converging_rounds_len(pixels)),
        };
        let splat_len = splats_len(&frame);
        let layer_planes = if sampling.adaptive().is_some() {
            planes
        } else {
            1
        };
        let layer_len = layer_planes * pixels * frame.layers.len() * 8;
        let rest = &body[HEADER_LEN..];
        if rest.len() != bitmap_len + sum_count * 32 + splat_len + layer_len + round_len {
            return Err(CheckpointError::Corrupt);
        }
        let (bitmap, rest) = rest.split_at(bitmap_len);
        let (sum_bytes, rest) = rest.split_at(sum_count * 32);
        let (splat_bytes, rest) = rest.split_at(splat_len);
        let (layer_bytes, round_bytes) = rest.split_at(layer_len);
        let layers = layer_bytes.chunks_exact(8).map(|v| i64_at(v, 0)).collect();
        let mut sums: Vec<[i64; 4]> = sum_bytes
            .chunks_exact(32)
            .map(|pixel| std::array::from_fn(|c| i64_at(pixel, c * 8)))
            .collect();
        let words: Vec<u32> = round_bytes
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes")))
            .collect();
        let (block_samples, round_words) = match sampling {
            Sampling::Adaptive(_) => {
                let (samples, round) = words.split_at(blocks);
                (samples.to_vec(), round)
            }
            _ => (Vec::new(), &words[..]),
        };
        let half = if sampling.adaptive().is_some() {
            sums.split_off(planes * pixels)
        } else {
            Vec::new()
        };
        let splats = frame.light_splats.then(|| {
            let (sums, light_paths) = splat_bytes.split_at(splat_bytes.len() - 8);
            FilmSplats {
                sums: sums
                    .chunks_exact(24)
                    .map(|pixel| std::array::from_fn(|c| i64_at(pixel, c * 8)))
                    .collect(),
                light_paths: u64::from_le_bytes(light_paths.try_into().expect("8 bytes")),
            }
        });
        checkpoint.film = Film::from_sums(frame, sums, half, block_samples, splats, layers)
            .ok_or(CheckpointError::Corrupt)?;
        // Checked as if hostile: a round no decision makes would plan nonsense units.
        match &mut checkpoint.rounds {
            Rounds::Uniform => {}
            Rounds::Adaptive(a, round) => {
                *round = Round {
                    index: round_words[0],
                    planned: round_words[1..].to_vec(),
                };
                if !round.fits(settings, a) {
                    return Err(CheckpointError::Corrupt);
                }
            }
            Rounds::Converging(halt, round) => {
                let index = round_words[0];
                let reference: Vec<[f32; 3]> = round_words[2..]
                    .chunks_exact(3)
                    .map(|rgb| std::array::from_fn(|c| f32::from_bits(rgb[c])))
                    .collect();
                *round = ConvergenceRound {
                    index,
                    reference: (index > 0).then_some(reference),
                    unconverged: (round_words[1] != u32::MAX).then_some(u64::from(round_words[1])),
                };
                if !round.fits(settings, halt) {
                    return Err(CheckpointError::Corrupt);
                }
            }
        }
        let unit_count = checkpoint.units(settings).len();
        if units as usize != unit_count || unit_count > checkpoint.bitmap_bits {
            return Err(CheckpointError::OtherRender);
        }
        checkpoint.done = (0..unit_count)
            .map(|i| bitmap[i / 8] >> (i % 8) & 1 == 1)
            .collect();
        checkpoint.done_count = checkpoint.done.iter().filter(|&&d| d).count();
        Ok(checkpoint)
    }
}

/// Bytes of an adaptive checkpoint's round: each block's samples so far, the round's number and
/// each block's planned samples (u32 each).
fn adaptive_rounds_len(blocks: usize) -> usize {
    4 * blocks + 4 + 4 * blocks
}

/// Bytes of a converging checkpoint's round: its number, the last test's failed pixels (u32
/// each) and the last test's image (three f32 per pixel).
fn converging_rounds_len(pixels: usize) -> usize {
    4 + 4 + 12 * pixels
}

/// Bytes of a checkpoint's light splats: three i64 sums per pixel and the light paths (u64),
/// for a render whose units carry them; none otherwise.
fn splats_len(frame: &FilmFrame) -> usize {
    if frame.light_splats {
        (frame.splat_entries() * 24 + 8) as usize
    } else {
        0
    }
}

/// The little-endian i64 at `at` of `bytes`.
fn i64_at(bytes: &[u8], at: usize) -> i64 {
    i64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
}

#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("not a YAT checkpoint")]
    NotACheckpoint,
    #[error("damaged (its checksum does not match)")]
    Corrupt,
    #[error("written in checkpoint format {0}, this yat reads format {FORMAT_VERSION}")]
    OtherFormat(u32),
    #[error("of another render (the scene's files, the settings or the yat version differ)")]
    OtherRender,
    #[error(transparent)]
    File(#[from] ReadFileError),
}

/// Where and how often a render keeps its checkpoint: `<output stem>.resume` beside the image.
pub struct CheckpointFile {
    path: PathBuf,
    identity: RenderIdentity,
    every: Duration,
}

impl CheckpointFile {
    pub fn beside(output_png: &Path, identity: RenderIdentity, every: Duration) -> Self {
        Self {
            path: output_png.with_extension("resume"),
            identity,
            every,
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn every(&self) -> Duration {
        self.every
    }

    /// The checkpoint this render left, if there is one.
    pub fn load(
        &self,
        settings: &RenderSettings,
        frame: FilmFrame,
        sampling: &Sampling,
    ) -> Result<Option<Checkpoint>, CheckpointError> {
        let expected = Checkpoint::file_len(settings, frame, sampling);
        let Some(bytes) = read_regular_file(&self.path, expected)? else {
            return Ok(None);
        };
        Checkpoint::decode(&bytes, &self.identity, settings, frame, sampling).map(Some)
    }

    /// The checkpoint to start from: the one on disk when it belongs to this render, else an
    /// empty one (saying why a file there is not used; it is overwritten by the next save).
    pub fn resume(
        &self,
        settings: &RenderSettings,
        frame: FilmFrame,
        sampling: &Sampling,
        quiet: bool,
    ) -> Checkpoint {
        match self.load(settings, frame, sampling) {
            Ok(Some(checkpoint)) => {
                if !quiet {
                    let (done, total) = checkpoint.samples(settings);
                    eprintln!(
                        "resuming from {}: {} of {} units{} ({:.1}% of the samples{}) already rendered",
                        self.path.display(),
                        checkpoint.done_count(),
                        checkpoint.done.len(),
                        checkpoint
                            .rounds()
                            .index()
                            .map_or(String::new(), |i| format!(" of round {i}")),
                        100.0 * done as f64 / total.max(1) as f64,
                        if sampling.has_rounds() { " at most" } else { "" },
                    );
                }
                checkpoint
            }
            Ok(None) => Checkpoint::new(settings, frame, sampling),
            Err(e) => {
                eprintln!(
                    "not resuming from {}: it is {e}; starting afresh",
                    self.path.display()
                );
                Checkpoint::new(settings, frame, sampling)
            }
        }
    }

    /// Writes the checkpoint atomically: a crash while saving leaves the previous one whole.
    pub fn save(&self, checkpoint: &Checkpoint) -> anyhow::Result<()> {
        Self::commit(self.stage(checkpoint)?)
    }

    /// The second half of [`CheckpointFile::save`]: syncs the staged file and renames it over
    /// the checkpoint.
    pub fn commit(staged: StagedFile) -> anyhow::Result<()> {
        let path = staged.destination().to_path_buf();
        staged
            .commit()
            .with_context(|| format!("cannot write {}", path.display()))
    }

    /// The first half of [`CheckpointFile::save`], the one that reads the checkpoint: its bytes
    /// written to a temporary file beside the real one (fast: they go to the page cache).
    pub fn stage(&self, checkpoint: &Checkpoint) -> anyhow::Result<StagedFile> {
        StagedFile::write(&self.path, |out| checkpoint.encode_to(&self.identity, out))
            .with_context(|| format!("cannot write {}", self.path.display()))
    }

    /// Removes the checkpoint once the final image is written.
    pub fn remove(&self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Passes bytes on, adding them to a digest.
struct DigestingWriter<W> {
    out: W,
    digest: Sha256Stream,
}

impl<W: Write> Write for DigestingWriter<W> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let written = self.out.write(bytes)?;
        self.digest.update(&bytes[..written]);
        Ok(written)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use yat_tracer::desc::LatLongConvention;
    use yat_tracer::render::adaptive::AdaptiveSettings;
    use yat_tracer::render::convergence::ConvergenceHalt;
    use yat_tracer::render::layers::Layers;
    use yat_tracer::render::plan_units;

    fn settings() -> RenderSettings {
        RenderSettings {
            width: 70,
            height: 40,
            spp: 64,
            max_depth: 3,
            seed: 0,
            latlong: LatLongConvention::Seed,
            transport: Default::default(),
            aovs: Default::default(),
        }
    }

    /// The border of a 2-pixel-wide filter's buffers (blackmanharris as the seed scenes use it).
    const BORDER: [u32; 2] = [2, 2];

    fn frame() -> FilmFrame {
        FilmFrame {
            border: BORDER,
            ..FilmFrame::unbordered(settings().width, settings().height)
        }
    }

    /// The film of a scene that says nothing of it: LuxRender's defaults.
    fn film_desc() -> FilmDesc {
        let mut files = yat_tracer::assets::MemorySource::new();
        files.insert(
            "f.lxs",
            std::sync::Arc::from(&b"WorldBegin\nWorldEnd\n"[..]),
        );
        yat_tracer::parse::parse_scene("f.lxs", &files)
            .unwrap()
            .film
    }

    fn encode(checkpoint: &Checkpoint, identity: &RenderIdentity) -> Vec<u8> {
        let mut bytes = Vec::new();
        checkpoint.encode_to(identity, &mut bytes).unwrap();
        bytes
    }

    fn identity(name: &str) -> RenderIdentity {
        RenderIdentity::of(
            &pb::LoadSceneRequest {
                main: Some(pb::SceneFile {
                    path: name.into(),
                    sha256: "0".repeat(64),
                }),
                assets: vec![],
                settings: Some((&settings()).into()),
            },
            &Sampling::Uniform,
        )
    }

    /// A checkpoint holding every third unit of the plan, with distinct sums per unit.
    fn partial() -> (Checkpoint, Vec<WorkUnit>) {
        let units = plan_units(&settings());
        let mut checkpoint = Checkpoint::new(&settings(), frame(), &Sampling::Uniform);
        for unit in units.iter().step_by(3) {
            let mut buffer = SampleBuffer::new(*unit, &frame());
            for (i, (rgb, w)) in buffer.rgb.iter_mut().zip(&mut buffer.weight).enumerate() {
                *rgb = [i as f32 * 0.25, unit.index as f32, -1.5];
                *w = 0.75;
            }
            assert!(checkpoint.add(&buffer).unwrap());
            assert!(!checkpoint.add(&buffer).unwrap(), "merged once");
        }
        (checkpoint, units)
    }

    #[test]
    fn a_checkpoint_reads_back_exactly() {
        let (checkpoint, units) = partial();
        let id = identity("a.lxs");
        let back = Checkpoint::decode(
            &encode(&checkpoint, &id),
            &id,
            &settings(),
            frame(),
            &Sampling::Uniform,
        )
        .expect("own checkpoint");
        assert_eq!(back.film().sums(), checkpoint.film().sums());
        assert_eq!(back.done, checkpoint.done);
        assert_eq!(back.done_count(), units.len().div_ceil(3));
        assert!(back.is_done(&units[3]) && !back.is_done(&units[4]));
        assert!(back.done_samples(&units) > 0 && !back.is_complete());
    }

    /// A render whose units carry light splats keeps their sums and light paths exactly, in a
    /// file of its own length; damaged splat sums are refused.
    #[test]
    fn a_checkpoint_keeps_light_splats_exactly() {
        let splat_frame = FilmFrame {
            light_splats: true,
            ..frame()
        };
        let units = plan_units(&settings());
        let mut checkpoint = Checkpoint::new(&settings(), splat_frame, &Sampling::Uniform);
        for unit in units.iter().step_by(2) {
            let mut buffer = SampleBuffer::new(*unit, &splat_frame);
            let pixels: Vec<u32> = (0..40).map(|k| unit.index % 20 * 7 + k * 67).collect();
            buffer.splats.rgb = pixels
                .iter()
                .map(|&p| [p as f32 * 0.125, -0.5, 1e-3 * unit.index as f32])
                .collect();
            buffer.splats.pixels = pixels;
            assert!(checkpoint.add(&buffer).unwrap());
        }
        let splats = checkpoint.film().splats().unwrap().clone();
        let samples: u64 = units.iter().step_by(2).map(WorkUnit::sample_count).sum();
        assert_eq!(splats.light_paths, samples);
        assert!(splats.sums.iter().any(|s| s[0] != 0));
        let id = identity("a.lxs");
        let bytes = encode(&checkpoint, &id);
        assert_eq!(
            bytes.len() as u64,
            Checkpoint::file_len(&settings(), splat_frame, &Sampling::Uniform)
        );
        let pixels = (settings().width * settings().height) as u64;
        assert_eq!(
            Checkpoint::file_len(&settings(), splat_frame, &Sampling::Uniform)
                - Checkpoint::file_len(&settings(), frame(), &Sampling::Uniform),
            pixels * 24 + 8
        );
        let back =
            Checkpoint::decode(&bytes, &id, &settings(), splat_frame, &Sampling::Uniform).unwrap();
        assert_eq!(back.film().splats(), Some(&splats));
        assert_eq!(back.film().sums(), checkpoint.film().sums());
        assert_eq!(back.film().radiance(), checkpoint.film().radiance());
        // The layout without splats is not read as one with them, nor the reverse.
        let plain = encode(
            &Checkpoint::new(&settings(), frame(), &Sampling::Uniform),
            &id,
        );
        assert!(
            Checkpoint::decode(&plain, &id, &settings(), splat_frame, &Sampling::Uniform).is_err()
        );
        assert!(Checkpoint::decode(&bytes, &id, &settings(), frame(), &Sampling::Uniform).is_err());
    }

    /// A render whose units carry alpha keeps its sums exactly, 8 bytes a pixel more (per
    /// source plane when adaptive); the layout without them is not read as one with them.
    #[test]
    fn a_checkpoint_keeps_alpha_exactly() {
        let alpha_frame = FilmFrame {
            layers: Layers {
                alpha: true,
                ..Layers::NONE
            },
            ..frame()
        };
        let a = AdaptiveSettings {
            threshold: 0.05,
            min_spp: 2,
        };
        let s = settings();
        let pixels = u64::from(s.width * s.height);
        for sampling in [Sampling::Uniform, Sampling::Adaptive(a)] {
            let mut checkpoint = Checkpoint::new(&s, alpha_frame, &sampling);
            for unit in checkpoint.units(&s).iter().step_by(2) {
                let mut buffer = SampleBuffer::new(*unit, &alpha_frame);
                for (i, w) in buffer.weight.iter_mut().enumerate() {
                    *w = 2.0;
                    buffer.layers[i] = (i % 3) as f32 * 0.5;
                }
                assert!(checkpoint.add(&buffer).unwrap());
            }
            assert!(checkpoint.film().layer_sums().iter().any(|&v| v != 0));
            let id = RenderIdentity::of(&pb::LoadSceneRequest::default(), &sampling);
            let bytes = encode(&checkpoint, &id);
            let len = |frame| Checkpoint::file_len(&s, frame, &sampling);
            assert_eq!(bytes.len() as u64, len(alpha_frame));
            let planes = sampling
                .adaptive()
                .map_or(1, |_| frame().source_planes() as u64);
            assert_eq!(len(alpha_frame) - len(frame()), pixels * 8 * planes);
            let back = Checkpoint::decode(&bytes, &id, &s, alpha_frame, &sampling).unwrap();
            assert_eq!(back.film().layer_sums(), checkpoint.film().layer_sums());
            assert_eq!(back.film().alpha(), checkpoint.film().alpha());
            assert!(Checkpoint::decode(&bytes, &id, &s, frame(), &sampling).is_err());
        }
    }

    #[test]
    fn an_adaptive_checkpoint_keeps_its_round_and_half_sums_exactly() {
        let a = AdaptiveSettings {
            threshold: 0.05,
            min_spp: 2,
        };
        let s = settings();
        let sampling = Sampling::Adaptive(a);
        let mut checkpoint = Checkpoint::new(&s, frame(), &sampling);
        // Round 0, then round 1 after a noisy film, then part of round 1.
        let fill = |checkpoint: &mut Checkpoint, every: usize| {
            for (n, unit) in checkpoint.units(&s).iter().enumerate().step_by(every) {
                let mut buffer = SampleBuffer::new(*unit, &frame());
                let value = |i: usize| ((i * 7919 + n * 104_729) % 97) as f32 / 9.0;
                for i in 0..buffer.weight.len() {
                    buffer.rgb[i] = [value(i), value(i) * 0.5, 1.0];
                    buffer.weight[i] = 2.0;
                }
                for i in 0..buffer.half_weight.len() {
                    buffer.half_rgb[i] = [value(i) * 0.1, 0.0, 0.5];
                    buffer.half_weight[i] = 1.0;
                }
                assert!(checkpoint.add(&buffer).unwrap());
            }
        };
        fill(&mut checkpoint, 1);
        let film_desc = film_desc();
        assert!(checkpoint.advance(&s, &film_desc), "a noisy film goes on");
        fill(&mut checkpoint, 2);
        let round = checkpoint.adaptive_round().unwrap().clone();
        assert_eq!(round.index, 1);
        let id = RenderIdentity::of(&pb::LoadSceneRequest::default(), &sampling);
        assert_ne!(
            id,
            RenderIdentity::of(&pb::LoadSceneRequest::default(), &Sampling::Uniform)
        );
        let bytes = encode(&checkpoint, &id);
        assert_eq!(
            bytes.len() as u64,
            Checkpoint::file_len(&s, frame(), &sampling)
        );
        let back = Checkpoint::decode(&bytes, &id, &s, frame(), &sampling).unwrap();
        assert_eq!(back.film().sums(), checkpoint.film().sums());
        assert_eq!(back.film().half_sums(), checkpoint.film().half_sums());
        assert_eq!(
            back.film().block_samples(),
            checkpoint.film().block_samples()
        );
        assert!(back.film().block_samples().contains(&4));
        assert_eq!(back.adaptive_round(), Some(&round));
        assert_eq!(back.done, checkpoint.done);
        assert_eq!(back.samples(&s), checkpoint.samples(&s));
        // A round no decision makes (a block planned for 3 samples) is refused.
        let mut forged = checkpoint.clone();
        let Rounds::Adaptive(_, forged_round) = &mut forged.rounds else {
            unreachable!("an adaptive checkpoint")
        };
        forged_round.planned[0] = 3;
        let bytes = encode(&forged, &id);
        assert!(matches!(
            Checkpoint::decode(&bytes, &id, &s, frame(), &sampling),
            Err(CheckpointError::Corrupt)
        ));
    }

    /// A converging render's checkpoint keeps its round, the last test's image and result
    /// exactly; a reference no display shows is refused.
    #[test]
    fn a_converging_checkpoint_keeps_its_round_and_reference_exactly() {
        let s = settings();
        let halt = ConvergenceHalt::new(0.0, 16.0);
        let sampling = Sampling::Converging(halt);
        let mut checkpoint = Checkpoint::new(&s, frame(), &sampling);
        let fill = |checkpoint: &mut Checkpoint, every: usize, salt: usize| {
            for unit in checkpoint.units(&s).iter().step_by(every) {
                let mut buffer = SampleBuffer::new(*unit, &frame());
                for i in 0..buffer.weight.len() {
                    let v = ((i * 7919 + salt * 104_729) % 97) as f32 / 50.0;
                    buffer.rgb[i] = [v, 0.5 * v, 1.0];
                    buffer.weight[i] = 1.0;
                }
                assert!(checkpoint.add(&buffer).unwrap());
            }
        };
        fill(&mut checkpoint, 1, 0);
        assert!(
            checkpoint.advance(&s, &film_desc()),
            "round 0 only sets the reference"
        );
        assert_eq!(checkpoint.rounds().index(), Some(1));
        fill(&mut checkpoint, 2, 1);
        let id = RenderIdentity::of(&pb::LoadSceneRequest::default(), &sampling);
        assert_ne!(
            id,
            RenderIdentity::of(&pb::LoadSceneRequest::default(), &Sampling::Uniform)
        );
        let bytes = encode(&checkpoint, &id);
        assert_eq!(
            bytes.len() as u64,
            Checkpoint::file_len(&s, frame(), &sampling)
        );
        let back = Checkpoint::decode(&bytes, &id, &s, frame(), &sampling).unwrap();
        assert_eq!(back.rounds(), checkpoint.rounds());
        assert_eq!(back.film().sums(), checkpoint.film().sums());
        assert_eq!(back.done, checkpoint.done);
        assert_eq!(back.samples(&s), checkpoint.samples(&s));
        let Rounds::Converging(_, round) = back.rounds() else {
            unreachable!("a converging checkpoint")
        };
        assert_eq!(round.reference.as_ref().map(Vec::len), Some(70 * 40));
        let mut forged = checkpoint.clone();
        let Rounds::Converging(_, forged_round) = &mut forged.rounds else {
            unreachable!("a converging checkpoint")
        };
        forged_round.reference.as_mut().unwrap()[5] = [2.0, 0.0, 0.0];
        assert!(matches!(
            Checkpoint::decode(&encode(&forged, &id), &id, &s, frame(), &sampling),
            Err(CheckpointError::Corrupt)
        ));
    }

    #[test]
    fn another_render_or_a_damaged_file_is_refused() {
        let (checkpoint, _) = partial();
        let id = identity("a.lxs");
        let bytes = encode(&checkpoint, &id);
        let decode = |bytes: &[u8], id: &RenderIdentity, settings: &RenderSettings| {
            Checkpoint::decode(bytes, id, settings, frame(), &Sampling::Uniform).err()
        };
        assert!(matches!(
            decode(&bytes, &identity("b.lxs"), &settings()),
            Some(CheckpointError::OtherRender)
        ));
        let wider = RenderSettings {
            width: 71,
            ..settings()
        };
        assert!(matches!(
            decode(&bytes, &id, &wider),
            Some(CheckpointError::OtherRender)
        ));
        for at in [9, HEADER_LEN + 1, bytes.len() / 2, bytes.len() - 1] {
            let mut damaged = bytes.clone();
            damaged[at] ^= 0x10;
            assert!(
                matches!(
                    decode(&damaged, &id, &settings()),
                    Some(CheckpointError::Corrupt)
                ),
                "byte {at}"
            );
        }
        for len in [0, 5, HEADER_LEN, bytes.len() - 1] {
            assert!(decode(&bytes[..len], &id, &settings()).is_some(), "{len}");
        }
        assert!(matches!(
            decode(b"PNG and more bytes than a header has, surely enough of them to pass the length check of the header and digest", &id, &settings()),
            Some(CheckpointError::NotACheckpoint)
        ));
    }

    #[test]
    fn saving_replaces_the_file_whole_and_resume_ignores_a_stranger() {
        let dir = tempfile::tempdir().unwrap();
        let output = dir.path().join("out.png");
        let file = CheckpointFile::beside(&output, identity("a.lxs"), Duration::from_secs(1));
        assert_eq!(file.path(), dir.path().join("out.resume"));
        assert!(file
            .load(&settings(), frame(), &Sampling::Uniform)
            .unwrap()
            .is_none());
        let (checkpoint, _) = partial();
        file.save(&Checkpoint::new(&settings(), frame(), &Sampling::Uniform))
            .unwrap();
        file.save(&checkpoint).unwrap();
        let loaded = file.resume(&settings(), frame(), &Sampling::Uniform, true);
        assert_eq!(loaded.film().sums(), checkpoint.film().sums());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "only the checkpoint, no temporary file"
        );

        let stranger = CheckpointFile::beside(&output, identity("b.lxs"), Duration::ZERO);
        assert_eq!(
            stranger
                .resume(&settings(), frame(), &Sampling::Uniform, true)
                .done_count(),
            0
        );
        file.remove();
        assert!(!file.path().exists());
    }
}
