//! The shared queue of a distributed render: which units wait, which are done, and how long a
//! unit may take before it is presumed lost.

use std::collections::VecDeque;
use std::sync::Mutex;
use std::time::Duration;

use tokio::sync::watch;
use yat_tracer::render::WorkUnit;

/// Units of the fixed plan handed out to workers. A unit a worker loses goes back to the front
/// of the queue; a unit's result is accepted once, whoever sends it first.
pub struct Schedule {
    units: Vec<WorkUnit>,
    state: Mutex<QueueState>,
    /// Bumped whenever a unit becomes available or the render ends, to wake idle workers.
    changed: watch::Sender<u64>,
}

struct QueueState {
    pending: VecDeque<u32>,
    done: Vec<bool>,
    done_count: usize,
}

impl Schedule {
    /// The plan's units, less those `already_done` (by a render this one resumes).
    pub fn new(units: Vec<WorkUnit>, already_done: impl Fn(&WorkUnit) -> bool) -> Self {
        let done: Vec<bool> = units.iter().map(already_done).collect();
        let state = QueueState {
            pending: (0..units.len() as u32)
                .filter(|&i| !done[i as usize])
                .collect(),
            done_count: done.iter().filter(|&&d| d).count(),
            done,
        };
        Self {
            units,
            state: Mutex::new(state),
            changed: watch::Sender::new(0),
        }
    }

    pub fn len(&self) -> usize {
        self.units.len()
    }

    /// Camera samples of the whole plan.
    pub fn sample_count(&self) -> u64 {
        self.units.iter().map(WorkUnit::sample_count).sum()
    }

    pub fn is_finished(&self) -> bool {
        let state = self.state.lock().unwrap();
        state.done_count == self.units.len()
    }

    /// The next unit to render, if any waits.
    pub fn take(&self) -> Option<WorkUnit> {
        let mut state = self.state.lock().unwrap();
        while let Some(index) = state.pending.pop_front() {
            if !state.done[index as usize] {
                return Some(self.units[index as usize]);
            }
        }
        None
    }

    /// Puts a unit a worker failed to return back in front of the queue.
    pub fn requeue(&self, unit: &WorkUnit) {
        let mut state = self.state.lock().unwrap();
        if !state.done[unit.index as usize] && !state.pending.contains(&unit.index) {
            state.pending.push_front(unit.index);
            drop(state);
            self.changed.send_modify(|v| *v += 1);
        }
    }

    /// Marks a unit done; true the first time only, so a late duplicate is not merged twice.
    pub fn complete(&self, unit: &WorkUnit) -> bool {
        let mut state = self.state.lock().unwrap();
        let first = !std::mem::replace(&mut state.done[unit.index as usize], true);
        if first {
            state.done_count += 1;
            if state.done_count == self.units.len() {
                drop(state);
                self.changed.send_modify(|v| *v += 1);
            }
        }
        first
    }

    /// A receiver that sees a change when a unit is requeued or the render ends.
    pub fn watch(&self) -> watch::Receiver<u64> {
        self.changed.subscribe()
    }
}

/// How long a unit may be in flight before it is presumed lost and handed to another worker:
/// `max(floor, factor x the slowest unit seen)`, or a fixed value (tests).
pub struct UnitDeadline {
    fixed: Option<Duration>,
    slowest: Mutex<Duration>,
}

/// No unit is presumed lost sooner than this (unless a fixed deadline is set).
const DEADLINE_FLOOR: Duration = Duration::from_secs(30);
/// A unit is presumed lost after this many times the slowest unit seen.
const DEADLINE_FACTOR: u32 = 4;

impl UnitDeadline {
    pub fn new(fixed: Option<Duration>) -> Self {
        Self {
            fixed,
            slowest: Mutex::new(Duration::ZERO),
        }
    }

    /// Records how long a unit took from request to reply.
    pub fn observe(&self, took: Duration) {
        let mut slowest = self.slowest.lock().unwrap();
        *slowest = (*slowest).max(took);
    }

    pub fn current(&self) -> Duration {
        self.fixed
            .unwrap_or_else(|| DEADLINE_FLOOR.max(*self.slowest.lock().unwrap() * DEADLINE_FACTOR))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use yat_tracer::desc::LatLongConvention;
    use yat_tracer::render::{plan_units, RenderSettings};

    fn plan() -> Vec<WorkUnit> {
        plan_units(&RenderSettings {
            width: 130,
            height: 70,
            spp: 16,
            max_depth: 4,
            seed: 0,
            latlong: LatLongConvention::Seed,
        })
    }

    fn schedule() -> Schedule {
        Schedule::new(plan(), |_| false)
    }

    #[test]
    fn a_resumed_schedule_hands_out_only_what_is_missing() {
        let s = Schedule::new(plan(), |u| u.index % 4 != 1);
        let taken: Vec<u32> = std::iter::from_fn(|| s.take()).map(|u| u.index).collect();
        assert_eq!(
            taken,
            (0..s.len() as u32)
                .filter(|i| i % 4 == 1)
                .collect::<Vec<_>>()
        );
        for index in taken {
            assert!(!s.is_finished());
            assert!(s.complete(&plan()[index as usize]));
        }
        assert!(s.is_finished());
        let all_done = Schedule::new(plan(), |_| true);
        assert!(all_done.is_finished() && all_done.take().is_none());
    }

    #[test]
    fn units_go_out_in_plan_order_and_lost_ones_come_back_first() {
        let s = schedule();
        let n = s.len();
        assert!(n > 6);
        let a = s.take().unwrap();
        let b = s.take().unwrap();
        assert_eq!((a.index, b.index), (0, 1));
        s.requeue(&b);
        s.requeue(&b);
        assert_eq!(s.take().unwrap().index, 1, "requeued units go first, once");
        assert_eq!(s.take().unwrap().index, 2);
        let mut seen = 3;
        while let Some(u) = s.take() {
            assert_eq!(u.index, seen);
            seen += 1;
        }
        assert_eq!(seen as usize, n);
    }

    #[test]
    fn a_result_counts_once_and_done_units_are_not_requeued() {
        let s = schedule();
        let mut rx = s.watch();
        let units: Vec<_> = std::iter::from_fn(|| s.take()).collect();
        assert!(s.complete(&units[0]));
        assert!(!s.complete(&units[0]), "a late duplicate is refused");
        s.requeue(&units[0]);
        assert!(s.take().is_none(), "a done unit is not handed out again");
        s.requeue(&units[1]);
        assert!(rx.has_changed().unwrap());
        rx.mark_unchanged();
        assert_eq!(s.take().unwrap().index, 1);
        for u in &units[1..] {
            assert!(!s.is_finished());
            assert!(s.complete(u));
        }
        assert!(s.is_finished());
        assert!(rx.has_changed().unwrap(), "the end wakes idle workers");
    }

    #[test]
    fn deadline_adapts_to_the_slowest_unit() {
        let d = UnitDeadline::new(None);
        assert_eq!(d.current(), DEADLINE_FLOOR);
        d.observe(Duration::from_secs(5));
        assert_eq!(d.current(), DEADLINE_FLOOR);
        d.observe(Duration::from_secs(20));
        d.observe(Duration::from_secs(1));
        assert_eq!(d.current(), Duration::from_secs(80));
        let fixed = UnitDeadline::new(Some(Duration::from_millis(500)));
        fixed.observe(Duration::from_secs(20));
        assert_eq!(fixed.current(), Duration::from_millis(500));
    }
}
