//! The `RenderNode` gRPC service: requests in to the node, [`NodeError`]s out as the status
//! codes `render.proto` documents. No logic lives here.

use std::sync::Arc;

use tonic::{Request, Response, Status, Streaming};
use yat_proto::pb;

use crate::error::NodeError;
use crate::node::Node;

pub struct GrpcNode {
    node: Arc<Node>,
}

impl GrpcNode {
    pub fn new(node: Arc<Node>) -> Self {
        Self { node }
    }
}

impl From<NodeError> for Status {
    fn from(error: NodeError) -> Self {
        use NodeError::*;
        let code = match &error {
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
            BlobTooLarge { .. } => tonic::Code::ResourceExhausted,
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
        Ok(Response::new(self.node.handshake(request.get_ref())?))
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
        let first = chunks.message().await?.ok_or(NodeError::EmptyBlobStream)?;
        let mut upload = self.node.begin_blob(first.sha256, first.size)?;
        upload.push(&first.data)?;
        while let Some(chunk) = chunks.message().await? {
            upload.push(&chunk.data)?;
        }
        Ok(Response::new(self.node.store_blob(upload).await?))
    }

    async fn load_scene(
        &self,
        request: Request<pb::LoadSceneRequest>,
    ) -> Result<Response<pb::LoadSceneReply>, Status> {
        Ok(Response::new(
            self.node.load_scene(request.into_inner()).await?,
        ))
    }

    async fn render_unit(
        &self,
        request: Request<pb::RenderUnitRequest>,
    ) -> Result<Response<pb::RenderUnitReply>, Status> {
        Ok(Response::new(
            self.node.render_unit(request.into_inner()).await?,
        ))
    }

    async fn stats(
        &self,
        _request: Request<pb::StatsRequest>,
    ) -> Result<Response<pb::StatsReply>, Status> {
        Ok(Response::new(self.node.stats()))
    }
}
