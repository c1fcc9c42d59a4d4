//! The threads that render units, apart from the async runtime so that a long unit never holds
//! up the network.

use std::panic::AssertUnwindSafe;
use std::sync::Arc;
use std::time::{Duration, Instant};

use prost::bytes::Bytes;
use yat_proto::convert::encode_pixels;
use yat_tracer::render::{UnitStats, WorkUnit};

use crate::error::NodeError;
use crate::loaded_scene::LoadedScene;

pub struct RenderPool {
    pool: rayon::ThreadPool,
}

/// A unit's sample buffer in its wire form, its counters, and the time the render took (not
/// counting the wait for a thread).
pub struct RenderedUnit {
    pub pixels: Bytes,
    pub stats: UnitStats,
    pub elapsed: Duration,
}

impl RenderPool {
    pub fn new(threads: usize) -> Result<Self, rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("yat-render-{i}"))
            .build()?;
        Ok(Self { pool })
    }

    /// Renders `unit` of `loaded` on one of the pool's threads.
    pub async fn render(
        &self,
        loaded: Arc<LoadedScene>,
        unit: WorkUnit,
    ) -> Result<RenderedUnit, NodeError> {
        let (done, result) = tokio::sync::oneshot::channel();
        self.pool.spawn(move || {
            let started = Instant::now();
            // A renderer bug fails this unit, not the whole worker.
            let rendered = std::panic::catch_unwind(AssertUnwindSafe(|| {
                let (buffer, stats) = loaded.scene.render_unit(&unit);
                (encode_pixels(&buffer), stats)
            }));
            let _ = done.send(rendered.map(|r| (r, started.elapsed())));
        });
        let ((pixels, stats), elapsed) = result
            .await
            .map_err(|_| NodeError::RenderThreadVanished)?
            .map_err(|_| NodeError::UnitPanicked(unit.index))?;
        Ok(RenderedUnit {
            pixels,
            stats,
            elapsed,
        })
    }
}
