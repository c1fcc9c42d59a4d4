//! What the loops serving each worker share (the schedule, the scene as workers load it) and
//! what they tell the render loop.

use tokio::sync::mpsc::UnboundedSender;
use yat_proto::pb;
use yat_tracer::film::SampleBuffer;
use yat_tracer::render::UnitStats;

use super::schedule::{Schedule, UnitDeadline};
use crate::manifest::SceneManifest;

/// What node loops tell the render loop.
pub enum Event {
    /// A unit's result, the first one for that unit.
    Result {
        buffer: SampleBuffer,
        stats: UnitStats,
    },
    /// A message for the terminal.
    Notice(String),
}

/// What every node loop shares.
pub struct Shared {
    pub schedule: Schedule,
    pub deadline: UnitDeadline,
    pub manifest: SceneManifest,
    pub load_request: pb::LoadSceneRequest,
    pub events: UnboundedSender<Event>,
}

impl Shared {
    pub fn notice(&self, message: String) {
        let _ = self.events.send(Event::Notice(message));
    }
}
