//! The threads that render units, apart from the async runtime so that a long unit never holds
//! up the network, and the queue in front of them. A unit waits in the queue (bounded) for a
//! free thread; a drain hands waiting units back at once and lets rendering ones finish; a unit
//! whose caller is gone stops within one path's time.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use prost::bytes::Bytes;
use tokio::sync::{watch, Semaphore};
use yat_proto::convert::{encode_layers, encode_pixels, encode_splats};
use yat_tracer::render::{UnitStats, WorkUnit};

use crate::error::NodeError;
use crate::loaded_scene::LoadedScene;

pub struct RenderPool {
    threads: rayon::ThreadPool,
    /// One permit per render thread, held from the moment a unit leaves the queue until its
    /// thread stops working on it (not merely until its caller stops waiting).
    slots: Arc<Semaphore>,
    waiting: AtomicU64,
    max_waiting: usize,
    /// Units holding a slot; a drain waits for it to reach zero.
    rendering: Arc<watch::Sender<u64>>,
    draining: watch::Receiver<bool>,
    /// Test hook: a pause before each unit, to make a worker slow on purpose.
    throttle: Duration,
}

/// A unit's sample buffer and light splats in their wire forms, its counters, and the time the
/// render took (not counting the wait for a thread).
pub struct RenderedUnit {
    pub pixels: Bytes,
    /// The layers' sums (empty unless the render keeps layers).
    pub layers: Bytes,
    pub splats: Bytes,
    pub stats: UnitStats,
    pub elapsed: Duration,
}

/// Units on a render thread and units waiting for one (what a drain lets finish and hands
/// back).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnitCounts {
    pub rendering: u64,
    pub waiting: u64,
}

impl RenderPool {
    /// `threads` render threads and a queue of at most `max_waiting` units, which empties when
    /// `draining` turns true.
    pub fn new(
        threads: usize,
        max_waiting: usize,
        draining: watch::Receiver<bool>,
        throttle: Duration,
    ) -> Result<Self, rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("yat-render-{i}"))
            .build()?;
        Ok(Self {
            threads: pool,
            slots: Arc::new(Semaphore::new(threads)),
            waiting: AtomicU64::new(0),
            max_waiting,
            rendering: Arc::new(watch::Sender::new(0)),
            draining,
            throttle,
        })
    }

    /// Units waiting for a thread and units on one.
    pub fn counts(&self) -> UnitCounts {
        UnitCounts {
            rendering: *self.rendering.borrow(),
            waiting: self.waiting.load(Ordering::Relaxed),
        }
    }

    /// Resolves once no unit is on a render thread.
    pub async fn idle(&self) {
        let mut rendering = self.rendering.subscribe();
        // The sender lives as long as `self`, so the wait cannot fail.
        let _ = rendering.wait_for(|n| *n == 0).await;
    }

    /// Renders `unit` of `loaded` once a thread is free. Dropping the future before it resolves
    /// takes a waiting unit out of the queue or stops a rendering one.
    pub async fn render(
        &self,
        loaded: Arc<LoadedScene>,
        unit: WorkUnit,
    ) -> Result<RenderedUnit, NodeError> {
        let slot = {
            let _waiting = Waiting::enter(&self.waiting, self.max_waiting)?;
            let mut draining = self.draining.clone();
            tokio::select! {
                biased;
                _ = draining.wait_for(|d| *d) => {
                    return Err(NodeError::Draining(format!("unit {}", unit.index)));
                }
                slot = self.slots.clone().acquire_owned() => slot.expect("the semaphore is never closed"),
            }
        };
        let rendering = Rendering::enter(&self.rendering);
        // A drain that began as this unit took its slot may have counted no unit rendering and
        // be stopping the server: the unit goes back, not rendered for a reply nobody gets. The
        // drain sets its flag before it counts the units rendering, and a unit counts itself
        // before it reads the flag, so one of the two sees the other.
        if *self.draining.borrow() {
            return Err(NodeError::Draining(format!("unit {}", unit.index)));
        }
        if !self.throttle.is_zero() {
            tokio::time::sleep(self.throttle).await;
        }
        let cancel = Arc::new(AtomicBool::new(false));
        let _cancel_on_drop = CancelOnDrop(cancel.clone());
        let (done, result) = tokio::sync::oneshot::channel();
        self.threads.spawn(move || {
            let _slot = slot;
            let _rendering = rendering;
            let started = Instant::now();
            // A renderer bug fails this unit, not the whole worker.
            let rendered = std::panic::catch_unwind(AssertUnwindSafe(|| {
                let (buffer, stats) = loaded.scene.render_unit_cancellable(&unit, &cancel)?;
                let encoded = [
                    encode_pixels(&buffer),
                    encode_layers(&buffer),
                    encode_splats(&buffer.splats),
                ];
                Some((encoded, stats))
            }));
            let _ = done.send(rendered.map(|r| r.map(|r| (r, started.elapsed()))));
        });
        let rendered = result
            .await
            .map_err(|_| NodeError::RenderThreadVanished)?
            .map_err(|_| NodeError::UnitPanicked(unit.index))?;
        let (([pixels, layers, splats], stats), elapsed) =
            rendered.ok_or(NodeError::UnitCancelled(unit.index))?;
        Ok(RenderedUnit {
            pixels,
            layers,
            splats,
            stats,
            elapsed,
        })
    }
}

/// A unit in the queue, refused when the queue is full.
struct Waiting<'a>(&'a AtomicU64);

impl<'a> Waiting<'a> {
    fn enter(waiting: &'a AtomicU64, max: usize) -> Result<Self, NodeError> {
        let before = waiting.fetch_add(1, Ordering::Relaxed);
        let guard = Self(waiting);
        if before >= max as u64 {
            return Err(NodeError::QueueFull { max });
        }
        Ok(guard)
    }
}

impl Drop for Waiting<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

/// A unit holding a render slot, from its throttle pause to the end of its render.
struct Rendering(Arc<watch::Sender<u64>>);

impl Rendering {
    fn enter(rendering: &Arc<watch::Sender<u64>>) -> Self {
        rendering.send_modify(|n| *n += 1);
        Self(rendering.clone())
    }
}

impl Drop for Rendering {
    fn drop(&mut self) {
        self.0.send_modify(|n| *n -= 1);
    }
}

/// Tells the render thread to give up when the caller stops waiting for the unit.
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}
