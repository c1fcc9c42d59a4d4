//! Durations given on the command line in seconds (`--checkpoint-every`, `--timeout`, ...).

use std::time::Duration;

use anyhow::Context;

/// The option `--name` given as `value` seconds.
pub fn seconds(name: &str, value: f64) -> anyhow::Result<Duration> {
    Duration::try_from_secs_f64(value)
        .with_context(|| format!("--{name} must be a non-negative number of seconds"))
}
