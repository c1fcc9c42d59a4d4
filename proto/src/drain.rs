//! How a draining worker says so. A worker that got SIGTERM (Slurm or Kubernetes taking its
//! node) stops taking work: it answers new calls, and units still waiting for a render thread,
//! with UNAVAILABLE carrying the `yat-draining` metadata entry. A coordinator that sees it puts
//! the unit back in the queue at once, without counting a failure, and does not hand that
//! worker more units until a new session's handshake succeeds.

use tonic::metadata::MetadataValue;
use tonic::{Code, Status};

/// The metadata key that marks a status as a drain, not a failure.
pub const DRAINING_KEY: &str = "yat-draining";

/// The status a draining worker answers with, `what` saying what it refused.
pub fn draining_status(what: &str) -> Status {
    let mut status = Status::unavailable(format!("worker draining: {what} refused"));
    status
        .metadata_mut()
        .insert(DRAINING_KEY, MetadataValue::from_static("1"));
    status
}

/// Whether `status` is a draining worker's refusal.
pub fn is_draining(status: &Status) -> bool {
    status.code() == Code::Unavailable && status.metadata().contains_key(DRAINING_KEY)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drain_is_told_apart_from_an_outage() {
        assert!(is_draining(&draining_status("unit 3")));
        assert!(!is_draining(&Status::unavailable("connection refused")));
        let mut marked_but_other_code = Status::internal("x");
        marked_but_other_code
            .metadata_mut()
            .insert(DRAINING_KEY, MetadataValue::from_static("1"));
        assert!(!is_draining(&marked_but_other_code));
    }
}
