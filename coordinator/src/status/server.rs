//! The status page's HTTP server (`yat render --status-addr`): axum routes on hyper, on a
//! runtime of its own so the render never waits for it. It serves only what it generates:
//! `/` the page, `/api/status` the JSON, `/metrics` the Prometheus text, `/image.png` the
//! image so far; any other path is 404 and any method but GET (and HEAD) is 405. No request
//! body is read, and no file is opened by a path from a request.
//!
//! With a token (`--token`, `--token-file`, `YAT_TOKEN`) every request must carry it: an
//! `Authorization: Bearer` header, or the cookie that `?token=...` in a URL (or the login form)
//! sets once. Without it the answer is 401 with the login form and nothing else.
//!
//! Bounds: at most [`MAX_CONNECTIONS`] connections at once (more wait to be accepted), the
//! request head within [`HEADER_TIMEOUT`], a connection at most [`CONNECTION_LIFETIME`] long,
//! applied by the bounded HTTP/1 loop a worker's `/metrics` is served on too
//! (`yat_worker::http`).

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use axum::body::Body;
use axum::extract::{Request, State};
use axum::http::{header, HeaderMap, HeaderValue, Method, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;
use yat_proto::auth::TokenDigest;
use yat_worker::http::HttpBounds;

use super::board::StatusBoard;
use super::metrics;

/// Connections served at once; more wait in the listen queue.
pub const MAX_CONNECTIONS: usize = 32;
/// A request's head must arrive within this.
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(5);
/// A connection (keep-alive included) is closed after this; a browser opens another.
pub const CONNECTION_LIFETIME: Duration = Duration::from_secs(60);
/// The bounds above; a request head's size and header count are hyper's defaults (about
/// 400 KiB, 100 headers: a browser may send every cookie of its host).
const BOUNDS: HttpBounds = HttpBounds {
    max_connections: MAX_CONNECTIONS,
    header_timeout: HEADER_TIMEOUT,
    connection_lifetime: CONNECTION_LIFETIME,
    max_head_bytes: None,
    max_headers: None,
};

const PAGE: &str = include_str!("page.html");
const LOGIN: &str = include_str!("login.html");
/// The cookie holding the token's SHA-256 (hex), not the token itself.
const COOKIE: &str = "yat_status";
/// What the page may load: itself, its own inline script and style, its own image and JSON.
const CSP: &str = "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
                   img-src 'self'; connect-src 'self'; form-action 'self'; \
                   frame-ancestors 'none'; base-uri 'none'";

#[derive(Debug, thiserror::Error)]
pub enum StatusServerError {
    #[error("cannot listen on {address} (--status-addr): {source}")]
    Listen {
        address: SocketAddr,
        source: std::io::Error,
    },
    #[error("cannot start the status server's runtime: {0}")]
    Runtime(std::io::Error),
}

/// The running server; it stops when dropped.
pub struct StatusServer {
    runtime: Option<tokio::runtime::Runtime>,
    address: SocketAddr,
}

struct AppState {
    board: Arc<StatusBoard>,
    /// SHA-256 (hex) of the token, when one is required.
    token_digest: Option<TokenDigest>,
    /// The newest image encoded: (generation, PNG bytes). Encoding holds the lock, so one
    /// request encodes and the others wait for its bytes.
    png: tokio::sync::Mutex<(u64, axum::body::Bytes)>,
}

impl StatusServer {
    /// Listens on `address` and serves `board` until dropped; `token` protects it.
    pub fn start(
        address: SocketAddr,
        board: Arc<StatusBoard>,
        token: Option<&str>,
    ) -> Result<Self, StatusServerError> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .max_blocking_threads(2)
            .thread_name("yat-status")
            .enable_all()
            .build()
            .map_err(StatusServerError::Runtime)?;
        let listener = runtime
            .block_on(TcpListener::bind(address))
            .map_err(|source| StatusServerError::Listen { address, source })?;
        let bound = listener
            .local_addr()
            .map_err(|source| StatusServerError::Listen { address, source })?;
        let state = Arc::new(AppState {
            board,
            token_digest: token.map(TokenDigest::of),
            png: tokio::sync::Mutex::new((0, axum::body::Bytes::new())),
        });
        let service = TowerToHyperService::new(router(state));
        // It serves until the runtime is shut down (the server dropped).
        let serving = yat_worker::http::serve(listener, service, BOUNDS, std::future::pending());
        runtime.spawn(serving);
        Ok(Self {
            runtime: Some(runtime),
            address: bound,
        })
    }

    /// The address it listens on (the port chosen when 0 was asked).
    pub fn address(&self) -> SocketAddr {
        self.address
    }
}

impl Drop for StatusServer {
    fn drop(&mut self) {
        if let Some(runtime) = self.runtime.take() {
            runtime.shutdown_background();
        }
    }
}

fn router(state: Arc<AppState>) -> Router {
    Router::new()
        .route("/", get(page))
        .route("/api/status", get(api_status))
        .route("/metrics", get(prometheus))
        .route("/image.png", get(image_png))
        .fallback(not_found)
        .layer(middleware::from_fn_with_state(state.clone(), require_token))
        .layer(middleware::from_fn(common_headers))
        .with_state(state)
}

/// Headers of every answer: nothing cached, nothing sniffed, nothing framed.
async fn common_headers(request: Request, next: Next) -> Response {
    let mut response = next.run(request).await;
    let headers = response.headers_mut();
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    headers.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    headers.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    headers.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(CSP),
    );
    headers.insert(
        header::REFERRER_POLICY,
        HeaderValue::from_static("no-referrer"),
    );
    response
}

/// Lets through a request that carries the token (header, cookie or `?token=`); a token
/// given in the URL sets the cookie, and for the page redirects to the URL without it.
async fn require_token(
    State(state): State<Arc<AppState>>,
    request: Request,
    next: Next,
) -> Response {
    let Some(expected) = &state.token_digest else {
        return next.run(request).await;
    };
    let headers = request.headers();
    let bearer = expected.matches_bearer(headers.get(header::AUTHORIZATION).map(|v| v.as_bytes()));
    let cookie = cookie_value(headers).is_some_and(|digest| expected.matches_digest(digest));
    if bearer || cookie {
        return next.run(request).await;
    }
    let from_url = request.uri().query().and_then(|query| {
        form_urlencoded::parse(query.as_bytes())
            .find(|(name, _)| name == "token")
            .map(|(_, value)| value.into_owned())
    });
    if !from_url
        .as_deref()
        .is_some_and(|t| expected.matches_token(t))
    {
        let challenge = [(header::WWW_AUTHENTICATE, "Bearer realm=\"yat status\"")];
        return (StatusCode::UNAUTHORIZED, challenge, html(LOGIN)).into_response();
    }
    let set_cookie = HeaderValue::try_from(format!(
        "{COOKIE}={}; HttpOnly; SameSite=Strict; Path=/",
        expected.hex()
    ))
    .expect("hex digits make a valid header");
    let mut response = if request.uri().path() == "/" && request.method() == Method::GET {
        // The token leaves the address bar (and the history) at once.
        (StatusCode::SEE_OTHER, [(header::LOCATION, "/")]).into_response()
    } else {
        next.run(request).await
    };
    response
        .headers_mut()
        .append(header::SET_COOKIE, set_cookie);
    response
}

/// The value of our cookie, if the request has it.
fn cookie_value(headers: &HeaderMap) -> Option<&str> {
    headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(|pair| pair.trim().split_once('='))
        .find(|(name, _)| *name == COOKIE)
        .map(|(_, value)| value)
}

fn html(body: &'static str) -> impl IntoResponse {
    ([(header::CONTENT_TYPE, "text/html; charset=utf-8")], body)
}

async fn page() -> impl IntoResponse {
    html(PAGE)
}

async fn api_status(State(state): State<Arc<AppState>>) -> Response {
    match serde_json::to_vec(&state.board.snapshot()) {
        Ok(json) => ([(header::CONTENT_TYPE, "application/json")], json).into_response(),
        Err(_) => StatusCode::INTERNAL_SERVER_ERROR.into_response(),
    }
}

async fn prometheus(State(state): State<Arc<AppState>>) -> impl IntoResponse {
    let text = metrics::render(&state.board.snapshot());
    ([(header::CONTENT_TYPE, metrics::CONTENT_TYPE)], text)
}

/// The newest image as PNG, encoded once per generation (off the runtime's thread).
async fn image_png(State(state): State<Arc<AppState>>) -> Response {
    let Some(published) = state.board.image() else {
        return (StatusCode::SERVICE_UNAVAILABLE, "no image yet").into_response();
    };
    let mut cached = state.png.lock().await;
    if cached.0 != published.generation {
        let image = published.image.clone();
        let started = std::time::Instant::now();
        let encoded = tokio::task::spawn_blocking(move || encode_png(&image)).await;
        state.board.note_encode_cost(started.elapsed());
        match encoded {
            Ok(Ok(png)) => *cached = (published.generation, png.into()),
            _ => return StatusCode::INTERNAL_SERVER_ERROR.into_response(),
        }
    }
    let headers = [
        (header::CONTENT_TYPE, "image/png".to_string()),
        (
            header::HeaderName::from_static("x-yat-image-generation"),
            cached.0.to_string(),
        ),
    ];
    (headers, Body::from(cached.1.clone())).into_response()
}

async fn not_found() -> impl IntoResponse {
    (StatusCode::NOT_FOUND, "not found")
}

/// The fastest PNG that is still small enough for a browser: fdeflate's fast mode and the
/// `Sub` filter. The default (balanced deflate, adaptive filters) took several times longer
/// on a noisy 512x512 image, a share of the render's CPU at one image a second.
fn encode_png(image: &image::RgbImage) -> image::ImageResult<Vec<u8>> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    use image::ImageEncoder;
    let mut png = Vec::new();
    PngEncoder::new_with_quality(&mut png, CompressionType::Fast, FilterType::Sub).write_image(
        image.as_raw(),
        image.width(),
        image.height(),
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(png)
}
