//! The shared queue of a distributed render: which units wait, which are out, which are done,
//! and how long a unit may take before it is presumed lost.
//!
//! The end of a render is where a farm idles: once the queue is shorter than what is out, the
//! last units sit in a few workers' queues while the others have nothing to do. So in that end
//! game a session keeps one unit per worker thread instead of two (no unit waits behind
//! another), and once nothing is pending a worker with a free thread gets a copy of a unit still
//! out elsewhere, the most recently handed out first (the one likely to finish last). A unit's
//! result is the same bytes wherever it is rendered and only the first is merged, so this
//! changes how soon the image is done, never the image. (The plan helps too: when units are
//! long its last pass comes in smaller tiles; see `plan_units`. docs/cluster.md has the
//! farm simulation's figures.)

use std::collections::hash_map::DefaultHasher;
use std::collections::VecDeque;
use std::hash::{Hash, Hasher};
use std::sync::Mutex;
use std::time::Duration;

use tokio::sync::watch;
use yat_tracer::render::WorkUnit;

/// Units of the fixed plan (or of an adaptive render's round) handed out to workers. A unit a
/// worker loses goes back to the front of the queue; a unit's result is accepted once, whoever
/// sends it first. An adaptive render's next round replaces the units once the round is in:
/// a unit is known by all its fields, so a late result of another round is never taken for
/// one of this round's.
pub struct Schedule {
    state: Mutex<QueueState>,
    /// Bumped whenever a unit becomes available or the render ends, to wake idle workers.
    changed: watch::Sender<u64>,
}

struct QueueState {
    units: Vec<WorkUnit>,
    /// Whether the render ends when these units are done (a uniform render's plan, an adaptive
    /// render's last round once decided).
    last: bool,
    /// Units of every round so far.
    planned: usize,
    pending: VecDeque<u32>,
    done: Vec<bool>,
    done_count: usize,
    /// Per unit, whether it is out at a worker (taken, neither done nor back in the queue).
    out: Vec<bool>,
    out_count: usize,
    /// Units in the order they were handed out, newest last: end-game copies come from the back.
    handed: Vec<u32>,
    /// Per unit: who it was first handed to (a hash of the worker's address), and whether a
    /// copy was handed out too (one copy: enough to race a slow worker and fill idle threads
    /// at the end, measured with bench/farm-sim; more only render the same unit again).
    holder: Vec<u64>,
    copied: Vec<bool>,
    copies: u64,
}

impl QueueState {
    fn of(units: Vec<WorkUnit>, already_done: impl Fn(&WorkUnit) -> bool, last: bool) -> Self {
        let done: Vec<bool> = units.iter().map(already_done).collect();
        let n = units.len();
        Self {
            pending: (0..n as u32).filter(|&i| !done[i as usize]).collect(),
            done_count: done.iter().filter(|&&d| d).count(),
            done,
            out: vec![false; n],
            out_count: 0,
            handed: Vec::new(),
            holder: vec![0; n],
            copied: vec![false; n],
            copies: 0,
            planned: n,
            last,
            units,
        }
    }

    /// Whether `unit` is one of these units (not one of another round's with its index).
    fn holds(&self, unit: &WorkUnit) -> bool {
        self.units.get(unit.index as usize) == Some(unit)
    }
}

impl Schedule {
    /// The plan's units, less those `already_done` (by a render this one resumes); `last`
    /// when the render ends with them (else the render loop says what comes next).
    pub fn new(units: Vec<WorkUnit>, already_done: impl Fn(&WorkUnit) -> bool, last: bool) -> Self {
        Self {
            state: Mutex::new(QueueState::of(units, already_done, last)),
            changed: watch::Sender::new(0),
        }
    }

    /// Replaces the units, all done, with the next round's.
    pub fn start_round(&self, units: Vec<WorkUnit>) {
        let mut state = self.state.lock().unwrap();
        let (planned, copies) = (state.planned, state.copies);
        *state = QueueState::of(units, |_| false, false);
        state.planned += planned;
        state.copies += copies;
        drop(state);
        self.changed.send_modify(|v| *v += 1);
    }

    /// Says that the units, all done, were the last: the render is finished.
    pub fn finish(&self) {
        self.state.lock().unwrap().last = true;
        self.changed.send_modify(|v| *v += 1);
    }

    /// Units planned, of every round so far.
    pub fn len(&self) -> usize {
        self.state.lock().unwrap().planned
    }

    pub fn is_finished(&self) -> bool {
        let state = self.state.lock().unwrap();
        state.last && state.done_count == state.units.len()
    }

    /// How many units a session that normally keeps `limit` in flight (two per worker thread)
    /// may hold now: one per thread in the end game, when fewer units wait than are out.
    pub fn in_flight_limit(&self, limit: usize) -> usize {
        let state = self.state.lock().unwrap();
        if state.pending.len() < state.out_count {
            limit.div_ceil(2)
        } else {
            limit
        }
    }

    /// The next unit for the worker at `holder` (its address): the next one waiting, or once
    /// none waits, a copy of the newest unit out at another worker that has no copy yet.
    pub fn take(&self, holder: &str) -> Option<WorkUnit> {
        let holder = holder_key(holder);
        let mut state = self.state.lock().unwrap();
        while let Some(index) = state.pending.pop_front() {
            let i = index as usize;
            if !state.done[i] {
                if !std::mem::replace(&mut state.out[i], true) {
                    state.out_count += 1;
                }
                state.holder[i] = holder;
                state.handed.push(index);
                // Requeued units are pushed again: now and then keep only the last place of
                // each unit not yet done, so the list stays within twice the plan.
                if state.handed.len() > 2 * state.units.len() {
                    let mut kept = vec![false; state.units.len()];
                    let mut handed: Vec<u32> = state
                        .handed
                        .iter()
                        .rev()
                        .copied()
                        .filter(|&i| {
                            let i = i as usize;
                            !state.done[i] && !std::mem::replace(&mut kept[i], true)
                        })
                        .collect();
                    handed.reverse();
                    state.handed = handed;
                }
                return Some(state.units[i]);
            }
        }
        // The end game. Done units at the back will never be copied: drop them as we go.
        while state.handed.last().is_some_and(|&i| state.done[i as usize]) {
            state.handed.pop();
        }
        let state = &mut *state;
        let index = state.handed.iter().rev().copied().find(|&i| {
            let i = i as usize;
            !state.done[i] && state.out[i] && !state.copied[i] && state.holder[i] != holder
        })?;
        state.copied[index as usize] = true;
        state.copies += 1;
        Some(state.units[index as usize])
    }

    /// Puts a unit a worker failed to return back in front of the queue.
    pub fn requeue(&self, unit: &WorkUnit) {
        let mut state = self.state.lock().unwrap();
        let i = unit.index as usize;
        if state.holds(unit) && !state.done[i] && !state.pending.contains(&unit.index) {
            if std::mem::take(&mut state.out[i]) {
                state.out_count -= 1;
            }
            state.pending.push_front(unit.index);
            drop(state);
            self.changed.send_modify(|v| *v += 1);
        }
    }

    /// Marks a unit done; true the first time only, so a late duplicate (or a unit of an
    /// earlier round) is not merged.
    pub fn complete(&self, unit: &WorkUnit) -> bool {
        let mut state = self.state.lock().unwrap();
        if !state.holds(unit) {
            return false;
        }
        let i = unit.index as usize;
        let first = !std::mem::replace(&mut state.done[i], true);
        if first {
            state.done_count += 1;
            if std::mem::take(&mut state.out[i]) {
                state.out_count -= 1;
            }
            if state.done_count == state.units.len() {
                drop(state);
                self.changed.send_modify(|v| *v += 1);
            }
        }
        first
    }

    /// End-game copies handed out (each renders a unit a second time).
    pub fn copies(&self) -> u64 {
        self.state.lock().unwrap().copies
    }

    /// A receiver that sees a change when a unit is requeued or the render ends.
    pub fn watch(&self) -> watch::Receiver<u64> {
        self.changed.subscribe()
    }
}

fn holder_key(address: &str) -> u64 {
    let mut hasher = DefaultHasher::new();
    address.hash(&mut hasher);
    hasher.finish()
}

/// How long a unit may be in flight before it is presumed lost and handed to another worker:
/// `max(floor, factor x the slowest unit seen)` up to a ceiling, or a fixed value (tests).
pub struct UnitDeadline {
    fixed: Option<Duration>,
    slowest: Mutex<Duration>,
}

/// No unit is presumed lost sooner than this (unless a fixed deadline is set).
const DEADLINE_FLOOR: Duration = Duration::from_secs(30);
/// A unit is presumed lost after this many times the slowest unit seen.
const DEADLINE_FACTOR: u32 = 4;
/// Nor later than this: a worker slow to the edge of each deadline would otherwise raise it
/// fourfold every time.
const DEADLINE_CEILING: Duration = Duration::from_secs(600);

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
        self.fixed.unwrap_or_else(|| {
            let adaptive = self.slowest.lock().unwrap().saturating_mul(DEADLINE_FACTOR);
            adaptive.clamp(DEADLINE_FLOOR, DEADLINE_CEILING)
        })
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
            transport: Default::default(),
            aovs: Default::default(),
        })
    }

    fn schedule() -> Schedule {
        Schedule::new(plan(), |_| false, true)
    }

    #[test]
    fn a_resumed_schedule_hands_out_only_what_is_missing() {
        let s = Schedule::new(plan(), |u| u.index % 4 != 1, true);
        let taken: Vec<u32> = std::iter::from_fn(|| s.take("a"))
            .map(|u| u.index)
            .collect();
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
        let all_done = Schedule::new(plan(), |_| true, true);
        assert!(all_done.is_finished() && all_done.take("a").is_none());
    }

    #[test]
    fn units_go_out_in_plan_order_and_lost_ones_come_back_first() {
        let s = schedule();
        let n = s.len();
        assert!(n > 6);
        let a = s.take("a").unwrap();
        let b = s.take("a").unwrap();
        assert_eq!((a.index, b.index), (0, 1));
        s.requeue(&b);
        s.requeue(&b);
        assert_eq!(
            s.take("a").unwrap().index,
            1,
            "requeued units go first, once"
        );
        assert_eq!(s.take("a").unwrap().index, 2);
        let mut seen = 3;
        while let Some(u) = s.take("a") {
            assert_eq!(u.index, seen);
            seen += 1;
        }
        assert_eq!(seen as usize, n);
    }

    #[test]
    fn a_result_counts_once_and_done_units_are_not_requeued() {
        let s = schedule();
        let mut rx = s.watch();
        let units: Vec<_> = std::iter::from_fn(|| s.take("a")).collect();
        assert!(s.complete(&units[0]));
        assert!(!s.complete(&units[0]), "a late duplicate is refused");
        s.requeue(&units[0]);
        assert!(s.take("a").is_none(), "a done unit is not handed out again");
        s.requeue(&units[1]);
        assert!(rx.has_changed().unwrap());
        rx.mark_unchanged();
        assert_eq!(s.take("a").unwrap().index, 1);
        for u in &units[1..] {
            assert!(!s.is_finished());
            assert!(s.complete(u));
        }
        assert!(s.is_finished());
        assert!(rx.has_changed().unwrap(), "the end wakes idle workers");
    }

    #[test]
    fn the_end_game_copies_the_newest_unit_out_elsewhere_once() {
        let s = schedule();
        let n = s.len() as u32;
        assert_eq!(s.in_flight_limit(8), 8);
        let taken: Vec<_> = (0..n - 2).map(|_| s.take("a").unwrap()).collect();
        assert_eq!(
            s.in_flight_limit(8),
            4,
            "2 pending < {} out: one per thread",
            n - 2
        );
        assert_eq!(s.take("b").unwrap().index, n - 2);
        assert_eq!(s.take("b").unwrap().index, n - 1);
        assert!(s.complete(&taken[n as usize - 3]));
        // Nothing waits: copies of units out at another worker, newest first, once each.
        assert_eq!(
            s.take("b").unwrap().index,
            n - 4,
            "the done unit is skipped"
        );
        assert_eq!(s.take("a").unwrap().index, n - 1, "a copy of b's newest");
        assert_eq!(s.take("b").unwrap().index, n - 5);
        assert_eq!(s.copies(), 3);
        let mut copied = vec![n - 4, n - 1, n - 5];
        copied.extend(std::iter::from_fn(|| s.take("c")).map(|u| u.index));
        let copies = copied.len();
        copied.sort();
        copied.dedup();
        assert_eq!(copied.len(), copies, "no unit is copied twice");
        assert_eq!(s.copies(), copies as u64);
        assert!(s.complete(&taken[n as usize - 4]));
        assert!(
            !s.complete(&taken[n as usize - 4]),
            "the copy's result is not merged twice"
        );
        // A lost unit goes back to the queue and is handed out before any copy.
        s.requeue(&taken[0]);
        assert_eq!(s.take("b").unwrap().index, 0);
    }

    #[test]
    fn a_unit_lost_again_and_again_keeps_the_bookkeeping_bounded() {
        let s = schedule();
        let unit = s.take("a").unwrap();
        for _ in 0..10 * s.len() {
            s.requeue(&unit);
            assert_eq!(s.take("a").unwrap().index, unit.index);
        }
        let planned = s.len();
        assert!(s.state.lock().unwrap().handed.len() <= 2 * planned);
    }

    #[test]
    fn rounds_replace_the_units_and_a_late_result_of_another_round_is_refused() {
        let first = plan();
        let s = Schedule::new(first.clone(), |_| false, false);
        let mut rx = s.watch();
        let taken: Vec<_> = std::iter::from_fn(|| s.take("a"))
            .take(first.len())
            .collect();
        for u in &taken {
            assert!(s.complete(u));
        }
        assert!(
            !s.is_finished(),
            "an adaptive round ends; the render goes on"
        );
        rx.mark_unchanged();
        let second: Vec<WorkUnit> = first
            .iter()
            .take(3)
            .map(|u| WorkUnit {
                sample_start: 16,
                sample_end: 32,
                ..*u
            })
            .collect();
        s.start_round(second.clone());
        assert!(
            rx.has_changed().unwrap(),
            "idle workers wake for the new round"
        );
        assert_eq!(s.len(), first.len() + 3);
        assert!(!s.complete(&first[0]), "round 0's unit 0 is not round 1's");
        s.requeue(&first[1]);
        assert_eq!(s.take("a"), Some(second[0]), "a stale requeue adds nothing");
        for u in &second {
            s.complete(u);
        }
        assert!(!s.is_finished());
        s.finish();
        assert!(s.is_finished());
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
        d.observe(Duration::from_secs(3600));
        assert_eq!(
            d.current(),
            DEADLINE_CEILING,
            "one slow unit cannot raise it further"
        );
        let fixed = UnitDeadline::new(Some(Duration::from_millis(500)));
        fixed.observe(Duration::from_secs(20));
        assert_eq!(fixed.current(), Duration::from_millis(500));
    }
}
