//! How a session with a worker ended badly, which decides what its loop does next.

pub enum SessionError {
    /// The connection failed or was lost (worker restarting, network): worth trying again
    /// later, and no fault of the worker's.
    Transient(String),
    /// The worker answered, wrongly: an invalid result, an error status, no answer within the
    /// deadline. Worth trying again later, but a worker that does nothing else is retired.
    BadReply(String),
    /// The worker is draining (SIGTERM): what it held goes back to the queue, no fault counted;
    /// it may be back after a restart.
    Draining(String),
    /// This worker cannot serve this render (token, protocol version, limits, a scene it
    /// cannot load).
    Permanent(String),
}
