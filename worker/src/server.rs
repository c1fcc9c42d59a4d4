//! Serving the node over gRPC on a listener the caller bound, until the caller's shutdown
//! future resolves: the token check, TLS, message limits and keepalives around the service.

use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use tokio::net::TcpListener;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::server::TcpIncoming;
use tonic::transport::{Identity, Server, ServerTlsConfig};
use yat_proto::auth::RequireToken;
use yat_proto::{RenderNodeServer, DEFAULT_MAX_MESSAGE_BYTES};

use crate::config::WorkerConfig;
use crate::error::ServeError;
use crate::grpc::GrpcNode;
use crate::node::Node;

/// A worker ready to serve: its caches opened and its render threads started.
pub struct Worker {
    node: Arc<Node>,
    token: Option<String>,
    tls: Option<Identity>,
}

impl Worker {
    pub fn new(config: WorkerConfig) -> Result<Self, ServeError> {
        Ok(Self {
            node: Arc::new(Node::new(&config)?),
            token: config.token,
            tls: config.tls,
        })
    }

    /// Serves coordinators on `listener` until `shutdown` resolves, then finishes the requests
    /// under way and returns.
    pub async fn serve(
        self,
        listener: TcpListener,
        shutdown: impl Future<Output = ()>,
    ) -> Result<(), ServeError> {
        tracing::info!(
            "{} thread(s){}{}",
            self.node.capabilities().threads,
            if self.tls.is_some() { ", TLS" } else { "" },
            if self.token.is_some() {
                ", token required"
            } else {
                ""
            }
        );
        let service = RenderNodeServer::new(GrpcNode::new(self.node))
            .max_decoding_message_size(DEFAULT_MAX_MESSAGE_BYTES)
            .max_encoding_message_size(DEFAULT_MAX_MESSAGE_BYTES);
        let service = InterceptedService::new(service, RequireToken::new(self.token.as_deref()));
        let mut server = Server::builder()
            .http2_keepalive_interval(Some(Duration::from_secs(10)))
            .http2_keepalive_timeout(Some(Duration::from_secs(20)));
        if let Some(identity) = self.tls {
            server = server
                .tls_config(ServerTlsConfig::new().identity(identity))
                .map_err(ServeError::Tls)?;
        }
        let incoming = TcpIncoming::from(listener).with_nodelay(Some(true));
        server
            .add_service(service)
            .serve_with_incoming_shutdown(incoming, shutdown)
            .await
            .map_err(ServeError::Server)
    }
}

/// Serves a worker started with `config` on `listener` until `shutdown` resolves.
pub async fn serve(
    listener: TcpListener,
    config: WorkerConfig,
    shutdown: impl Future<Output = ()>,
) -> Result<(), ServeError> {
    Worker::new(config)?.serve(listener, shutdown).await
}
