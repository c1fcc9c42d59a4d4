//! A bounded HTTP/1 server loop on hyper, for the small HTTP endpoints YAT serves: a worker's
//! `/metrics` (`metrics_server.rs`) and the coordinator's status page. What a peer can make it
//! spend is bounded by [`HttpBounds`]: connections at once (more wait in the listen backlog),
//! the time a request's head may take to arrive, a connection's whole life (keep-alive and
//! slow readers included), and optionally the head's bytes and header count (beyond them
//! hyper answers 431 and closes). It stops accepting when `shutdown` resolves and ends the
//! connections still open.

use std::error::Error;
use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use hyper::body::{Body, Incoming};
use hyper::service::Service;
use hyper::{Request, Response};
use hyper_util::rt::{TokioIo, TokioTimer};
use tokio::net::TcpListener;
use tokio::sync::Semaphore;
use tokio::task::JoinSet;

/// The pause after `accept` failed (out of descriptors and the like), rather than a spin.
const ACCEPT_RETRY: Duration = Duration::from_millis(100);

/// What one server lets a peer spend.
#[derive(Clone, Copy, Debug)]
pub struct HttpBounds {
    /// Connections served at once; more wait in the listen backlog.
    pub max_connections: usize,
    /// A request's head must arrive within this.
    pub header_timeout: Duration,
    /// A connection is closed this long after its accept, whatever it is doing.
    pub connection_lifetime: Duration,
    /// The most bytes of a request head (request line and headers); `None`: hyper's default
    /// buffer limit (about 400 KiB).
    pub max_head_bytes: Option<usize>,
    /// The most headers of a request; `None`: hyper's default (100).
    pub max_headers: Option<usize>,
}

/// Serves `service` on `listener` within `bounds` until `shutdown` resolves, then closes the
/// connections still open and returns.
pub async fn serve<S, B>(
    listener: TcpListener,
    service: S,
    bounds: HttpBounds,
    shutdown: impl Future<Output = ()>,
) where
    S: Service<Request<Incoming>, Response = Response<B>> + Clone + Send + 'static,
    S::Future: Send + 'static,
    S::Error: Into<Box<dyn Error + Send + Sync>>,
    B: Body + Send + 'static,
    B::Data: Send,
    B::Error: Into<Box<dyn Error + Send + Sync>>,
{
    let open = Arc::new(Semaphore::new(bounds.max_connections.max(1)));
    let mut connections = JoinSet::new();
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new())
        .header_read_timeout(bounds.header_timeout);
    if let Some(bytes) = bounds.max_head_bytes {
        http.max_buf_size(bytes);
    }
    if let Some(headers) = bounds.max_headers {
        http.max_headers(headers);
    }
    tokio::pin!(shutdown);
    loop {
        let accepted = tokio::select! {
            biased;
            () = &mut shutdown => break,
            accepted = accept(&listener, &open) => accepted,
        };
        // Finished connections' tasks, so the set holds only live ones.
        while connections.try_join_next().is_some() {}
        let Some((stream, permit)) = accepted else {
            tokio::time::sleep(ACCEPT_RETRY).await;
            continue;
        };
        let connection = http.serve_connection(TokioIo::new(stream), service.clone());
        connections.spawn(async move {
            let _ = tokio::time::timeout(bounds.connection_lifetime, connection).await;
            drop(permit);
        });
    }
    connections.shutdown().await;
}

/// The next connection once a slot is free; `None` when `accept` failed.
async fn accept(
    listener: &TcpListener,
    open: &Arc<Semaphore>,
) -> Option<(tokio::net::TcpStream, tokio::sync::OwnedSemaphorePermit)> {
    let permit = open
        .clone()
        .acquire_owned()
        .await
        .expect("the semaphore is never closed");
    let (stream, _) = listener.accept().await.ok()?;
    Some((stream, permit))
}

#[cfg(test)]
mod tests {
    use std::convert::Infallible;

    use tokio::io::{AsyncReadExt, AsyncWriteExt};

    use super::*;

    fn bounds(max_connections: usize) -> HttpBounds {
        HttpBounds {
            max_connections,
            header_timeout: Duration::from_millis(200),
            connection_lifetime: Duration::from_secs(1),
            max_head_bytes: None,
            max_headers: None,
        }
    }

    async fn start(bounds: HttpBounds) -> std::net::SocketAddr {
        let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
        let address = listener.local_addr().unwrap();
        let service = hyper::service::service_fn(|_| async {
            Ok::<_, Infallible>(Response::new("hello".to_string()))
        });
        tokio::spawn(serve(listener, service, bounds, std::future::pending()));
        address
    }

    /// Bytes until the server closes the connection, within a generous bound.
    async fn until_closed(stream: &mut tokio::net::TcpStream) -> Vec<u8> {
        let mut raw = Vec::new();
        tokio::time::timeout(Duration::from_secs(30), stream.read_to_end(&mut raw))
            .await
            .expect("the server closes the connection")
            .unwrap_or(0);
        raw
    }

    #[tokio::test]
    async fn a_silent_or_slow_peer_is_closed_at_its_deadlines() {
        let address = start(bounds(4)).await;
        // Nothing sent: closed at the head's deadline.
        let mut silent = tokio::net::TcpStream::connect(address).await.unwrap();
        assert!(until_closed(&mut silent).await.is_empty());
        // Half a head: the same.
        let mut slow = tokio::net::TcpStream::connect(address).await.unwrap();
        slow.write_all(b"GET / HTTP/1.1\r\nHost").await.unwrap();
        let raw = until_closed(&mut slow).await;
        assert!(!String::from_utf8_lossy(&raw).contains("hello"));
        // A kept-alive connection that asks nothing more: closed too, after its answer.
        let mut kept = tokio::net::TcpStream::connect(address).await.unwrap();
        kept.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")
            .await
            .unwrap();
        let raw = until_closed(&mut kept).await;
        assert!(String::from_utf8_lossy(&raw).ends_with("hello"));
    }

    #[tokio::test]
    async fn connections_beyond_the_cap_wait_for_a_slot() {
        let address = start(bounds(1)).await;
        let mut first = tokio::net::TcpStream::connect(address).await.unwrap();
        let mut second = tokio::net::TcpStream::connect(address).await.unwrap();
        second
            .write_all(b"GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
            .await
            .unwrap();
        // The second is answered once the first, silent, is closed at its deadline.
        assert!(until_closed(&mut first).await.is_empty());
        let raw = until_closed(&mut second).await;
        assert!(String::from_utf8_lossy(&raw).ends_with("hello"));
    }
}
