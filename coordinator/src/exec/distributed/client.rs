//! The client of one worker: the connection (address, TLS, token), every call with its deadline,
//! and what a call's failure means for the session ([`SessionError`]).

use std::time::Duration;

use prost::bytes::Bytes;
use prost::Message;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::{Channel, ClientTlsConfig, Endpoint};
use tonic::{Code, Request, Status};
use yat_proto::auth::AttachToken;
use yat_proto::{pb, RenderNodeClient, BLOB_CHUNK_BYTES, DEFAULT_MAX_MESSAGE_BYTES};

use super::session_error::SessionError;

const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);
/// Deadline of the small calls (handshake, blob queries, stats).
const CALL_TIMEOUT: Duration = Duration::from_secs(10);
/// Deadline of a scene load: parsing and building a big mesh's BVH takes a while.
const LOAD_TIMEOUT: Duration = Duration::from_secs(600);
/// Upload deadline: a base plus this much time per MiB (a slow 1 MiB/s link still makes it).
const UPLOAD_TIMEOUT_BASE: Duration = Duration::from_secs(30);
const UPLOAD_TIMEOUT_PER_MIB: Duration = Duration::from_secs(1);

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
    address: String,
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
        Ok(Self {
            inner,
            address: config.address.clone(),
        })
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
            Code::FailedPrecondition => SessionError::Permanent(status.message().to_string()),
            _ => transient("handshake", status),
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
        .map_err(|s| transient("blob query", s))?;
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
        let chunk_bytes = BLOB_CHUNK_BYTES.min(max_message_bytes as usize / 2).max(1);
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
            Code::ResourceExhausted => SessionError::Permanent(status.message().to_string()),
            _ => transient("upload", status),
        })?;
        Ok(sent)
    }

    /// A scene the worker cannot parse or build fails the whole render: no worker can.
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
            Code::InvalidArgument => SessionError::Fatal(anyhow::anyhow!(
                "worker {} cannot load the scene: {}",
                self.address,
                status.message()
            )),
            _ => transient("scene load", status),
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
            .map_err(|status| transient(&format!("unit {index}"), status))
    }
}

/// A failed call: worth another session later, unless the worker refused our token.
fn transient(what: &str, status: Status) -> SessionError {
    match status.code() {
        Code::Unauthenticated => SessionError::Permanent(format!(
            "authentication failed (unauthenticated): {}",
            status.message()
        )),
        _ => SessionError::Transient(format!("{what}: {}", describe_status(&status))),
    }
}

fn describe_status(status: &Status) -> String {
    let text = format!("{:?}: {}", status.code(), status.message());
    match std::error::Error::source(status) {
        Some(cause) => format!("{text}: {}", error_chain(cause)),
        None => text,
    }
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
/// their sources).
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
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_authentication_failure_is_permanent_and_says_so() {
        let refused = transient("handshake", Status::unauthenticated("wrong token"));
        assert!(matches!(refused, SessionError::Permanent(m) if m.contains("authentication")));
        let lost = transient("unit 3", Status::unavailable("connection reset"));
        assert!(matches!(lost, SessionError::Transient(m) if m.contains("unit 3")));
    }
}
