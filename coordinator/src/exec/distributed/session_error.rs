//! How a session with a worker ended badly, which decides what its loop does next.

pub enum SessionError {
    /// Worth trying again later (connection lost, deadline, worker restarted).
    Transient(String),
    /// This worker cannot serve this render (token, protocol version, limits).
    Permanent(String),
    /// Nobody can serve this render.
    Fatal(anyhow::Error),
}
