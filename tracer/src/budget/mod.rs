//! What a scene may cost to parse and build, and the flag that abandons a build.
//!
//! A scene file of a few kilobytes can describe gigabytes: an object instanced a million times,
//! an Include fan-out (a file including another ten times, which includes another ten
//! times...), an image whose header claims 60000 x 60000 texels. Every node checks its own
//! [`BuildBudget`] (set by its flags) while it parses and builds, and stops with an error naming the limit, the
//! figure reached and the statement (file:line:col) that reached it. The defaults leave room for
//! every scene the project renders (CaptainFalcon: 10 107 triangles, 2.2 million texels, 1.3 MB
//! of scene text, well under one percent of each).
//!
//! [`BuildGuard`] adds a cancel flag checked at the same points, so a worker whose coordinator
//! went away can abandon a build.

pub mod memory_limit;

use std::sync::atomic::{AtomicBool, Ordering};

/// Bytes of scene text parsed when the command line does not say: 4 GiB, counting a file once
/// per Include visit, plus PLY files once each.
pub const DEFAULT_MAX_PARSED_BYTES: u64 = 4 << 30;
/// Include statements followed when the command line does not say.
pub const DEFAULT_MAX_INCLUDE_VISITS: u64 = 10_000;
/// Primitives (triangles, spheres, disks, cylinders, planes) placed in the world, counting
/// every instance, when the command line does not say: 2^26 (some 30 GB once built, which the
/// memory figure bounds).
pub const DEFAULT_MAX_PRIMITIVES: u64 = 1 << 26;
/// Texels of the distinct image files decoded, and of the tables sky lights are tabulated on
/// (each [`SkyLight::TABLE_TEXELS`](crate::lights::SkyLight::TABLE_TEXELS)), when the command line
/// does not say: 2^29, for example eight 8k x 8k maps (1.5 GiB as 8-bit RGB). One image is also
/// held to the `image` crate's own decoding limit of 512 MiB.
pub const DEFAULT_MAX_TEXELS: u64 = 1 << 29;
/// Bytes of memory the build may hold at its peak, as estimated, when the caller does not say:
/// no limit. The memory a process may use depends on where it runs, so the command line sets
/// this figure from [`memory_limit::MemoryLimit::detect`].
pub const DEFAULT_MAX_MEMORY_BYTES: u64 = u64::MAX;

const MIB: u64 = 1 << 20;

/// What a scene may cost to parse and build; every figure counts the whole scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuildBudget {
    pub max_parsed_bytes: u64,
    pub max_include_visits: u64,
    pub max_primitives: u64,
    pub max_texels: u64,
    pub max_memory_bytes: u64,
}

impl BuildBudget {
    pub const DEFAULT: Self = Self {
        max_parsed_bytes: DEFAULT_MAX_PARSED_BYTES,
        max_include_visits: DEFAULT_MAX_INCLUDE_VISITS,
        max_primitives: DEFAULT_MAX_PRIMITIVES,
        max_texels: DEFAULT_MAX_TEXELS,
        max_memory_bytes: DEFAULT_MAX_MEMORY_BYTES,
    };

    /// The limit of `kind`.
    pub fn max(&self, kind: Limit) -> u64 {
        match kind {
            Limit::ParsedBytes => self.max_parsed_bytes,
            Limit::IncludeVisits => self.max_include_visits,
            Limit::Primitives => self.max_primitives,
            Limit::Texels => self.max_texels,
            Limit::MemoryBytes => self.max_memory_bytes,
        }
    }
}

impl Default for BuildBudget {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// One figure of the budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    ParsedBytes,
    IncludeVisits,
    Primitives,
    Texels,
    /// The bytes the build holds at its peak, estimated from the counts before allocating.
    MemoryBytes,
}

/// The figures, in the order of [`BudgetMeter`]'s array.
const LIMITS: usize = 5;

impl Limit {
    /// What is counted, as a person reads it.
    pub fn what(self) -> &'static str {
        match self {
            Limit::ParsedBytes => "bytes of scene files parsed",
            Limit::IncludeVisits => "Include visits",
            Limit::Primitives => "primitives (triangles and shapes, every instance counted)",
            Limit::Texels => "texels of images and sky tables",
            Limit::MemoryBytes => "memory (estimated before allocating)",
        }
    }

    /// The `yat render`, `yat check` and `yat worker` flag that sets it.
    pub fn flag(self) -> &'static str {
        match self {
            Limit::ParsedBytes => "--max-scene-mib",
            Limit::IncludeVisits => "--max-include-visits",
            Limit::Primitives => "--max-primitives",
            Limit::Texels => "--max-texels",
            Limit::MemoryBytes => "--max-memory-mib",
        }
    }

    /// An amount of this figure as a person reads it: bytes in MiB (to a tenth, so an amount
    /// just over a limit still reads as more), counts as they are.
    pub fn amount(self, value: u64) -> String {
        match self {
            Limit::MemoryBytes => format!("{:.1} MiB", value as f64 / MIB as f64),
            _ => value.to_string(),
        }
    }
}

/// A figure of the budget exceeded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the scene needs more than its limit of {} {} ({} reached; {} raises the limit)", .limit.amount(*.max), .limit.what(), .limit.amount(*.reached), .limit.flag())]
pub struct OverBudget {
    pub limit: Limit,
    pub reached: u64,
    pub max: u64,
}

/// The build was abandoned through its cancel flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the scene build was cancelled")]
pub struct Cancelled;

/// What bounds one parse and build: the budget, and the flag that abandons it.
#[derive(Clone, Copy, Debug)]
pub struct BuildGuard<'a> {
    pub budget: &'a BuildBudget,
    pub cancel: &'a AtomicBool,
}

static DEFAULT_BUDGET: BuildBudget = BuildBudget::DEFAULT;
static NEVER_CANCELLED: AtomicBool = AtomicBool::new(false);

impl Default for BuildGuard<'static> {
    /// The default budget, never cancelled.
    fn default() -> Self {
        Self {
            budget: &DEFAULT_BUDGET,
            cancel: &NEVER_CANCELLED,
        }
    }
}

impl BuildGuard<'_> {
    pub fn check_cancel(&self) -> Result<(), Cancelled> {
        if self.cancel.load(Ordering::Relaxed) {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

/// The figures of the budget spent so far.
#[derive(Clone, Debug, Default)]
pub struct BudgetMeter {
    spent: [u64; LIMITS],
    /// Per figure, the largest amount charged as transient: held only while one item is made
    /// (an image while it decodes), and items are made one after another, so a figure is what
    /// is kept plus the largest transient.
    transient: [u64; LIMITS],
}

impl BudgetMeter {
    /// Adds `amount` to the figure `limit`, failing when it goes over `budget`.
    pub fn spend(
        &mut self,
        budget: &BuildBudget,
        limit: Limit,
        amount: u64,
    ) -> Result<(), OverBudget> {
        self.spend_with_transient(budget, limit, amount, 0)
    }

    /// Adds `kept` to the figure `limit`, and `transient` more while the item is made; fails
    /// when the figure goes over `budget`. A refused amount is not spent.
    pub fn spend_with_transient(
        &mut self,
        budget: &BuildBudget,
        limit: Limit,
        kept: u64,
        transient: u64,
    ) -> Result<(), OverBudget> {
        let i = limit as usize;
        let spent = self.spent[i].saturating_add(kept);
        let transient = self.transient[i].max(transient);
        let reached = spent.saturating_add(transient);
        let max = budget.max(limit);
        if reached > max {
            return Err(OverBudget {
                limit,
                reached,
                max,
            });
        }
        self.spent[i] = spent;
        self.transient[i] = transient;
        Ok(())
    }

    /// The figure `limit` so far: what is kept plus the largest transient.
    pub fn spent(&self, limit: Limit) -> u64 {
        let i = limit as usize;
        self.spent[i].saturating_add(self.transient[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_meter_fails_past_the_limit_and_names_it() {
        let budget = BuildBudget {
            max_primitives: 10,
            ..BuildBudget::DEFAULT
        };
        let mut meter = BudgetMeter::default();
        meter.spend(&budget, Limit::Primitives, 10).unwrap();
        let err = meter.spend(&budget, Limit::Primitives, 1).unwrap_err();
        assert_eq!(
            err,
            OverBudget {
                limit: Limit::Primitives,
                reached: 11,
                max: 10
            }
        );
        assert!(err.to_string().contains("--max-primitives"), "{err}");
        assert_eq!(
            meter.spent(Limit::Primitives),
            10,
            "a refused amount is not spent"
        );
        meter.spend(&budget, Limit::Texels, u64::MAX).unwrap_err();
    }

    /// Transient amounts (an image while it decodes) are held one at a time: the figure is what
    /// is kept plus the largest of them, and the check counts both.
    #[test]
    fn a_memory_figure_counts_what_is_kept_and_the_largest_transient() {
        let budget = BuildBudget {
            max_memory_bytes: 100,
            ..BuildBudget::DEFAULT
        };
        let mut meter = BudgetMeter::default();
        meter
            .spend_with_transient(&budget, Limit::MemoryBytes, 10, 50)
            .unwrap();
        meter
            .spend_with_transient(&budget, Limit::MemoryBytes, 10, 30)
            .unwrap();
        assert_eq!(meter.spent(Limit::MemoryBytes), 70);
        meter.spend(&budget, Limit::MemoryBytes, 30).unwrap();
        assert_eq!(meter.spent(Limit::MemoryBytes), 100);
        let err = meter
            .spend_with_transient(&budget, Limit::MemoryBytes, 0, 51)
            .unwrap_err();
        assert_eq!(err.reached, 101);
        let text = err.to_string();
        assert!(
            text.contains("--max-memory-mib") && text.contains("0.0 MiB"),
            "{text}"
        );
        assert_eq!(meter.spent(Limit::MemoryBytes), 100);
    }
}
