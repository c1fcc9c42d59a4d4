//! What the loops serving each worker share (the schedule, the scene as workers load it) and
//! what they tell the render loop.

use tokio::sync::mpsc::UnboundedSender;
use yat_proto::pb;
use yat_tracer::film::SampleBuffer;
use yat_tracer::filter::WeightBounds;
use yat_tracer::render::unit::FilmFrame;
use yat_tracer::render::UnitStats;

use super::schedule::{Schedule, UnitDeadline};
use crate::manifest::SceneManifest;

/// What node loops tell the render loop.
pub enum SessionEvent {
    /// A unit's result, the first one for that unit (boxed: a buffer's vectors and light
    /// splats make it ten times a notice's size).
    Result {
        buffer: Box<SampleBuffer>,
        stats: UnitStats,
    },
    /// A message for the terminal.
    Notice(String),
}

/// The render as every worker's session loop sees it: the units to hand out and how long one
/// may take, the scene to load, what a reply must fit, and where results go.
pub struct SessionContext {
    pub schedule: Schedule,
    pub deadline: UnitDeadline,
    pub manifest: SceneManifest,
    pub load_request: pb::LoadSceneRequest,
    /// The film's size and the border of every unit's buffer: what a reply must cover.
    pub frame: FilmFrame,
    /// What the scene's filter lets a sample weigh a pixel: what a reply's weight sums may be.
    pub weights: WeightBounds,
    pub events: UnboundedSender<SessionEvent>,
}

impl SessionContext {
    pub fn notice(&self, message: String) {
        let _ = self.events.send(SessionEvent::Notice(message));
    }
}
