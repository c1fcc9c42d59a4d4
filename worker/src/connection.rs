//! The connections a worker accepts: at most so many at once (connection N+1 waits in the
//! listen backlog until one closes), each admitted as pending until a request on it passes the
//! token check (`admission.rs`), closed when it has not done so by the handshake deadline or
//! when its peer sends nothing for a while, with TCP keepalive so a vanished peer's socket does
//! not linger. The worker's HTTP/2 keepalive pings every peer every few seconds and a live
//! peer's stack answers, so only dead or silent peers reach the idle limit.
//!
//! The accept loop survives every error `accept` can return: those that concern one
//! connection (ECONNABORTED, a reset before the accept) are skipped, those that concern the
//! process or the system (EMFILE, ENFILE, ENOBUFS, ENOMEM) back off from
//! [`FIRST_BACKOFF`] to [`LAST_BACKOFF`] and report NOT_SERVING until an accept succeeds. Its
//! warnings are rate-limited, so a flood writes a line per cause per interval.
//!
//! Each connection is counted while it is open (and once authenticated), and each one closed
//! for admission, the handshake deadline or a token check that failed is counted under its
//! reason (`metrics.rs`).

use std::future::Future;
use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;

use futures_util::Stream;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{OwnedSemaphorePermit, Semaphore};
use tokio::time::{Instant, Sleep};
use tonic::service::Interceptor;
use tonic::transport::server::Connected;
use tonic::{Request, Status};
use yat_proto::auth::RequireToken;

use crate::admission::{Admission, ConnectionStanding};
use crate::availability::Availability;
use crate::log_limit::{LogLimit, LOG_INTERVAL};
use crate::metrics::{Metrics, OpenConnection, Refusal};

/// Idle time before the kernel's TCP keepalive probes a silent peer.
const TCP_KEEPALIVE: Duration = Duration::from_secs(60);

/// The first pause after `accept` failed for want of descriptors, buffers or memory; each
/// failure in a row doubles it up to [`LAST_BACKOFF`].
pub const FIRST_BACKOFF: Duration = Duration::from_millis(10);
pub const LAST_BACKOFF: Duration = Duration::from_secs(1);

/// How long a connection may stay silent, and stay unauthenticated.
#[derive(Clone, Copy, Debug)]
pub struct ConnectionTimeouts {
    /// Closed after this long without a byte from the peer.
    pub idle: Duration,
    /// Closed when no request on it has passed the token check by then.
    pub handshake: Duration,
}

/// What the accept loop works with.
pub struct Acceptor {
    pub listener: TcpListener,
    pub max_connections: usize,
    pub admission: Arc<Admission>,
    pub timeouts: ConnectionTimeouts,
    pub availability: Arc<Availability>,
    pub metrics: Arc<Metrics>,
}

struct AcceptLoop {
    acceptor: Acceptor,
    slots: Arc<Semaphore>,
    backoff: Duration,
    log: LogLimit,
}

/// The connections the acceptor's listener accepts and admits.
pub fn accept(acceptor: Acceptor) -> impl Stream<Item = io::Result<Connection>> {
    let state = AcceptLoop {
        slots: Arc::new(Semaphore::new(acceptor.max_connections.max(1))),
        acceptor,
        backoff: FIRST_BACKOFF,
        log: LogLimit::new(LOG_INTERVAL),
    };
    futures_util::stream::unfold(state, |mut state| async move {
        let connection = state.next().await;
        Some((Ok(connection), state))
    })
}

impl AcceptLoop {
    async fn next(&mut self) -> Connection {
        let slot = match self.slots.clone().try_acquire_owned() {
            Ok(slot) => slot,
            Err(_) => {
                self.acceptor.availability.set_accepting(false).await;
                self.log.warn(
                    "connections full",
                    format_args!(
                        "all {} connection slots are taken; new connections wait",
                        self.acceptor.max_connections
                    ),
                );
                self.slots
                    .clone()
                    .acquire_owned()
                    .await
                    .expect("never closed")
            }
        };
        loop {
            let (stream, peer) = match self.acceptor.listener.accept().await {
                Ok(accepted) => accepted,
                Err(error) => {
                    self.failed(error).await;
                    continue;
                }
            };
            self.backoff = FIRST_BACKOFF;
            self.acceptor.availability.set_accepting(true).await;
            self.acceptor.metrics.connection_accepted();
            if let Err(error) = configure(&stream) {
                self.log.warn(
                    "socket options",
                    format_args!("cannot set up a connection from {peer}: {error}"),
                );
                continue;
            }
            match self.acceptor.admission.admit(peer.ip()) {
                Ok(standing) => {
                    let metrics = self.acceptor.metrics.clone();
                    let timeouts = self.acceptor.timeouts;
                    return Connection::new(stream, timeouts, standing, slot, metrics);
                }
                Err(full) => {
                    self.acceptor.metrics.refused(Refusal::AddressFull);
                    self.log.warn(
                        "peer over its allowance",
                        format_args!("connection closed at once: {full}"),
                    )
                }
            }
        }
    }

    /// After `accept` failed: skips a failure of one connection, backs off from one of the
    /// process or the system.
    async fn failed(&mut self, error: io::Error) {
        if concerns_one_connection(&error) {
            return;
        }
        self.acceptor.availability.set_accepting(false).await;
        self.log.warn(
            accept_failure_cause(&error),
            format_args!(
                "cannot accept a connection: {error}; retrying in {} ms",
                self.backoff.as_millis()
            ),
        );
        tokio::time::sleep(self.backoff).await;
        self.backoff = (self.backoff * 2).min(LAST_BACKOFF);
    }
}

/// Errors `accept` returns for a connection that went away before it was accepted.
fn concerns_one_connection(error: &io::Error) -> bool {
    matches!(
        error.kind(),
        io::ErrorKind::ConnectionAborted
            | io::ErrorKind::ConnectionReset
            | io::ErrorKind::Interrupted
            | io::ErrorKind::WouldBlock
    ) || error.raw_os_error() == Some(libc::EPROTO)
}

/// The rate limiter's cause for an accept failure: a fixed name per errno.
fn accept_failure_cause(error: &io::Error) -> &'static str {
    match error.raw_os_error() {
        Some(libc::EMFILE) => "accept: EMFILE",
        Some(libc::ENFILE) => "accept: ENFILE",
        Some(libc::ENOBUFS) => "accept: ENOBUFS",
        Some(libc::ENOMEM) => "accept: ENOMEM",
        _ => "accept: other",
    }
}

fn configure(stream: &TcpStream) -> io::Result<()> {
    stream.set_nodelay(true)?;
    let keepalive = socket2::TcpKeepalive::new().with_time(TCP_KEEPALIVE);
    socket2::SockRef::from(stream).set_tcp_keepalive(&keepalive)
}

/// One accepted connection: the socket, its deadlines, its standing and its slot among the
/// connections.
pub struct Connection {
    stream: TcpStream,
    idle: Duration,
    idle_deadline: Pin<Box<Sleep>>,
    /// Until a request on it passes the token check.
    handshake_deadline: Option<Pin<Box<Sleep>>>,
    /// Why it is closing, once it is (counted once, reported to every later read).
    closing: Option<Closing>,
    standing: ConnectionStanding,
    metrics: Arc<Metrics>,
    /// Counts the connection as open, and as authenticated once it is.
    open: OpenConnection,
    _slot: OwnedSemaphorePermit,
}

/// Why a connection that never authenticated is closed.
#[derive(Clone, Copy, Debug)]
enum Closing {
    Evicted,
    HandshakeDeadline,
}

impl Closing {
    fn refusal(self) -> Refusal {
        match self {
            Closing::Evicted => Refusal::UnauthenticatedEvicted,
            Closing::HandshakeDeadline => Refusal::HandshakeTimeout,
        }
    }

    fn error(self) -> io::Error {
        match self {
            Closing::Evicted => io::Error::new(
                io::ErrorKind::ConnectionAborted,
                "closed before it authenticated, to make room for a newer connection",
            ),
            Closing::HandshakeDeadline => io::Error::new(
                io::ErrorKind::TimedOut,
                "no authenticated request before the handshake deadline",
            ),
        }
    }
}

impl Connection {
    fn new(
        stream: TcpStream,
        timeouts: ConnectionTimeouts,
        standing: ConnectionStanding,
        slot: OwnedSemaphorePermit,
        metrics: Arc<Metrics>,
    ) -> Self {
        Self {
            stream,
            idle: timeouts.idle,
            idle_deadline: Box::pin(tokio::time::sleep(timeouts.idle)),
            handshake_deadline: Some(Box::pin(tokio::time::sleep(timeouts.handshake))),
            closing: None,
            standing,
            open: metrics.open_connection(),
            metrics,
            _slot: slot,
        }
    }

    /// Why the connection is to close now, if it is.
    fn poll_closing(&mut self, cx: &mut Context<'_>) -> Option<io::Error> {
        if let Some(closing) = self.closing {
            return Some(closing.error());
        }
        let Some(handshake) = &mut self.handshake_deadline else {
            return None;
        };
        if self.standing.is_authenticated() {
            self.handshake_deadline = None;
            self.open.authenticated();
            return None;
        }
        let closing = if self.standing.is_evicted(cx.waker()) {
            Closing::Evicted
        } else if handshake.as_mut().poll(cx).is_ready() {
            Closing::HandshakeDeadline
        } else {
            return None;
        };
        self.metrics.refused(closing.refusal());
        self.closing = Some(closing);
        Some(closing.error())
    }
}

impl Drop for Connection {
    fn drop(&mut self) {
        self.standing.closed();
    }
}

/// What every request on a connection carries in its extensions: the connection's standing.
#[derive(Clone, Debug)]
pub struct ConnectionInfo {
    pub standing: ConnectionStanding,
}

impl Connected for Connection {
    type ConnectInfo = ConnectionInfo;

    fn connect_info(&self) -> ConnectionInfo {
        ConnectionInfo {
            standing: self.standing.clone(),
        }
    }
}

/// The token check, which also marks the connection of a request that passes it as
/// authenticated (no longer subject to the handshake deadline and the pending caps), and
/// counts the requests it refuses.
#[derive(Clone)]
pub struct Authenticate {
    pub token: RequireToken,
    pub metrics: Arc<Metrics>,
}

impl Interceptor for Authenticate {
    fn call(&mut self, request: Request<()>) -> Result<Request<()>, Status> {
        let bearer = request
            .metadata()
            .get("authorization")
            .and_then(|v| v.to_str().ok())
            .is_some_and(|v| v.starts_with("Bearer "));
        let request = self.token.call(request).inspect_err(|_| {
            self.metrics.refused(if bearer {
                Refusal::TokenWrong
            } else {
                Refusal::TokenMissing
            });
        })?;
        if let Some(info) = request.extensions().get::<ConnectionInfo>() {
            info.standing.authenticated();
        }
        Ok(request)
    }
}

impl AsyncRead for Connection {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        if let Some(closing) = self.poll_closing(cx) {
            return Poll::Ready(Err(closing));
        }
        let before = buf.filled().len();
        match Pin::new(&mut self.stream).poll_read(cx, buf) {
            Poll::Ready(result) => {
                if buf.filled().len() > before {
                    let next = Instant::now() + self.idle;
                    self.idle_deadline.as_mut().reset(next);
                }
                Poll::Ready(result)
            }
            Poll::Pending => match self.idle_deadline.as_mut().poll(cx) {
                Poll::Ready(()) => Poll::Ready(Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    "the peer sent nothing for too long",
                ))),
                Poll::Pending => Poll::Pending,
            },
        }
    }
}

impl AsyncWrite for Connection {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.stream).poll_write(cx, buf)
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.stream).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.stream).poll_shutdown(cx)
    }

    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.stream).poll_write_vectored(cx, bufs)
    }

    fn is_write_vectored(&self) -> bool {
        self.stream.is_write_vectored()
    }
}
