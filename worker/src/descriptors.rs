//! The connections the process's file descriptor limit leaves room for. Every connection is a
//! descriptor; so are the listener, the runtime's own, the standard streams and the files the
//! disk cache opens while it reads or writes a blob. A cap above what the limit allows would
//! let connections take the descriptors the rest needs, and `accept` fail with EMFILE.

use std::io;

/// Descriptors kept for everything but connections, beyond those open when the worker starts:
/// the disk cache's files (one per blob being read or written), the health service's and the
/// runtime's, with room to spare.
pub const DESCRIPTOR_HEADROOM: u64 = 64;

/// The connection cap a worker runs with, and what it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConnectionCap {
    pub connections: usize,
    /// The process's descriptor limit (the soft limit, raised to the hard one where allowed).
    pub descriptor_limit: u64,
    /// Descriptors open when the cap was set.
    pub in_use: u64,
}

impl ConnectionCap {
    /// The cap for `asked` connections under `descriptor_limit` with `in_use` descriptors open:
    /// at most what the limit leaves after those and [`DESCRIPTOR_HEADROOM`]; `None` when that
    /// is no connection at all.
    pub fn under(asked: usize, descriptor_limit: u64, in_use: u64) -> Option<Self> {
        let room = descriptor_limit
            .saturating_sub(in_use)
            .saturating_sub(DESCRIPTOR_HEADROOM);
        let connections = (asked as u64).min(room);
        (connections > 0).then_some(Self {
            connections: connections as usize,
            descriptor_limit,
            in_use,
        })
    }

    /// The cap for `asked` connections in this process, after raising its soft descriptor
    /// limit to the hard one.
    pub fn of_this_process(asked: usize) -> io::Result<Option<Self>> {
        let limit = raise_descriptor_limit()?;
        Ok(Self::under(asked, limit, descriptors_in_use()))
    }
}

/// Raises the soft limit on open descriptors to the hard limit and returns the soft limit then
/// in force.
fn raise_descriptor_limit() -> io::Result<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given, which lives for the call.
    if unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut limit) } != 0 {
        return Err(io::Error::last_os_error());
    }
    if limit.rlim_cur < limit.rlim_max {
        let raised = libc::rlimit {
            rlim_cur: limit.rlim_max,
            rlim_max: limit.rlim_max,
        };
        // SAFETY: setrlimit reads the struct it is given, which lives for the call.
        if unsafe { libc::setrlimit(libc::RLIMIT_NOFILE, &raised) } == 0 {
            limit = raised;
        }
    }
    Ok(limit.rlim_cur)
}

/// Descriptors open now (the entries of /proc/self/fd, less the one reading it); 0 where the
/// system has no /proc.
fn descriptors_in_use() -> u64 {
    std::fs::read_dir("/proc/self/fd")
        .map(|entries| entries.count().saturating_sub(1) as u64)
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cap_leaves_the_headroom_and_what_is_open() {
        let cap = ConnectionCap::under(256, 256, 10).unwrap();
        assert_eq!(cap.connections, 256 - 10 - DESCRIPTOR_HEADROOM as usize);
        // A generous limit keeps the cap asked for.
        assert_eq!(
            ConnectionCap::under(256, 1 << 20, 10).unwrap().connections,
            256
        );
        // No room at all, and infinite limits (RLIM_INFINITY is u64::MAX).
        assert_eq!(ConnectionCap::under(256, 60, 10), None);
        assert_eq!(
            ConnectionCap::under(256, u64::MAX, 10).unwrap().connections,
            256
        );
    }

    #[test]
    fn this_process_gets_a_cap_within_its_limit() {
        let cap = ConnectionCap::of_this_process(usize::MAX).unwrap().unwrap();
        assert!(cap.in_use >= 3, "{cap:?}");
        assert!(
            cap.connections as u64 + cap.in_use + DESCRIPTOR_HEADROOM <= cap.descriptor_limit,
            "{cap:?}"
        );
    }
}
