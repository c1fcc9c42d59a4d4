//! Warnings a peer can repeat at will (a flood of connections the worker cannot accept, for
//! one), logged at most once per cause per interval with the count of those held back: a flood
//! costs a few lines a minute, not a line per event, so the log stays readable and its pipe
//! does not fill.

use std::collections::HashMap;
use std::fmt;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// One line per cause this often at most.
pub const LOG_INTERVAL: Duration = Duration::from_secs(10);

/// Per cause: when it was last logged and how many times it came since.
#[derive(Debug)]
pub struct LogLimit {
    interval: Duration,
    causes: Mutex<HashMap<&'static str, Window>>,
}

#[derive(Debug)]
struct Window {
    logged: Instant,
    held_back: u64,
}

impl LogLimit {
    pub fn new(interval: Duration) -> Self {
        Self {
            interval,
            causes: Mutex::new(HashMap::new()),
        }
    }

    /// Whether a warning of `cause` at `now` is logged, and if so how many of that cause were
    /// held back since the last one logged. Causes are a fixed set of names in the code, so the
    /// table never grows with what peers send.
    pub fn admit(&self, cause: &'static str, now: Instant) -> Option<u64> {
        let mut causes = self.causes.lock().unwrap_or_else(|e| e.into_inner());
        match causes.get_mut(cause) {
            Some(window) if now.saturating_duration_since(window.logged) < self.interval => {
                window.held_back += 1;
                None
            }
            Some(window) => {
                let held_back = window.held_back;
                *window = Window {
                    logged: now,
                    held_back: 0,
                };
                Some(held_back)
            }
            None => {
                causes.insert(
                    cause,
                    Window {
                        logged: now,
                        held_back: 0,
                    },
                );
                Some(0)
            }
        }
    }

    /// Logs `message` as a warning unless a warning of `cause` was logged less than the
    /// interval ago.
    pub fn warn(&self, cause: &'static str, message: fmt::Arguments<'_>) {
        match self.admit(cause, Instant::now()) {
            Some(0) => tracing::warn!("{message}"),
            Some(held_back) => tracing::warn!(
                "{message} (and {held_back} more like it in the last {} s)",
                self.interval.as_secs()
            ),
            None => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_per_cause_per_interval_with_the_count_held_back() {
        let limit = LogLimit::new(Duration::from_secs(10));
        let start = Instant::now();
        let at = |ms: u64| start + Duration::from_millis(ms);
        assert_eq!(limit.admit("accept", at(0)), Some(0));
        // A flood of 1000 within the interval: none logged.
        for ms in 1..=1000 {
            assert_eq!(limit.admit("accept", at(ms)), None);
        }
        // Another cause has a window of its own.
        assert_eq!(limit.admit("cache", at(500)), Some(0));
        // The first after the interval carries the count.
        assert_eq!(limit.admit("accept", at(10_000)), Some(1000));
        assert_eq!(limit.admit("accept", at(10_001)), None);
        assert_eq!(limit.admit("accept", at(25_000)), Some(1));
    }
}
