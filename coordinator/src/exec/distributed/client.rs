//! The client of one worker: the connection (address, TLS, token), every call with its deadline,
//! and what a call's failure means for the session ([`SessionError`]).

use std::time::Duration;

use prost::bytes::Bytes;
use prost::Message;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::{Channel, ClientTlsConfig, Endpoint};
use tonic::{Code, Request, Status};
use yat_proto::auth::AttachToken;
use yat_proto::drain::is_draining;
use yat_proto::{pb, RenderNodeClient, BLOB_CHUNK_BYTES, DEFAULT_MAX_MESSAGE_BYTES};

use super::session_error::SessionError;
use crate::sanitize::peer_text;

const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);
/// Deadline of the small calls (handshake, blob queries, stats).
const CALL_TIMEOUT: Duration = Duration::from_secs(10);
/// Deadline of a scene load: parsing and building a big mesh's BVH takes a while.
const LOAD_TIMEOUT: Duration = Duration::from_secs(600);
/// Upload deadline: a base plus this much time per MiB (a slow 1 MiB/s link still makes it).
const UPLOAD_TIMEOUT_BASE: Duration = Duration::from_secs(30);
const UPLOAD_TIMEOUT_PER_MIB: Duration = Duration::from_secs(1);
/// Smallest blob chunk sent, whatever message limit a worker advertises (the handshake refuses
/// a worker whose limit is below twice this).
pub const MIN_CHUNK_BYTES: usize = 64 << 10;
/// Characters of a worker's error message kept for the terminal and the report.
const MAX_MESSAGE_CHARS: usize = 300;

/// How to reach one worker.
pub struct ClientConfig {
    pub address: String,
    pub token: Option<String>,
    pub tls: Option<ClientTlsConfig>,
}

impl ClientConfig {
    fn endpoint(&self) -> anyhow::Result<Endpoint> {
        let scheme = if self.tls.is_some() { "https" } else { "http" };
        let mut endpoint = Endpoint::from_shared(format!("{scheme}://{}", self.address))
            .map_err(|e| anyhow::anyhow!("bad worker address {:?}: {e}", self.address))?
            .connect_timeout(CONNECT_TIMEOUT)
            .tcp_nodelay(true)
            .http2_keep_alive_interval(Duration::from_secs(10))
            .keep_alive_timeout(Duration::from_secs(20))
            .keep_alive_while_idle(true);
        if let Some(tls) = &self.tls {
            endpoint = endpoint.tls_config(tls.clone())?;
        }
        Ok(endpoint)
    }

    /// Checks the address and token before anything starts.
    pub fn validate(&self) -> anyhow::Result<()> {
        self.endpoint()?;
        AttachToken::new(self.token.as_deref())?;
        Ok(())
    }
}

/// A connection to one worker; clones share it, so units can be in flight side by side.
#[derive(Clone)]
pub struct WorkerClient {
    inner: RenderNodeClient<InterceptedService<Channel, AttachToken>>,
}

impl WorkerClient {
    pub async fn connect(config: &ClientConfig) -> Result<Self, SessionError> {
        let channel = config
            .endpoint()
            .map_err(|e| SessionError::Permanent(format!("{e:#}")))?
            .connect()
            .await
            .map_err(|e| SessionError::Transient(format!("cannot connect: {}", error_chain(&e))))?;
        let token = AttachToken::new(config.token.as_deref())
            .map_err(|e| SessionError::Permanent(e.to_string()))?;
        let inner = RenderNodeClient::with_interceptor(channel, token)
            .max_decoding_message_size(DEFAULT_MAX_MESSAGE_BYTES)
            .max_encoding_message_size(DEFAULT_MAX_MESSAGE_BYTES);
        Ok(Self { inner })
    }

    /// A worker of another protocol version refuses for good.
    pub async fn handshake(
        &mut self,
        hello: pb::HandshakeRequest,
    ) -> Result<pb::HandshakeReply, SessionError> {
        with_deadline(
            CALL_TIMEOUT,
            self.inner.handshake(request(hello, CALL_TIMEOUT)),
        )
        .await
        .map_err(|status| match status.code() {
            Code::FailedPrecondition => SessionError::Permanent(worker_message(&status)),
            _ => call_error("handshake", status),
        })
    }

    /// The blobs of `query` the worker lacks.
    pub async fn missing_blobs(
        &mut self,
        query: pb::HasBlobsRequest,
    ) -> Result<Vec<String>, SessionError> {
        let reply = with_deadline(
            CALL_TIMEOUT,
            self.inner.has_blobs(request(query, CALL_TIMEOUT)),
        )
        .await
        .map_err(|s| call_error("blob query", s))?;
        Ok(reply.missing)
    }

    /// Streams one blob in chunks that fit the worker's message limit, with a deadline that
    /// grows with its size; returns the bytes sent on the wire. A blob the worker finds too
    /// large is refused for good.
    pub async fn put_blob(
        &mut self,
        hash: &str,
        bytes: &Bytes,
        max_message_bytes: u64,
    ) -> Result<u64, SessionError> {
        let half_limit = usize::try_from(max_message_bytes / 2).unwrap_or(usize::MAX);
        let chunk_bytes = BLOB_CHUNK_BYTES.min(half_limit).max(MIN_CHUNK_BYTES);
        let chunks: Vec<pb::BlobChunk> = (0..bytes.len().div_ceil(chunk_bytes).max(1))
            .map(|i| {
                let range = i * chunk_bytes..((i + 1) * chunk_bytes).min(bytes.len());
                pb::BlobChunk {
                    sha256: if i == 0 {
                        hash.to_string()
                    } else {
                        String::new()
                    },
                    size: if i == 0 { bytes.len() as u64 } else { 0 },
                    data: bytes.slice(range),
                }
            })
            .collect();
        let sent: u64 = chunks.iter().map(|c| c.encoded_len() as u64).sum();
        let deadline = UPLOAD_TIMEOUT_BASE
            + UPLOAD_TIMEOUT_PER_MIB * (bytes.len() >> 20).try_into().unwrap_or(u32::MAX);
        with_deadline(
            deadline,
            self.inner
                .put_blob(request(tokio_stream::iter(chunks), deadline)),
        )
        .await
        .map_err(|status| match status.code() {
            Code::ResourceExhausted => SessionError::Permanent(worker_message(&status)),
            _ => call_error("upload", status),
        })?;
        Ok(sent)
    }

    /// A worker that cannot parse or build the scene (INVALID_ARGUMENT, INTERNAL, OUT_OF_RANGE
    /// and the like: errors that would repeat) is the odd one out, since this coordinator parsed
    /// it: that worker is refused for this render, the render goes on with the others.
    pub async fn load_scene(
        &mut self,
        load: pb::LoadSceneRequest,
    ) -> Result<pb::LoadSceneReply, SessionError> {
        with_deadline(
            LOAD_TIMEOUT,
            self.inner.load_scene(request(load, LOAD_TIMEOUT)),
        )
        .await
        .map_err(|status| match status.code() {
            Code::InvalidArgument
            | Code::Internal
            | Code::OutOfRange
            | Code::Unimplemented
            | Code::Unknown
            | Code::DataLoss => SessionError::Permanent(format!(
                "cannot load the scene: {}",
                describe_status(&status)
            )),
            _ => call_error("scene load", status),
        })
    }

    /// One unit, presumed lost after `deadline`.
    pub async fn render_unit(
        &mut self,
        unit: pb::RenderUnitRequest,
        deadline: Duration,
    ) -> Result<pb::RenderUnitReply, SessionError> {
        let index = unit.unit.as_ref().map_or(0, |u| u.index);
        with_deadline(deadline, self.inner.render_unit(request(unit, deadline)))
            .await
            .map_err(|status| call_error(&format!("unit {index}"), status))
    }
}

/// What a failed call means: a drain; a refused token (for good); a lost connection (no
/// fault of the worker's: a status our transport made from an error it carries as its source,
/// or one of the codes that say so); any other status, the deadline included, is a bad reply.
fn call_error(what: &str, status: Status) -> SessionError {
    if is_draining(&status) {
        return SessionError::Draining(format!("{what} refused"));
    }
    let described = format!("{what}: {}", describe_status(&status));
    if std::error::Error::source(&status).is_some() {
        return SessionError::Transient(described);
    }
    match status.code() {
        Code::Unauthenticated => SessionError::Permanent(format!(
            "authentication failed (unauthenticated): {}",
            worker_message(&status)
        )),
        Code::Unavailable | Code::Cancelled | Code::Aborted => SessionError::Transient(described),
        _ => SessionError::BadReply(described),
    }
}

/// The status's code and message, its causes after it, safe to print.
fn describe_status(status: &Status) -> String {
    let text = format!("{:?}: {}", status.code(), worker_message(status));
    match std::error::Error::source(status) {
        Some(cause) => format!("{text}: {}", error_chain(cause)),
        None => text,
    }
}

/// The message a worker (or the transport) put in a status, safe to print.
fn worker_message(status: &Status) -> String {
    peer_text(status.message(), MAX_MESSAGE_CHARS)
}

/// The call's reply, or DEADLINE_EXCEEDED when it takes longer than `deadline` (the request's
/// own timeout tells the worker; this one holds even when the worker does not answer at all).
async fn with_deadline<T>(
    deadline: Duration,
    call: impl std::future::Future<Output = Result<tonic::Response<T>, Status>>,
) -> Result<T, Status> {
    match tokio::time::timeout(deadline, call).await {
        Ok(reply) => reply.map(tonic::Response::into_inner),
        Err(_) => Err(Status::deadline_exceeded(format!(
            "no answer within {:.1} s",
            deadline.as_secs_f64()
        ))),
    }
}

fn request<T>(message: T, deadline: Duration) -> Request<T> {
    let mut request = Request::new(message);
    request.set_timeout(deadline);
    request
}

/// An error and its causes on one line (tonic's transport errors hide the useful part in
/// their sources), safe to print (a peer's bytes may be quoted in them).
fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        // Layers often repeat their cause's words ("transport error: transport error").
        if !text.ends_with(&cause_text) {
            text.push_str(": ");
            text.push_str(&cause_text);
        }
        source = cause.source();
    }
    peer_text(&text, MAX_MESSAGE_CHARS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_authentication_failure_is_permanent_and_says_so() {
        let refused = call_error("handshake", Status::unauthenticated("wrong token"));
        assert!(matches!(refused, SessionError::Permanent(m) if m.contains("authentication")));
        let lost = call_error("unit 3", Status::unavailable("connection reset"));
        assert!(matches!(lost, SessionError::Transient(m) if m.contains("unit 3")));
    }

    #[test]
    fn errors_the_worker_answers_are_bad_replies_and_a_drain_is_none() {
        for status in [
            Status::internal("boom"),
            Status::out_of_range("x"),
            Status::invalid_argument("x"),
            Status::not_found("scene"),
            Status::deadline_exceeded("no answer within 2.0 s"),
        ] {
            let code = status.code();
            assert!(
                matches!(call_error("unit 1", status), SessionError::BadReply(m) if m.contains("unit 1")),
                "{code:?}"
            );
        }
        let broken = std::io::Error::new(std::io::ErrorKind::BrokenPipe, "broken pipe");
        let lost = call_error("unit 1", Status::from_error(Box::new(broken)));
        assert!(matches!(lost, SessionError::Transient(m) if m.contains("broken pipe")));
        let drain = call_error("unit 2", yat_proto::drain::draining_status("unit 2"));
        assert!(matches!(drain, SessionError::Draining(m) if m.contains("unit 2")));
    }

    #[test]
    fn a_workers_message_reaches_the_terminal_without_escapes() {
        let hostile = Status::internal(format!("\x1b]0;pwn\x07\x1b[2J{}", "x".repeat(10_000)));
        let SessionError::BadReply(text) = call_error("unit 1", hostile) else {
            panic!("an error status is a bad reply");
        };
        assert!(!text.contains('\x1b') && !text.contains('\x07'), "{text:?}");
        assert!(text.contains("]0;pwn"));
        assert!(
            text.chars().count() < MAX_MESSAGE_CHARS + 50,
            "{}",
            text.len()
        );
    }
}
