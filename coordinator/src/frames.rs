//! A sequence of frames (an animation as LuxBlend exports it: a scene file a frame) rendered by
//! one command: which scene files it is (arguments, globs, a list file), where each frame's
//! image goes, and the journal that lets the same command, stopped, go on at the frame where it
//! stopped (each frame's own checkpoint then goes on at the sample).

use std::collections::HashSet;
use std::ffi::OsString;
use std::fs::File;
use std::io::{Read, Write};
use std::os::unix::ffi::OsStringExt;
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::checkpoint::RenderIdentity;

/// The longest list file read (one scene path a line).
pub const MAX_LIST_FILE_BYTES: u64 = 1 << 20;

/// The most frames one command renders: what a list file of the longest allowed size could
/// name at one path a line, rounded.
pub const MAX_FRAMES: usize = 1 << 18;

/// The longest journal read: a line per frame of at most a path's length and an identity.
const MAX_JOURNAL_BYTES: u64 = 64 << 20;

/// One task's share of a sequence (a job array's task, an indexed job's pod): frames
/// `task * per_task` to `task * per_task + per_task - 1` (from 0) of the whole list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameSlice {
    pub task: usize,
    pub per_task: usize,
}

impl FrameSlice {
    /// The frames of this task out of `scenes` (none past the end is an error: the task was
    /// given more tasks than the list has frames for).
    pub fn of(&self, scenes: Vec<PathBuf>) -> anyhow::Result<Vec<PathBuf>> {
        anyhow::ensure!(self.per_task > 0, "--frames-per-task must be at least 1");
        let first = self.task.saturating_mul(self.per_task);
        anyhow::ensure!(
            first < scenes.len(),
            "task {} of {} frames a task starts at frame {}, but the sequence has {} frames",
            self.task,
            self.per_task,
            first.saturating_add(1),
            scenes.len()
        );
        let end = first.saturating_add(self.per_task).min(scenes.len());
        Ok(scenes[first..end].to_vec())
    }
}

/// The scene files of a sequence, in order: each argument (an argument that names no file but
/// holds a glob pattern is expanded, its matches sorted), then the lines of `list` if given
/// (`-` reads standard input); of them only `slice`'s, when given.
pub fn scene_files(
    arguments: &[PathBuf],
    list: Option<&Path>,
    slice: Option<FrameSlice>,
) -> anyhow::Result<Vec<PathBuf>> {
    let mut scenes = Vec::new();
    for argument in arguments {
        let text = argument.to_string_lossy();
        let pattern = text.contains(['*', '?', '[']) && !argument.exists();
        if !pattern {
            scenes.push(argument.clone());
            continue;
        }
        let matches = glob::glob(&text)
            .with_context(|| format!("{} is not a glob pattern", argument.display()))?;
        let mut found: Vec<PathBuf> = matches
            .collect::<Result<_, _>>()
            .with_context(|| format!("cannot list the files of {}", argument.display()))?;
        anyhow::ensure!(
            !found.is_empty(),
            "no scene file matches {}",
            argument.display()
        );
        found.sort();
        scenes.extend(found);
        anyhow::ensure!(scenes.len() <= MAX_FRAMES, "more than {MAX_FRAMES} frames");
    }
    if let Some(list) = list {
        scenes.extend(read_list_file(list)?.into_iter().map(PathBuf::from));
    }
    anyhow::ensure!(!scenes.is_empty(), "no scene to render");
    anyhow::ensure!(scenes.len() <= MAX_FRAMES, "more than {MAX_FRAMES} frames");
    match slice {
        Some(slice) => slice.of(scenes),
        None => Ok(scenes),
    }
}

/// The scene paths a list file names: one a line (a Windows line end taken off), blank lines
/// skipped; `-` is standard input. At most [`MAX_LIST_FILE_BYTES`] are read.
pub fn read_list_file(path: &Path) -> anyhow::Result<Vec<OsString>> {
    let cannot = || format!("cannot read the scene list {}", path.display());
    let mut bytes = Vec::new();
    let reader: Box<dyn Read> = if path.as_os_str() == "-" {
        Box::new(std::io::stdin())
    } else {
        Box::new(File::open(path).with_context(cannot)?)
    };
    reader
        .take(MAX_LIST_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .with_context(cannot)?;
    if bytes.len() as u64 > MAX_LIST_FILE_BYTES {
        anyhow::bail!(
            "{}: longer than {} KiB",
            cannot(),
            MAX_LIST_FILE_BYTES >> 10
        );
    }
    Ok(bytes
        .split(|&b| b == b'\n')
        .map(|line| line.strip_suffix(b"\r").unwrap_or(line))
        .filter(|line| !line.iter().all(u8::is_ascii_whitespace))
        .map(|line| OsString::from_vec(line.to_vec()))
        .collect())
}

/// Whether `-o` names a folder: one that exists, or a path ending in `/` (made if missing).
pub fn is_folder(output: &Path) -> bool {
    output.is_dir() || output.as_os_str().as_encoded_bytes().ends_with(b"/")
}

/// Where the frames' images go: the folder `-o` names (it must be one; a path ending in `/` is
/// made), or the current one; each frame's image is its Film filename there, and no two frames
/// may share one.
pub struct FrameOutputs {
    folder: PathBuf,
    taken: HashSet<PathBuf>,
}

impl FrameOutputs {
    pub fn new(output: Option<&Path>) -> anyhow::Result<Self> {
        let folder = match output {
            None => PathBuf::from("."),
            Some(folder) if is_folder(folder) => {
                std::fs::create_dir_all(folder)
                    .with_context(|| format!("cannot make the folder {}", folder.display()))?;
                folder.to_path_buf()
            }
            Some(other) => anyhow::bail!(
                "-o {} must be a folder when several frames render: each frame's image goes \
                 there under its Film filename",
                other.display()
            ),
        };
        Ok(Self {
            folder,
            taken: HashSet::new(),
        })
    }

    /// The image of frame `scene`, whose film names `film_output` (the current folder's PNG
    /// of its Film filename); refuses a name an earlier frame took.
    pub fn place(&mut self, scene: &Path, film_output: &Path) -> anyhow::Result<PathBuf> {
        let name = film_output
            .file_name()
            .context("a Film filename names no file")?;
        let output = self.folder.join(name);
        anyhow::ensure!(
            self.taken.insert(output.clone()),
            "{}: its Film filename gives {}, an earlier frame's image: give each frame's Film \
             its own filename",
            scene.display(),
            output.display()
        );
        Ok(output)
    }

    pub fn folder(&self) -> &Path {
        &self.folder
    }
}

/// The frames of a sequence already rendered, by render identity and image: `X.sequence`
/// beside the first frame's image `X.png`, a line a frame ("IDENTITY IMAGE"). A frame is
/// skipped when the same render of it (scene files by content, settings) wrote the same image,
/// which is still there with no checkpoint beside it. Removed once every frame is rendered.
pub struct FrameJournal {
    path: PathBuf,
    done: HashSet<(String, String)>,
}

impl FrameJournal {
    /// The journal beside `first_image`, read if a stopped run left one.
    pub fn beside(first_image: &Path) -> anyhow::Result<Self> {
        let path = first_image.with_extension("sequence");
        let mut done = HashSet::new();
        if let Ok(file) = File::open(&path) {
            let mut text = String::new();
            file.take(MAX_JOURNAL_BYTES)
                .read_to_string(&mut text)
                .with_context(|| format!("cannot read {}", path.display()))?;
            for line in text.lines() {
                if let Some((identity, image)) = line.split_once(' ') {
                    done.insert((identity.to_string(), image.to_string()));
                }
            }
        }
        Ok(Self { path, done })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the frame of `identity` writing `image` is rendered already.
    pub fn is_done(&self, identity: &RenderIdentity, image: &Path) -> bool {
        let key = (identity.hex().to_string(), image.display().to_string());
        self.done.contains(&key) && image.is_file() && !image.with_extension("resume").exists()
    }

    /// Records a frame rendered (flushed before the next frame starts).
    pub fn record(&mut self, identity: &RenderIdentity, image: &Path) -> anyhow::Result<()> {
        let line = format!("{} {}\n", identity.hex(), image.display());
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&self.path)
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        file.write_all(line.as_bytes())
            .and_then(|()| file.sync_data())
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        self.done
            .insert((identity.hex().to_string(), image.display().to_string()));
        Ok(())
    }

    /// The sequence is complete: the journal goes.
    pub fn remove(self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_globs_and_list_lines_in_order() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["f2.lxs", "f1.lxs", "f10.lxs", "other.txt"] {
            std::fs::write(dir.path().join(name), "").unwrap();
        }
        let list = dir.path().join("frames.txt");
        std::fs::write(&list, "x.lxs\r\n\n  \ny.lxs\n").unwrap();
        let pattern = dir.path().join("f*.lxs");
        let both = [dir.path().join("a.lxs"), pattern];
        let scenes = scene_files(&both, Some(&list), None).unwrap();
        let names: Vec<String> = scenes
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            ["a.lxs", "f1.lxs", "f10.lxs", "f2.lxs", "x.lxs", "y.lxs"]
        );
        let none = scene_files(&[dir.path().join("z*.lxs")], None, None).unwrap_err();
        assert!(none.to_string().contains("no scene file matches"), "{none}");
        assert!(scene_files(&[], None, None).is_err());
        // Task 1 of two frames a task: the third and fourth; task 2 the sixth alone.
        let slice = |task| Some(FrameSlice { task, per_task: 2 });
        let names_of = |scenes: Vec<PathBuf>| -> Vec<String> {
            scenes
                .iter()
                .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
                .collect()
        };
        let task = |t| names_of(scene_files(&both, Some(&list), slice(t)).unwrap());
        assert_eq!(task(1), ["f10.lxs", "f2.lxs"]);
        assert_eq!(task(2), ["x.lxs", "y.lxs"]);
        let past = scene_files(&both, Some(&list), slice(3))
            .unwrap_err()
            .to_string();
        assert!(past.contains("the sequence has 6 frames"), "{past}");
    }

    #[test]
    fn a_list_longer_than_its_limit_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let list = dir.path().join("long.txt");
        std::fs::write(&list, vec![b'a'; MAX_LIST_FILE_BYTES as usize + 1]).unwrap();
        let err = read_list_file(&list).unwrap_err().to_string();
        assert!(err.contains("longer than 1024 KiB"), "{err}");
    }

    #[test]
    fn frames_get_their_film_names_in_the_folder_and_never_share_one() {
        let dir = tempfile::tempdir().unwrap();
        let mut outputs = FrameOutputs::new(Some(dir.path())).unwrap();
        let a = outputs
            .place(Path::new("a.lxs"), Path::new("frame.0001.png"))
            .unwrap();
        assert_eq!(a, dir.path().join("frame.0001.png"));
        let twice = outputs
            .place(Path::new("b.lxs"), Path::new("frame.0001.png"))
            .unwrap_err()
            .to_string();
        assert!(twice.contains("an earlier frame's image"), "{twice}");
        let file = dir.path().join("x.png");
        std::fs::write(&file, "").unwrap();
        assert!(FrameOutputs::new(Some(&file)).is_err());
    }

    #[test]
    fn the_journal_names_frames_done_while_their_image_stands_alone() {
        let dir = tempfile::tempdir().unwrap();
        let image = dir.path().join("f1.png");
        let identity = RenderIdentity::of(
            &Default::default(),
            &yat_tracer::render::sampling::Sampling::Uniform,
        );
        let mut journal = FrameJournal::beside(&image).unwrap();
        assert!(!journal.is_done(&identity, &image));
        std::fs::write(&image, "png").unwrap();
        journal.record(&identity, &image).unwrap();
        let read = FrameJournal::beside(&image).unwrap();
        assert!(read.is_done(&identity, &image));
        std::fs::write(image.with_extension("resume"), "").unwrap();
        assert!(
            !read.is_done(&identity, &image),
            "a checkpoint beside it: not done"
        );
        std::fs::remove_file(image.with_extension("resume")).unwrap();
        let other = dir.path().join("f2.png");
        assert!(!read.is_done(&identity, &other));
        read.remove();
        assert!(!FrameJournal::beside(&image)
            .unwrap()
            .is_done(&identity, &image));
    }
}
