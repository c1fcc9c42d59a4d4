//! What a render writes while it runs, each on its own period: the preview image
//! (`<output>.preview.png`), the checkpoint (`<output>.resume`) and, for the status page, the
//! same image as the preview into the status board. The files go once the final image is
//! written.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context;
use yat_tracer::desc::FilmDesc;
use yat_tracer::private_file::StagedFile;

use crate::checkpoint::{Checkpoint, CheckpointFile};
use crate::status::snapshot::EventKind;
use crate::status::StatusBoard;

/// The tone-mapped image so far, rewritten every so often next to the output.
pub struct PreviewFile {
    path: PathBuf,
    every: Duration,
}

impl PreviewFile {
    pub fn beside(output_png: &Path, every: Duration) -> Self {
        Self {
            path: output_png.with_extension("preview.png"),
            every,
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// The render's interim outputs; either file may be off.
pub struct InterimOutputs {
    pub preview: Option<PreviewFile>,
    pub checkpoint: Option<CheckpointFile>,
    /// What the status page shows (a board nobody reads without `--status-addr`).
    pub status: Arc<StatusBoard>,
}

/// When each interim output was last written (or the render started).
pub struct InterimClock {
    preview: Instant,
    checkpoint: Instant,
}

impl Default for InterimClock {
    fn default() -> Self {
        let now = Instant::now();
        Self {
            preview: now,
            checkpoint: now,
        }
    }
}

/// Which interim outputs to write now.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DueOutputs {
    pub preview: bool,
    pub checkpoint: bool,
    /// A new image for the status page (the board says when).
    pub status_image: bool,
}

impl DueOutputs {
    pub fn any(self) -> bool {
        self.preview || self.checkpoint || self.status_image
    }
}

impl InterimOutputs {
    /// The outputs whose period has passed; their clocks restart now.
    pub fn due(&self, clock: &mut InterimClock) -> DueOutputs {
        let restart = |last: &mut Instant, every: Option<Duration>| {
            let due = every.is_some_and(|every| last.elapsed() >= every);
            if due {
                *last = Instant::now();
            }
            due
        };
        DueOutputs {
            preview: restart(&mut clock.preview, self.preview.as_ref().map(|p| p.every)),
            checkpoint: restart(
                &mut clock.checkpoint,
                self.checkpoint.as_ref().map(CheckpointFile::every),
            ),
            status_image: self.status.image_due(),
        }
    }

    /// The part of writing the due outputs that reads the render so far, and is quick: tone
    /// mapping the preview (once, for the file and the status page), writing the checkpoint's
    /// bytes. Render threads wait for it.
    pub fn stage(
        &self,
        due: DueOutputs,
        checkpoint: &Checkpoint,
        desc: &FilmDesc,
    ) -> StagedOutputs {
        let preview_file = self.preview.as_ref().filter(|_| due.preview);
        let started = Instant::now();
        let image = (preview_file.is_some() || due.status_image)
            .then(|| checkpoint.film().to_display(desc));
        if let (true, Some(image)) = (due.status_image, &image) {
            self.status.publish_image(image.clone(), started.elapsed());
        }
        let preview = preview_file
            .zip(image)
            .map(|(p, image)| (p.path.clone(), image));
        let checkpoint = self
            .checkpoint
            .as_ref()
            .filter(|_| due.checkpoint)
            .map(|c| c.stage(checkpoint));
        StagedOutputs {
            status: checkpoint.is_some().then(|| self.status.clone()),
            preview,
            checkpoint,
        }
    }

    /// Removes both once the final image is written.
    pub fn remove(&self) {
        if let Some(preview) = &self.preview {
            let _ = std::fs::remove_file(&preview.path);
        }
        if let Some(checkpoint) = &self.checkpoint {
            checkpoint.remove();
        }
    }
}

/// Interim outputs staged, to be finished without holding up the render.
pub struct StagedOutputs {
    preview: Option<(PathBuf, image::RgbImage)>,
    checkpoint: Option<anyhow::Result<StagedFile>>,
    /// Told when the checkpoint is written.
    status: Option<Arc<StatusBoard>>,
}

impl StagedOutputs {
    /// Encodes the preview PNG and syncs the checkpoint to disk, each through a temporary file
    /// renamed over the last one; what failed is returned, for the render to report and go on.
    pub fn finish(self) -> Vec<anyhow::Error> {
        let preview = self.preview.map(|(path, image)| {
            StagedFile::write(&path, |out| {
                image
                    .write_to(out, image::ImageFormat::Png)
                    .map_err(std::io::Error::other)
            })
            .and_then(StagedFile::commit)
            .with_context(|| format!("cannot write the preview {}", path.display()))
        });
        let checkpoint = self
            .checkpoint
            .map(|staged| staged.and_then(CheckpointFile::commit));
        if let (Some(Ok(())), Some(status)) = (&checkpoint, &self.status) {
            status.event(EventKind::CheckpointWritten, "checkpoint written".into());
        }
        [preview, checkpoint]
            .into_iter()
            .flatten()
            .filter_map(Result::err)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_output_is_due_on_its_own_period() {
        let dir = std::env::temp_dir();
        let outputs = InterimOutputs {
            preview: Some(PreviewFile::beside(
                &dir.join("x.png"),
                Duration::from_millis(200),
            )),
            checkpoint: None,
            status: StatusBoard::unserved(),
        };
        let mut clock = InterimClock::default();
        assert_eq!(outputs.due(&mut clock), DueOutputs::default());
        std::thread::sleep(Duration::from_millis(250));
        let due = outputs.due(&mut clock);
        assert!(due.preview && !due.checkpoint && due.any());
        assert!(!outputs.due(&mut clock).any(), "the clock restarted");
    }
}
