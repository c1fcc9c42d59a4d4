//! The `RenderNode` service: handshake, blob upload, scene loading and unit rendering.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use prost::Message;
use tonic::{Request, Response, Status, Streaming};
use yat_proto::convert::{encode_pixels, unit_from_wire};
use yat_proto::hash::{is_sha256_hex, sha256_hex, Sha256Stream};
use yat_proto::{pb, PROTOCOL_VERSION};
use yat_tracer::assets::MemorySource;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{RenderScene, RenderSettings};

use crate::blobs::BlobStore;
use crate::scenes::SceneCache;

/// Scenes a worker keeps built at once.
const SCENE_CACHE_CAPACITY: usize = 4;

/// A scene ready for units, with what its loading reported.
pub struct LoadedScene {
    scene: RenderScene,
    settings: RenderSettings,
    warnings: Vec<String>,
    triangle_count: u64,
}

/// What the worker tells coordinators about itself.
pub struct Capabilities {
    pub threads: u32,
    pub max_message_bytes: u64,
    pub max_blob_bytes: u64,
    pub features: Vec<String>,
}

#[derive(Default)]
struct Counters {
    units_done: AtomicU64,
    samples_done: AtomicU64,
    blob_bytes_received: AtomicU64,
    result_bytes_sent: AtomicU64,
    units_in_flight: AtomicU64,
}

pub struct RenderNodeService {
    capabilities: Capabilities,
    blobs: Arc<BlobStore>,
    scenes: SceneCache<LoadedScene>,
    pool: rayon::ThreadPool,
    /// Test hook: a pause before each unit, to make a worker slow on purpose.
    throttle: Duration,
    counters: Counters,
    started: Instant,
}

impl RenderNodeService {
    pub fn new(
        capabilities: Capabilities,
        blobs: BlobStore,
        throttle: Duration,
    ) -> anyhow::Result<Self> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(capabilities.threads as usize)
            .thread_name(|i| format!("yat-render-{i}"))
            .build()?;
        Ok(Self {
            capabilities,
            blobs: Arc::new(blobs),
            scenes: SceneCache::new(SCENE_CACHE_CAPACITY),
            pool,
            throttle,
            counters: Counters::default(),
            started: Instant::now(),
        })
    }

    async fn build_scene(
        &self,
        main: pb::SceneFile,
        assets: Vec<pb::SceneFile>,
        settings: RenderSettings,
    ) -> Result<LoadedScene, Status> {
        let blobs = self.blobs.clone();
        let build = move || {
            let mut source = MemorySource::new();
            for file in std::iter::once(&main).chain(&assets) {
                let bytes = blobs
                    .get(&file.sha256)
                    .map_err(|e| Status::internal(format!("blob cache: {e}")))?
                    .ok_or_else(|| {
                        Status::failed_precondition(format!(
                            "blob {} (\"{}\") is missing: upload it first",
                            file.sha256, file.path
                        ))
                    })?;
                source.insert(file.path.clone(), bytes);
            }
            let started = Instant::now();
            let desc = parse_scene(&main.path, &source)
                .map_err(|e| Status::invalid_argument(format!("{}: {e}", main.path)))?;
            let scene = RenderScene::build(&desc, &source, &settings)
                .map_err(|e| Status::invalid_argument(format!("{}: {e}", main.path)))?;
            tracing::info!(
                "built {} ({} triangles) in {:.2} s",
                main.path,
                scene.triangle_count(),
                started.elapsed().as_secs_f64()
            );
            Ok(LoadedScene {
                triangle_count: scene.triangle_count() as u64,
                scene,
                settings,
                warnings: desc.warnings.iter().map(ToString::to_string).collect(),
            })
        };
        tokio::task::spawn_blocking(build)
            .await
            .map_err(|e| Status::internal(format!("scene build failed: {e}")))?
    }
}

fn missing(what: &str) -> Status {
    Status::invalid_argument(format!("the request lacks its {what}"))
}

/// Counts a unit as in flight until dropped, even when the coordinator gives up on it.
struct InFlight<'a>(&'a AtomicU64);

impl<'a> InFlight<'a> {
    fn enter(counter: &'a AtomicU64) -> Self {
        counter.fetch_add(1, Ordering::Relaxed);
        Self(counter)
    }
}

impl Drop for InFlight<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

#[tonic::async_trait]
impl pb::render_node_server::RenderNode for RenderNodeService {
    async fn handshake(
        &self,
        request: Request<pb::HandshakeRequest>,
    ) -> Result<Response<pb::HandshakeReply>, Status> {
        let request = request.into_inner();
        if request.protocol_version != PROTOCOL_VERSION {
            return Err(Status::failed_precondition(format!(
                "protocol version mismatch: this worker speaks version {PROTOCOL_VERSION}, \
                 the client ({}) version {}",
                request.client, request.protocol_version
            )));
        }
        tracing::info!("handshake from {}", request.client);
        let caps = &self.capabilities;
        Ok(Response::new(pb::HandshakeReply {
            protocol_version: PROTOCOL_VERSION,
            threads: caps.threads,
            hostname: gethostname::gethostname().to_string_lossy().into_owned(),
            max_message_bytes: caps.max_message_bytes,
            max_blob_bytes: caps.max_blob_bytes,
            features: caps.features.clone(),
            software: format!("yat {}", env!("CARGO_PKG_VERSION")),
        }))
    }

    async fn has_blobs(
        &self,
        request: Request<pb::HasBlobsRequest>,
    ) -> Result<Response<pb::HasBlobsReply>, Status> {
        let missing = request
            .into_inner()
            .sha256
            .into_iter()
            .filter(|h| !self.blobs.contains(h))
            .collect();
        Ok(Response::new(pb::HasBlobsReply { missing }))
    }

    async fn put_blob(
        &self,
        request: Request<Streaming<pb::BlobChunk>>,
    ) -> Result<Response<pb::PutBlobReply>, Status> {
        let mut chunks = request.into_inner();
        let first = chunks
            .message()
            .await?
            .ok_or_else(|| Status::invalid_argument("empty blob stream"))?;
        let (hash, size) = (first.sha256, first.size);
        if !is_sha256_hex(&hash) {
            return Err(Status::invalid_argument(
                "a blob's first chunk must name its sha256 (64 lowercase hex digits)",
            ));
        }
        if size > self.capabilities.max_blob_bytes {
            return Err(Status::resource_exhausted(format!(
                "blob {hash} has {size} bytes; this worker accepts at most {}",
                self.capabilities.max_blob_bytes
            )));
        }
        // The declared size bounds the allocation; the stream may not exceed it.
        let mut data = Vec::with_capacity(size as usize);
        let mut hasher = Sha256Stream::default();
        let mut chunk_data = first.data;
        loop {
            if (data.len() + chunk_data.len()) as u64 > size {
                return Err(Status::invalid_argument(format!(
                    "blob {hash}: more bytes than the declared {size}"
                )));
            }
            hasher.update(&chunk_data);
            data.extend_from_slice(&chunk_data);
            match chunks.message().await? {
                Some(chunk) => chunk_data = chunk.data,
                None => break,
            }
        }
        if data.len() as u64 != size {
            return Err(Status::invalid_argument(format!(
                "blob {hash}: received {} bytes of the declared {size}",
                data.len()
            )));
        }
        let actual = hasher.finish_hex();
        if actual != hash {
            return Err(Status::invalid_argument(format!(
                "blob hash mismatch: declared {hash}, content hashes to {actual}"
            )));
        }
        let blobs = self.blobs.clone();
        let stored_bytes = size;
        tokio::task::spawn_blocking(move || blobs.insert(&hash, data.into()))
            .await
            .map_err(|e| Status::internal(e.to_string()))?
            .map_err(|e| Status::internal(format!("blob cache: {e}")))?;
        self.counters
            .blob_bytes_received
            .fetch_add(stored_bytes, Ordering::Relaxed);
        Ok(Response::new(pb::PutBlobReply { stored_bytes }))
    }

    async fn load_scene(
        &self,
        request: Request<pb::LoadSceneRequest>,
    ) -> Result<Response<pb::LoadSceneReply>, Status> {
        let request = request.into_inner();
        // Protobuf encoding of the same message is the same bytes: the id names the files'
        // contents, their paths and the settings, identically on every worker.
        let scene_id = sha256_hex(&request.encode_to_vec());
        let main = request.main.ok_or_else(|| missing("main file"))?;
        let settings = request.settings.ok_or_else(|| missing("settings"))?;
        let settings = RenderSettings::try_from(&settings)
            .map_err(|e| Status::invalid_argument(e.to_string()))?;
        for file in std::iter::once(&main).chain(&request.assets) {
            if !is_sha256_hex(&file.sha256) {
                return Err(Status::invalid_argument(format!(
                    "\"{}\": malformed sha256 \"{}\"",
                    file.path, file.sha256
                )));
            }
        }
        let started = Instant::now();
        let (loaded, built) = self
            .scenes
            .get_or_build(&scene_id, || {
                self.build_scene(main, request.assets, settings)
            })
            .await?;
        Ok(Response::new(pb::LoadSceneReply {
            scene_id,
            triangle_count: loaded.triangle_count,
            build_seconds: if built {
                started.elapsed().as_secs_f64()
            } else {
                0.0
            },
            warnings: loaded.warnings.clone(),
        }))
    }

    async fn render_unit(
        &self,
        request: Request<pb::RenderUnitRequest>,
    ) -> Result<Response<pb::RenderUnitReply>, Status> {
        let request = request.into_inner();
        let loaded = self.scenes.get(&request.scene_id).ok_or_else(|| {
            Status::not_found(format!(
                "scene {} is not loaded here: load it again",
                request.scene_id
            ))
        })?;
        let unit = request.unit.as_ref().ok_or_else(|| missing("unit"))?;
        let unit = unit_from_wire(unit, &loaded.settings)
            .map_err(|e| Status::invalid_argument(e.to_string()))?;
        let _in_flight = InFlight::enter(&self.counters.units_in_flight);
        if !self.throttle.is_zero() {
            tokio::time::sleep(self.throttle).await;
        }
        let (done, result) = tokio::sync::oneshot::channel();
        self.pool.spawn(move || {
            let started = Instant::now();
            // A renderer bug fails this unit, not the whole worker.
            let rendered = std::panic::catch_unwind(AssertUnwindSafe(|| {
                let (buffer, stats) = loaded.scene.render_unit(&unit);
                (encode_pixels(&buffer), stats)
            }));
            let _ = done.send(rendered.map(|r| (r, started.elapsed())));
        });
        let ((pixels, stats), elapsed) = result
            .await
            .map_err(|_| Status::internal("render thread vanished"))?
            .map_err(|_| Status::internal(format!("unit {} panicked", unit.index)))?;
        let c = &self.counters;
        c.units_done.fetch_add(1, Ordering::Relaxed);
        c.samples_done.fetch_add(stats.samples, Ordering::Relaxed);
        c.result_bytes_sent
            .fetch_add(pixels.len() as u64, Ordering::Relaxed);
        Ok(Response::new(pb::RenderUnitReply {
            index: unit.index,
            pixels,
            stats: Some(stats.into()),
            render_seconds: elapsed.as_secs_f64(),
        }))
    }

    async fn stats(
        &self,
        _request: Request<pb::StatsRequest>,
    ) -> Result<Response<pb::StatsReply>, Status> {
        let c = &self.counters;
        Ok(Response::new(pb::StatsReply {
            units_done: c.units_done.load(Ordering::Relaxed),
            samples_done: c.samples_done.load(Ordering::Relaxed),
            blob_bytes_received: c.blob_bytes_received.load(Ordering::Relaxed),
            result_bytes_sent: c.result_bytes_sent.load(Ordering::Relaxed),
            blobs_cached: self.blobs.len() as u64,
            scenes_cached: self.scenes.len() as u64,
            units_in_flight: c.units_in_flight.load(Ordering::Relaxed),
            uptime_seconds: self.started.elapsed().as_secs_f64(),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tonic::transport::server::TcpIncoming;
    use tonic::Code;
    use yat_proto::{RenderNodeClient, RenderNodeServer};

    /// A worker on a loopback port, with a 1000-byte blob limit, and a client to it.
    async fn worker() -> RenderNodeClient<tonic::transport::Channel> {
        let capabilities = Capabilities {
            threads: 1,
            max_message_bytes: 1 << 20,
            max_blob_bytes: 1000,
            features: Vec::new(),
        };
        let blobs = BlobStore::new(1 << 20, None).unwrap();
        let service = RenderNodeService::new(capabilities, blobs, Duration::ZERO).unwrap();
        let incoming = TcpIncoming::bind("127.0.0.1:0".parse().unwrap()).unwrap();
        let address = incoming.local_addr().unwrap();
        tokio::spawn(
            tonic::transport::Server::builder()
                .add_service(RenderNodeServer::new(service))
                .serve_with_incoming(incoming),
        );
        RenderNodeClient::connect(format!("http://{address}"))
            .await
            .unwrap()
    }

    fn chunks(hash: &str, size: u64, parts: &[&'static [u8]]) -> Vec<pb::BlobChunk> {
        parts
            .iter()
            .enumerate()
            .map(|(i, data)| pb::BlobChunk {
                sha256: if i == 0 {
                    hash.to_string()
                } else {
                    String::new()
                },
                size: if i == 0 { size } else { 0 },
                data: prost::bytes::Bytes::from_static(data),
            })
            .collect()
    }

    #[tokio::test]
    async fn blobs_are_verified_before_they_are_stored() {
        let mut client = worker().await;
        let good = sha256_hex(b"hello world");
        let uploader = client.clone();
        let put = |c: Vec<pb::BlobChunk>| {
            let mut client = uploader.clone();
            async move { client.put_blob(tokio_stream::iter(c)).await }
        };
        let wrong_hash = sha256_hex(b"something else");
        let refused = [
            (
                chunks(&wrong_hash, 11, &[b"hello ", b"world"]),
                Code::InvalidArgument,
            ),
            (
                chunks(&good, 5, &[b"hello ", b"world"]),
                Code::InvalidArgument,
            ),
            (
                chunks(&good, 12, &[b"hello ", b"world"]),
                Code::InvalidArgument,
            ),
            (
                chunks("../etc/passwd", 11, &[b"hello world"]),
                Code::InvalidArgument,
            ),
            (
                chunks(&good, 5000, &[b"hello world"]),
                Code::ResourceExhausted,
            ),
        ];
        for (stream, code) in refused {
            assert_eq!(put(stream).await.unwrap_err().code(), code);
        }
        let query = pb::HasBlobsRequest {
            sha256: vec![good.clone(), wrong_hash.clone()],
        };
        let missing = client.has_blobs(query.clone()).await.unwrap().into_inner();
        assert_eq!(missing.missing, vec![good.clone(), wrong_hash.clone()]);

        let stored = put(chunks(&good, 11, &[b"hello ", b"world"]))
            .await
            .unwrap();
        assert_eq!(stored.into_inner().stored_bytes, 11);
        let missing = client.has_blobs(query).await.unwrap().into_inner();
        assert_eq!(missing.missing, vec![wrong_hash]);
        let stats = client
            .stats(pb::StatsRequest {})
            .await
            .unwrap()
            .into_inner();
        assert_eq!((stats.blob_bytes_received, stats.blobs_cached), (11, 1));
    }

    #[tokio::test]
    async fn other_protocol_versions_and_unknown_scenes_are_refused() {
        let mut client = worker().await;
        let hello = |protocol_version| pb::HandshakeRequest {
            protocol_version,
            client: "test".into(),
        };
        let reply = client.handshake(hello(PROTOCOL_VERSION)).await.unwrap();
        assert_eq!(reply.into_inner().threads, 1);
        let refused = client
            .handshake(hello(PROTOCOL_VERSION + 1))
            .await
            .unwrap_err();
        assert_eq!(refused.code(), Code::FailedPrecondition);
        assert!(refused.message().contains(&format!(
            "version {PROTOCOL_VERSION}, the client (test) version {}",
            PROTOCOL_VERSION + 1
        )));
        let unit = pb::RenderUnitRequest {
            scene_id: "nothing".into(),
            unit: None,
        };
        let status = client.render_unit(unit).await.unwrap_err();
        assert_eq!(status.code(), Code::NotFound);
    }
}
