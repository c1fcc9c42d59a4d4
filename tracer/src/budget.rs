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

use std::sync::atomic::{AtomicBool, Ordering};

/// Bytes of scene text parsed when the command line does not say: 4 GiB, counting a file once
/// per Include visit, plus PLY files once each.
pub const DEFAULT_MAX_PARSED_BYTES: u64 = 4 << 30;
/// Include statements followed when the command line does not say.
pub const DEFAULT_MAX_INCLUDE_VISITS: u64 = 10_000;
/// Primitives (triangles, spheres, disks, cylinders, planes) placed in the world, counting
/// every instance, when the command line does not say: 2^26, some 16 GiB of built geometry.
pub const DEFAULT_MAX_PRIMITIVES: u64 = 1 << 26;
/// Texels of the distinct image files decoded, and of the tables sky lights are tabulated on
/// (each [`SkyLight::TABLE_TEXELS`](crate::lights::SkyLight::TABLE_TEXELS)), when the command line
/// does not say: 2^29, for example eight 8k x 8k maps (1.5 GiB as 8-bit RGB). One image is also
/// held to the `image` crate's own decoding limit of 512 MiB.
pub const DEFAULT_MAX_TEXELS: u64 = 1 << 29;

/// What a scene may cost to parse and build; every figure counts the whole scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuildBudget {
    pub max_parsed_bytes: u64,
    pub max_include_visits: u64,
    pub max_primitives: u64,
    pub max_texels: u64,
}

impl BuildBudget {
    pub const DEFAULT: Self = Self {
        max_parsed_bytes: DEFAULT_MAX_PARSED_BYTES,
        max_include_visits: DEFAULT_MAX_INCLUDE_VISITS,
        max_primitives: DEFAULT_MAX_PRIMITIVES,
        max_texels: DEFAULT_MAX_TEXELS,
    };

    /// The limit of `kind`.
    pub fn max(&self, kind: Limit) -> u64 {
        match kind {
            Limit::ParsedBytes => self.max_parsed_bytes,
            Limit::IncludeVisits => self.max_include_visits,
            Limit::Primitives => self.max_primitives,
            Limit::Texels => self.max_texels,
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
}

impl Limit {
    /// What is counted, as a person reads it.
    pub fn what(self) -> &'static str {
        match self {
            Limit::ParsedBytes => "bytes of scene files parsed",
            Limit::IncludeVisits => "Include visits",
            Limit::Primitives => "primitives (triangles and shapes, every instance counted)",
            Limit::Texels => "texels of images and sky tables",
        }
    }

    /// The `yat render`, `yat check` and `yat worker` flag that sets it.
    pub fn flag(self) -> &'static str {
        match self {
            Limit::ParsedBytes => "--max-scene-mib",
            Limit::IncludeVisits => "--max-include-visits",
            Limit::Primitives => "--max-primitives",
            Limit::Texels => "--max-texels",
        }
    }
}

/// A figure of the budget exceeded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the scene needs more than its limit of {max} {} ({reached} reached; {} raises the limit)", .limit.what(), .limit.flag())]
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
    spent: [u64; 4],
}

impl BudgetMeter {
    /// Adds `amount` to the figure `limit`, failing when it goes over `budget`.
    pub fn spend(
        &mut self,
        budget: &BuildBudget,
        limit: Limit,
        amount: u64,
    ) -> Result<(), OverBudget> {
        let spent = &mut self.spent[limit as usize];
        let reached = spent.saturating_add(amount);
        let max = budget.max(limit);
        if reached > max {
            return Err(OverBudget {
                limit,
                reached,
                max,
            });
        }
        *spent = reached;
        Ok(())
    }

    pub fn spent(&self, limit: Limit) -> u64 {
        self.spent[limit as usize]
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
}
