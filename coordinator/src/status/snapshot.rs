//! What the status page shows, as plain data: the JSON of `/api/status` (every field is
//! documented in docs/status.md), also the source of `/metrics` and of the HTML page.
//! Nothing here knows the executors or HTTP; the board fills it, the server reads it.

use serde::Serialize;

/// Bumped when a field changes meaning or goes; new fields may appear without a bump.
pub const SNAPSHOT_VERSION: u32 = 1;

/// The whole page at one moment.
#[derive(Clone, Debug, Serialize)]
pub struct Snapshot {
    pub version: u32,
    pub scene: SceneInfo,
    pub settings: SettingsInfo,
    /// `rendering`, `finished` or `failed`.
    pub state: RenderState,
    pub progress: ProgressFigures,
    pub workers: Vec<WorkerRow>,
    /// The last events, oldest first.
    pub events: Vec<Event>,
    pub image: ImageInfo,
    /// Once the render has ended.
    pub summary: Option<Summary>,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct SceneInfo {
    /// The main file, as given on the command line.
    pub path: String,
    /// Its file name.
    pub name: String,
}

/// The settings that decide the image, and who renders it.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SettingsInfo {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
    /// `in-process` or `distributed`.
    pub executor: String,
    /// Render threads of an in-process render (`None` when distributed).
    pub threads: Option<usize>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RenderState {
    #[default]
    Rendering,
    Finished,
    Failed,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct ProgressFigures {
    pub units_done: u64,
    pub units_total: u64,
    /// Camera samples merged, including those a resumed checkpoint held.
    pub samples_done: u64,
    pub samples_total: u64,
    /// samples_done / samples_total, 0 to 1.
    pub ratio: f64,
    /// Samples merged by this run per second of this run's rendering.
    pub samples_per_second: f64,
    /// Since the render started (the scene loaded).
    pub elapsed_seconds: f64,
    /// What is left at the rate so far; `None` before the first unit or after the end.
    pub eta_seconds: Option<f64>,
    /// Units a worker lost or gave back, sent again.
    pub units_requeued: u64,
    /// The adaptive sampling round and how many there are (`None` without rounds).
    pub round: Option<u32>,
    pub rounds: Option<u32>,
}

/// A worker as the coordinator sees it: connecting (never reached yet), connected, stalled
/// (connected, but no result for longer than a unit should take), gone (lost, retired or
/// removed from DNS), done (connected until the render ended).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WorkerState {
    Connecting,
    Connected,
    Stalled,
    Gone,
    Done,
}

impl WorkerState {
    pub const ALL: [WorkerState; 5] = [
        WorkerState::Connecting,
        WorkerState::Connected,
        WorkerState::Stalled,
        WorkerState::Gone,
        WorkerState::Done,
    ];

    pub fn name(self) -> &'static str {
        match self {
            WorkerState::Connecting => "connecting",
            WorkerState::Connected => "connected",
            WorkerState::Stalled => "stalled",
            WorkerState::Gone => "gone",
            WorkerState::Done => "done",
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct WorkerRow {
    pub address: String,
    /// What the worker says its host is called (cleaned of control characters).
    pub hostname: String,
    pub threads: u32,
    pub state: WorkerState,
    /// Units whose results were merged.
    pub units: u64,
    pub samples: u64,
    /// Its samples per second of the render so far.
    pub samples_per_second: f64,
    /// Sessions lost and bad replies.
    pub failures: u64,
    pub units_requeued: u64,
    pub bytes_sent: u64,
    pub bytes_received: u64,
    /// Why it is gone, or its last error.
    pub reason: Option<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    WorkerJoined,
    WorkerLeft,
    UnitsRequeued,
    CheckpointWritten,
    RenderFinished,
    RenderFailed,
}

#[derive(Clone, Debug, Serialize)]
pub struct Event {
    /// Seconds since the render started.
    pub at_seconds: f64,
    pub kind: EventKind,
    /// The worker concerned, if any.
    pub worker: Option<String>,
    /// One line for people.
    pub text: String,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct ImageInfo {
    /// Bumped each time a newer image is published; `/image.png?v=N` fetches it.
    pub generation: u64,
    pub width: u32,
    pub height: u32,
}

/// How the render ended.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub seconds: f64,
    /// Samples this run rendered.
    pub samples: u64,
    pub samples_per_second: f64,
    /// The image written (`None` if the render failed).
    pub output: Option<String>,
    pub error: Option<String>,
}
