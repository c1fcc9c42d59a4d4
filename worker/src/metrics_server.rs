//! `yat worker --metrics-addr IP:PORT`: the worker's Prometheus text at `GET /metrics`
//! (and HEAD), on plain HTTP/1 (`http.rs`), and nothing else: any other path is 404, any other
//! method 405, and no request body is read.
//!
//! The token rule is the status page's (docs/status.md): when the worker has a token, every
//! request must carry `Authorization: Bearer TOKEN`, compared in constant time (as SHA-256
//! digests, so not even the length shows); without it the answer is 401 and nothing else.
//! Without a token the endpoint is open, and so a metrics address beyond loopback needs a
//! token or `--insecure` (`Worker::check_metrics_exposure`): TLS client certificates protect
//! the gRPC port only. There are no cookies and no login form: scrapers send headers.
//!
//! Bounds: [`BOUNDS`], at most 8 connections at once, a request head of at most 16 KiB and 32
//! headers arriving within 5 s, a connection at most 60 s long.

use std::convert::Infallible;
use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use hyper::body::Incoming;
use hyper::header::{self, HeaderValue};
use hyper::{Method, Request, Response, StatusCode};
use tokio::net::TcpListener;
use yat_proto::auth::TokenDigest;

use crate::http::{self, HttpBounds};
use crate::prometheus_text::CONTENT_TYPE;

/// What one scraper, or a stranger, can make the endpoint spend.
pub const BOUNDS: HttpBounds = HttpBounds {
    max_connections: 8,
    header_timeout: Duration::from_secs(5),
    connection_lifetime: Duration::from_secs(60),
    // hyper's smallest buffer; a scrape's head is a few hundred bytes.
    max_head_bytes: Some(16 << 10),
    max_headers: Some(32),
};

/// The path served.
pub const PATH: &str = "/metrics";

struct Endpoint<F> {
    /// SHA-256 (hex) of the token, when one is required.
    token_digest: Option<TokenDigest>,
    exposition: F,
}

/// Serves `exposition()` at [`PATH`] on `listener` until `shutdown` resolves; `token`, when
/// given, is required.
pub async fn serve<F>(
    listener: TcpListener,
    token: Option<&str>,
    exposition: F,
    shutdown: impl Future<Output = ()>,
) where
    F: Fn() -> String + Send + Sync + 'static,
{
    let endpoint = Arc::new(Endpoint {
        token_digest: token.map(TokenDigest::of),
        exposition,
    });
    let service = hyper::service::service_fn(move |request| {
        let endpoint = endpoint.clone();
        async move { Ok::<_, Infallible>(endpoint.answer(&request)) }
    });
    http::serve(listener, service, BOUNDS, shutdown).await;
}

impl<F: Fn() -> String> Endpoint<F> {
    fn answer(&self, request: &Request<Incoming>) -> Response<String> {
        if !self.authorized(request) {
            let mut response = plain(StatusCode::UNAUTHORIZED, "a token is required\n");
            response.headers_mut().insert(
                header::WWW_AUTHENTICATE,
                HeaderValue::from_static("Bearer realm=\"yat worker metrics\""),
            );
            return response;
        }
        if request.uri().path() != PATH {
            return plain(StatusCode::NOT_FOUND, "not found\n");
        }
        if request.method() != Method::GET && request.method() != Method::HEAD {
            let mut response = plain(StatusCode::METHOD_NOT_ALLOWED, "GET only\n");
            response
                .headers_mut()
                .insert(header::ALLOW, HeaderValue::from_static("GET, HEAD"));
            return response;
        }
        let mut response = plain(StatusCode::OK, "");
        *response.body_mut() = (self.exposition)();
        response
            .headers_mut()
            .insert(header::CONTENT_TYPE, HeaderValue::from_static(CONTENT_TYPE));
        response
    }

    fn authorized(&self, request: &Request<Incoming>) -> bool {
        let Some(expected) = &self.token_digest else {
            return true;
        };
        expected.matches_bearer(
            request
                .headers()
                .get(header::AUTHORIZATION)
                .map(|v| v.as_bytes()),
        )
    }
}

/// A short text answer that is not cached or sniffed.
fn plain(status: StatusCode, text: &str) -> Response<String> {
    let mut response = Response::new(text.to_string());
    *response.status_mut() = status;
    let headers = response.headers_mut();
    headers.insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("text/plain; charset=utf-8"),
    );
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    headers.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    response
}

#[cfg(test)]
mod tests {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};

    use super::*;

    /// Sends `request` (raw bytes) on a new connection; the answer's status code and text.
    async fn exchange(address: std::net::SocketAddr, request: &[u8]) -> (u16, String) {
        let mut stream = tokio::net::TcpStream::connect(address).await.unwrap();
        stream.write_all(request).await.unwrap();
        let mut raw = Vec::new();
        let read = stream.read_to_end(&mut raw);
        tokio::time::timeout(Duration::from_secs(30), read)
            .await
            .expect("the server answers and closes")
            .unwrap();
        let text = String::from_utf8_lossy(&raw).into_owned();
        let code = text
            .split(' ')
            .nth(1)
            .and_then(|c| c.parse().ok())
            .unwrap_or(0);
        (code, text)
    }

    fn request(method: &str, path: &str, headers: &[&str]) -> Vec<u8> {
        let mut text = format!("{method} {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n");
        for header in headers {
            text.push_str(header);
            text.push_str("\r\n");
        }
        text.push_str("\r\n");
        text.into_bytes()
    }

    #[tokio::test]
    async fn the_token_the_path_the_method_and_the_head_bound() {
        let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
        let address = listener.local_addr().unwrap();
        let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
        let server = tokio::spawn(serve(
            listener,
            Some("s3cret"),
            || "yat_node_units_total 7\n".to_string(),
            async {
                let _ = stopped.await;
            },
        ));
        let token = "Authorization: Bearer s3cret";
        for (method, path, headers, code) in [
            ("GET", "/metrics", vec![], 401),
            ("GET", "/metrics", vec!["Authorization: Bearer wrong"], 401),
            ("GET", "/metrics", vec!["Authorization: s3cret"], 401),
            ("GET", "/other", vec![], 401),
            ("GET", "/metrics", vec![token], 200),
            ("GET", "/metrics?x=1", vec![token], 200),
            ("GET", "/", vec![token], 404),
            ("GET", "/metrics/../etc/passwd", vec![token], 404),
            ("POST", "/metrics", vec![token], 405),
        ] {
            let (got, text) = exchange(address, &request(method, path, &headers)).await;
            assert_eq!(got, code, "{method} {path} {headers:?}: {text}");
            match code {
                200 => {
                    assert!(text.contains(&format!("content-type: {CONTENT_TYPE}\r\n")));
                    assert!(text.ends_with("\r\n\r\nyat_node_units_total 7\n"), "{text}");
                }
                401 => {
                    assert!(text.contains("www-authenticate: Bearer"), "{text}");
                    assert!(!text.contains("yat_node"), "{text}");
                }
                _ => assert!(!text.contains("yat_node"), "{text}"),
            }
        }
        // A head over 16 KiB, or with too many headers, is refused and nothing served.
        let big = format!("X-Big: {}", "a".repeat(20 << 10));
        let (code, text) = exchange(address, &request("GET", "/metrics", &[token, &big])).await;
        assert!(code == 431 || code == 0, "{text}");
        assert!(!text.contains("yat_node"));
        let many: Vec<String> = (0..40).map(|i| format!("X-{i}: {i}")).collect();
        let mut headers: Vec<&str> = many.iter().map(String::as_str).collect();
        headers.push(token);
        let (code, text) = exchange(address, &request("GET", "/metrics", &headers)).await;
        assert!(code == 431 || code == 0, "{text}");
        // The server stops at its shutdown, a silent connection still open.
        let _silent = tokio::net::TcpStream::connect(address).await.unwrap();
        stop.send(()).unwrap();
        tokio::time::timeout(Duration::from_secs(30), server)
            .await
            .expect("serve returns at shutdown")
            .unwrap();
        assert!(tokio::net::TcpStream::connect(address).await.is_err());
    }

    #[tokio::test]
    async fn without_a_token_it_is_open() {
        let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
        let address = listener.local_addr().unwrap();
        tokio::spawn(serve(
            listener,
            None,
            || "a 1\n".to_string(),
            std::future::pending(),
        ));
        let (code, text) = exchange(address, &request("GET", "/metrics", &[])).await;
        assert_eq!(code, 200, "{text}");
        let (code, _) = exchange(address, &request("HEAD", "/metrics", &[])).await;
        assert_eq!(code, 200);
    }
}
