//! Serving the node over gRPC on a listener the caller bound, until the caller's shutdown
//! future resolves and the node has drained: the token check, TLS, the health service, message
//! and connection limits and keepalives around the service.
//!
//! The health service (`grpc.health.v1`, for `""` and `yat.render.v1.RenderNode`) is outside
//! the token check: orchestrators' probes cannot send metadata, and it reveals nothing but
//! SERVING or NOT_SERVING (`availability.rs`).
//!
//! With a metrics listener (`yat worker --metrics-addr`), the worker's Prometheus text is
//! served beside it (`metrics_server.rs`) until the gRPC server has drained and stopped.

use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use tokio::net::TcpListener;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::{Certificate, Identity, Server, ServerTlsConfig};
use yat_proto::auth::RequireToken;
use yat_proto::{RenderNodeServer, DEFAULT_MAX_MESSAGE_BYTES};

use crate::admission::{Admission, AdmissionLimits};
use crate::availability::Availability;
use crate::config::{defaults, NetworkLimits, WorkerConfig};
use crate::connection::{self, Acceptor, Authenticate, ConnectionTimeouts};
use crate::descriptors::{ConnectionCap, DESCRIPTOR_HEADROOM};
use crate::error::ServeError;
use crate::grpc::GrpcNode;
use crate::metrics_server;
use crate::node::Node;

/// HTTP/2 pings to every peer, so a live peer's connection is never idle and a dead one is
/// found: this often, or three times per connection idle limit if that is shorter.
const KEEPALIVE_INTERVAL: Duration = Duration::from_secs(10);
const KEEPALIVE_TIMEOUT: Duration = Duration::from_secs(20);

/// After the drain, how long the last replies get to leave before the server stops regardless
/// of connections still open.
const REPLY_GRACE: Duration = Duration::from_secs(2);

/// A worker ready to serve: its caches opened and its render threads started.
pub struct Worker {
    node: Arc<Node>,
    network: NetworkLimits,
    drain: Duration,
    token: Option<String>,
    tls: Option<Identity>,
    tls_client_ca: Option<Certificate>,
    insecure: bool,
    /// Where to serve `/metrics`, if anywhere.
    metrics_listener: Option<TcpListener>,
}

impl Worker {
    pub fn new(config: WorkerConfig) -> Result<Self, ServeError> {
        Ok(Self {
            node: Arc::new(Node::new(&config)?),
            network: config.network,
            drain: config.drain,
            token: config.token,
            tls: config.tls,
            tls_client_ca: config.tls_client_ca,
            insecure: config.insecure,
            metrics_listener: None,
        })
    }

    /// Also serves the worker's metrics on `listener` (`GET /metrics`), for as long as the
    /// worker serves.
    pub fn with_metrics(mut self, listener: TcpListener) -> Self {
        self.metrics_listener = Some(listener);
        self
    }

    /// Refuses to serve beyond loopback when anyone reaching the port could use the worker: no
    /// token, no TLS client certificates, and no `--insecure`.
    pub fn check_exposure(&self, address: SocketAddr) -> Result<(), ServeError> {
        let open = self.token.is_none() && self.tls_client_ca.is_none();
        if open && !address.ip().is_loopback() && !self.insecure {
            return Err(ServeError::Exposed { address });
        }
        Ok(())
    }

    /// Refuses to serve metrics beyond loopback when anyone reaching that port could read
    /// them: no token (client certificates do not cover the plain-HTTP metrics port), and no
    /// `--insecure`.
    pub fn check_metrics_exposure(&self, address: SocketAddr) -> Result<(), ServeError> {
        if self.token.is_none() && !address.ip().is_loopback() && !self.insecure {
            return Err(ServeError::MetricsExposed { address });
        }
        Ok(())
    }

    /// Serves coordinators on `listener` until `shutdown` resolves, then drains: reports
    /// NOT_SERVING, refuses new work, hands queued units back, lets units already rendering
    /// finish for up to the drain period, and returns.
    pub async fn serve(
        self,
        listener: TcpListener,
        shutdown: impl Future<Output = ()>,
    ) -> Result<(), ServeError> {
        let address = listener.local_addr().map_err(ServeError::Listener)?;
        self.check_exposure(address)?;
        if let Some(metrics) = &self.metrics_listener {
            self.check_metrics_exposure(metrics.local_addr().map_err(ServeError::Listener)?)?;
        }
        let network = &self.network;
        let cap = ConnectionCap::of_this_process(network.max_connections)
            .map_err(ServeError::DescriptorLimit)?
            .ok_or(ServeError::NoRoomForConnections)?;
        let admission_limits = AdmissionLimits {
            total: network
                .max_unauthenticated
                .unwrap_or_else(|| defaults::max_unauthenticated(cap.connections)),
            per_peer: network.max_unauthenticated_per_address,
        };
        if cap.connections < network.max_connections {
            tracing::warn!(
                "serving {} connections at most, not {}: the descriptor limit is {} with {} \
                 open and {DESCRIPTOR_HEADROOM} kept for files (raise it with ulimit -n)",
                cap.connections,
                network.max_connections,
                cap.descriptor_limit,
                cap.in_use
            );
        }
        tracing::info!(
            "{} thread(s){}{}{}; at most {} connections, {} of them unauthenticated ({} per \
             address, {} s to authenticate)",
            self.node.capabilities().threads,
            if self.tls.is_some() { ", TLS" } else { "" },
            if self.tls_client_ca.is_some() {
                ", client certificates required"
            } else {
                ""
            },
            if self.token.is_some() {
                ", token required"
            } else {
                ""
            },
            cap.connections,
            admission_limits.total,
            admission_limits.per_peer,
            network.handshake_timeout.as_secs_f64(),
        );
        let (health, health_service) = tonic_health::server::health_reporter();
        let availability = Arc::new(Availability::new(health).await);
        let service =
            RenderNodeServer::new(GrpcNode::new(self.node.clone(), self.network.blob_idle))
                .max_decoding_message_size(DEFAULT_MAX_MESSAGE_BYTES)
                .max_encoding_message_size(DEFAULT_MAX_MESSAGE_BYTES);
        let service = InterceptedService::new(
            service,
            Authenticate {
                token: RequireToken::new(self.token.as_deref()),
                metrics: self.node.metrics().clone(),
            },
        );
        let mut server = Server::builder()
            .http2_keepalive_interval(Some(KEEPALIVE_INTERVAL.min(network.connection_idle / 3)))
            .http2_keepalive_timeout(Some(KEEPALIVE_TIMEOUT))
            .max_concurrent_streams(network.max_streams_per_connection)
            .concurrency_limit_per_connection(network.max_streams_per_connection as usize)
            .timeout(network.request_timeout);
        if let Some(identity) = self.tls {
            let mut tls = ServerTlsConfig::new().identity(identity);
            if let Some(ca) = self.tls_client_ca {
                tls = tls.client_ca_root(ca);
            }
            server = server.tls_config(tls).map_err(ServeError::Tls)?;
        }
        let incoming = connection::accept(Acceptor {
            listener,
            max_connections: cap.connections,
            admission: Admission::new(admission_limits),
            timeouts: ConnectionTimeouts {
                idle: network.connection_idle,
                handshake: network.handshake_timeout,
            },
            availability: availability.clone(),
            metrics: self.node.metrics().clone(),
        });
        // Stops when this function returns, whichever way: the sender drops.
        let (metrics_running, metrics_stop) = tokio::sync::oneshot::channel::<()>();
        let metrics = self.metrics_listener.map(|listener| {
            let node = self.node.clone();
            let token = self.token.clone();
            tokio::spawn(async move {
                let stop = async {
                    let _ = metrics_stop.await;
                };
                metrics_server::serve(listener, token.as_deref(), move || node.exposition(), stop)
                    .await;
            })
        });
        let (drained, drained_rx) = tokio::sync::oneshot::channel();
        let node = self.node.clone();
        let drain_period = self.drain;
        let stop = async move {
            shutdown.await;
            drain(&node, &availability, drain_period).await;
            let _ = drained.send(());
        };
        let serving = server
            .add_service(health_service)
            .add_service(service)
            .serve_with_incoming_shutdown(incoming, stop);
        let deadline = async {
            if drained_rx.await.is_err() {
                return std::future::pending().await;
            }
            tokio::time::sleep(REPLY_GRACE).await;
        };
        let served = tokio::select! {
            served = serving => served.map_err(ServeError::Server),
            () = deadline => {
                tracing::warn!("connections still open {REPLY_GRACE:?} after the drain; stopping");
                Ok(())
            }
        };
        drop(metrics_running);
        if let Some(metrics) = metrics {
            let _ = metrics.await;
        }
        served
    }
}

/// The steps of a drain, logged.
async fn drain(node: &Node, availability: &Availability, period: Duration) {
    availability.drain().await;
    let units = node.begin_drain();
    tracing::info!(
        "draining: {} units finishing, {} handed back",
        units.rendering,
        units.waiting
    );
    match tokio::time::timeout(period, node.idle()).await {
        Ok(()) => tracing::info!("drained"),
        Err(_) => tracing::warn!(
            "drain: units still rendering after {} s; stopping anyway",
            period.as_secs_f64()
        ),
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
