//! The `RenderNode` gRPC service: requests in to the node, [`NodeError`]s out as the status
//! codes `render.proto` documents (each counted on its way out, `metrics.rs`). No logic lives
//! here.

use std::sync::Arc;
use std::time::Duration;

use tonic::{Request, Response, Status, Streaming};
use yat_proto::drain::draining_status;
use yat_proto::pb;

use crate::error::NodeError;
use crate::node::Node;

/// The service as served.
pub type RenderService = yat_proto::RenderNodeServer<GrpcNode>;

pub struct GrpcNode {
    node: Arc<Node>,
    /// How long a PutBlob stream may go without a chunk.
    blob_idle: Duration,
}

impl GrpcNode {
    pub fn new(node: Arc<Node>, blob_idle: Duration) -> Self {
        Self { node, blob_idle }
    }
}

impl GrpcNode {
    /// The status of `error`, counted.
    fn refuse(&self, error: NodeError) -> Status {
        self.node.metrics().failed(&error);
        error.into()
    }

    /// The reply, or the status of the error, counted.
    fn answer<T>(&self, result: Result<T, NodeError>) -> Result<Response<T>, Status> {
        result.map(Response::new).map_err(|e| self.refuse(e))
    }

    /// The next chunk of blob `hash`, failing the upload when none comes in time.
    async fn next_chunk(
        &self,
        chunks: &mut Streaming<pb::BlobChunk>,
        hash: &str,
    ) -> Result<Option<pb::BlobChunk>, Status> {
        match tokio::time::timeout(self.blob_idle, chunks.message()).await {
            Ok(chunk) => chunk,
            Err(_) => Err(self.refuse(NodeError::BlobStalled {
                hash: hash.to_string(),
                seconds: self.blob_idle.as_secs(),
            })),
        }
    }
}

impl From<NodeError> for Status {
    fn from(error: NodeError) -> Self {
        use NodeError::*;
        let code = match &error {
            Draining(what) => return draining_status(what),
            ProtocolVersion { .. } | BlobMissing { .. } => tonic::Code::FailedPrecondition,
            Wire(_)
            | MalformedHash { .. }
            | EmptyBlobStream
            | UnnamedBlob
            | BlobTooLong { .. }
            | BlobTooShort { .. }
            | BlobHashMismatch { .. }
            | SceneParse { .. }
            | SceneBuild { .. } => tonic::Code::InvalidArgument,
            BlobTooLarge { .. } | UploadBudget { .. } | CacheFull { .. } | QueueFull { .. } => {
                tonic::Code::ResourceExhausted
            }
            BlobStalled { .. } => tonic::Code::DeadlineExceeded,
            UnitCancelled(_) => tonic::Code::Cancelled,
            SceneNotLoaded(_) => tonic::Code::NotFound,
            BlobCache(_) | UnitPanicked(_) | RenderThreadVanished | BlobTask(_) | BuildTask(_) => {
                tonic::Code::Internal
            }
        };
        Status::new(code, error.to_string())
    }
}

#[tonic::async_trait]
impl pb::render_node_server::RenderNode for GrpcNode {
    async fn handshake(
        &self,
        request: Request<pb::HandshakeRequest>,
    ) -> Result<Response<pb::HandshakeReply>, Status> {
        self.answer(self.node.handshake(request.get_ref()))
    }

    async fn has_blobs(
        &self,
        request: Request<pb::HasBlobsRequest>,
    ) -> Result<Response<pb::HasBlobsReply>, Status> {
        Ok(Response::new(self.node.missing_blobs(request.into_inner())))
    }

    async fn put_blob(
        &self,
        request: Request<Streaming<pb::BlobChunk>>,
    ) -> Result<Response<pb::PutBlobReply>, Status> {
        let mut chunks = request.into_inner();
        let first = self
            .next_chunk(&mut chunks, "(unnamed)")
            .await?
            .ok_or_else(|| self.refuse(NodeError::EmptyBlobStream))?;
        let mut upload = self
            .node
            .begin_blob(first.sha256, first.size)
            .map_err(|e| self.refuse(e))?;
        upload.push(&first.data).map_err(|e| self.refuse(e))?;
        while let Some(chunk) = self.next_chunk(&mut chunks, upload.hash()).await? {
            upload.push(&chunk.data).map_err(|e| self.refuse(e))?;
        }
        self.answer(self.node.store_blob(upload).await)
    }

    async fn load_scene(
        &self,
        request: Request<pb::LoadSceneRequest>,
    ) -> Result<Response<pb::LoadSceneReply>, Status> {
        self.answer(self.node.load_scene(request.into_inner()).await)
    }

    async fn render_unit(
        &self,
        request: Request<pb::RenderUnitRequest>,
    ) -> Result<Response<pb::RenderUnitReply>, Status> {
        self.answer(self.node.render_unit(request.into_inner()).await)
    }

    async fn stats(
        &self,
        _request: Request<pb::StatsRequest>,
    ) -> Result<Response<pb::StatsReply>, Status> {
        Ok(Response::new(self.node.stats()))
    }
}
