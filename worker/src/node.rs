//! The render node's logic on plain types: what a coordinator may ask of a worker (handshake,
//! blobs, scenes, units, counters) and the state it takes (the blob and scene caches, the render
//! threads, the counters in `metrics.rs`). The gRPC layer only carries requests in and errors
//! out.

use std::sync::Arc;
use std::time::Instant;

use prost::Message;
use tokio::sync::watch;
use yat_proto::convert::{unit_from_wire, WireError};
use yat_proto::hash::{is_sha256_hex, sha256_hex};
use yat_proto::{pb, DEFAULT_MAX_MESSAGE_BYTES, PROTOCOL_VERSION};
use yat_tracer::budget::BuildBudget;
use yat_tracer::render::RenderSettings;

use crate::blobs::BlobStore;
use crate::config::WorkerConfig;
use crate::error::{NodeError, ServeError};
use crate::loaded_scene::LoadedScene;
use crate::metrics::{Metrics, NodeGauges};
use crate::pool::{RenderPool, UnitCounts};
use crate::scenes::SceneCache;
use crate::upload::{BlobUpload, UploadBudget};

/// Scenes a worker keeps built at once.
const SCENE_CACHE_CAPACITY: usize = 4;

/// What the worker tells coordinators about itself.
pub struct Capabilities {
    pub threads: u32,
    pub max_message_bytes: u64,
    pub max_blob_bytes: u64,
    pub features: Vec<String>,
}

pub struct Node {
    capabilities: Capabilities,
    blobs: Arc<BlobStore>,
    scenes: SceneCache<LoadedScene>,
    pool: RenderPool,
    /// What a scene may cost to parse and build.
    build_budget: BuildBudget,
    uploads: UploadBudget,
    /// Set once at the shutdown signal: new work is refused, queued units handed back.
    draining: watch::Sender<bool>,
    metrics: Arc<Metrics>,
    started: Instant,
}

impl Node {
    pub fn new(config: &WorkerConfig) -> Result<Self, ServeError> {
        let threads = config.threads.max(1);
        let blobs = BlobStore::new(
            config.memory_cache_bytes,
            config.cache_dir.as_deref(),
            config.cache_dir_bytes,
        )
        .map_err(|e| match &config.cache_dir {
            Some(dir) => ServeError::CacheFolder(dir.clone(), e),
            None => ServeError::Cache(e),
        })?;
        let mut features = Vec::new();
        if config.cache_dir.is_some() {
            features.push("disk-cache".to_string());
        }
        if config.tls.is_some() {
            features.push("tls".to_string());
        }
        let draining = watch::Sender::new(false);
        let pool = RenderPool::new(
            threads,
            config.max_queued_units,
            draining.subscribe(),
            config.throttle,
        )?;
        Ok(Self {
            capabilities: Capabilities {
                threads: threads as u32,
                max_message_bytes: DEFAULT_MAX_MESSAGE_BYTES as u64,
                // A blob is held whole while it arrives, so it must fit the uploads' budget.
                max_blob_bytes: config.max_blob_bytes.min(config.upload_budget_bytes),
                features,
            },
            blobs: Arc::new(blobs),
            scenes: SceneCache::new(SCENE_CACHE_CAPACITY),
            pool,
            build_budget: config.build_budget,
            uploads: UploadBudget::new(config.upload_budget_bytes),
            draining,
            metrics: Arc::default(),
            started: Instant::now(),
        })
    }

    pub fn capabilities(&self) -> &Capabilities {
        &self.capabilities
    }

    /// The worker's counters, which the connections and the gRPC layer count into too.
    pub fn metrics(&self) -> &Arc<Metrics> {
        &self.metrics
    }

    /// The Prometheus text of the counters and the node's state now.
    pub fn exposition(&self) -> String {
        let units = self.pool.counts();
        let cache = self.blobs.held_bytes();
        self.metrics.render(&NodeGauges {
            threads: self.capabilities.threads,
            busy_threads: units.rendering,
            queued_units: units.waiting,
            memory_cache_bytes: cache.memory,
            disk_cache_bytes: cache.disk,
            blobs_cached: self.blobs.len() as u64,
            scenes_cached: self.scenes.len() as u64,
            upload_bytes_held: self.uploads.held(),
            draining: *self.draining.borrow(),
            uptime: self.started.elapsed(),
        })
    }

    /// Stops taking work: new blobs, scenes and units are refused from now on and units waiting
    /// for a render thread are handed back. Says how many units were rendering and waiting.
    pub fn begin_drain(&self) -> UnitCounts {
        let counts = self.pool.counts();
        self.draining.send_replace(true);
        counts
    }

    /// Resolves once no unit is rendering.
    pub async fn idle(&self) {
        self.pool.idle().await;
    }

    fn refuse_if_draining(&self, what: impl FnOnce() -> String) -> Result<(), NodeError> {
        if *self.draining.borrow() {
            return Err(NodeError::Draining(what()));
        }
        Ok(())
    }

    /// The worker's version and capabilities, for a client of the same protocol version.
    pub fn handshake(
        &self,
        request: &pb::HandshakeRequest,
    ) -> Result<pb::HandshakeReply, NodeError> {
        if request.protocol_version != PROTOCOL_VERSION {
            return Err(NodeError::ProtocolVersion {
                client: request.client.clone(),
                version: request.protocol_version,
            });
        }
        tracing::info!("handshake from {}", request.client);
        let caps = &self.capabilities;
        Ok(pb::HandshakeReply {
            protocol_version: PROTOCOL_VERSION,
            threads: caps.threads,
            hostname: gethostname::gethostname().to_string_lossy().into_owned(),
            max_message_bytes: caps.max_message_bytes,
            max_blob_bytes: caps.max_blob_bytes,
            features: caps.features.clone(),
            software: format!("yat {}", env!("CARGO_PKG_VERSION")),
            renderer_build: yat_tracer::RENDERER_BUILD.into(),
        })
    }

    /// The requested blobs this worker does not hold, in request order.
    pub fn missing_blobs(&self, request: pb::HasBlobsRequest) -> pb::HasBlobsReply {
        let asked = request.sha256.len() as u64;
        let missing: Vec<String> = request
            .sha256
            .into_iter()
            .filter(|h| !self.blobs.contains(h))
            .collect();
        let missed = missing.len() as u64;
        self.metrics.blobs_asked(asked - missed, missed);
        pb::HasBlobsReply { missing }
    }

    /// Starts receiving a blob, named and sized by its first chunk.
    pub fn begin_blob(&self, hash: String, size: u64) -> Result<BlobUpload, NodeError> {
        self.refuse_if_draining(|| format!("blob {hash}"))?;
        BlobUpload::begin(
            hash,
            size,
            self.capabilities.max_blob_bytes,
            self.uploads.clone(),
        )
    }

    /// Stores a blob received whole and verified.
    pub async fn store_blob(&self, upload: BlobUpload) -> Result<pb::PutBlobReply, NodeError> {
        let (hash, data) = upload.finish()?;
        let stored_bytes = data.len() as u64;
        let blobs = self.blobs.clone();
        tokio::task::spawn_blocking(move || blobs.insert(&hash, data.into()))
            .await
            .map_err(NodeError::BlobTask)??;
        self.metrics.blob_stored(stored_bytes);
        Ok(pb::PutBlobReply { stored_bytes })
    }

    /// Builds the scene the request names, unless it is built already.
    pub async fn load_scene(
        &self,
        request: pb::LoadSceneRequest,
    ) -> Result<pb::LoadSceneReply, NodeError> {
        self.refuse_if_draining(|| "scene load".to_string())?;
        // Protobuf encoding of the same message is the same bytes: the id names the files'
        // contents, their paths and the settings, identically on every worker.
        let scene_id = sha256_hex(&request.encode_to_vec());
        let main = request.main.ok_or(WireError::Missing("main file"))?;
        let settings = request.settings.ok_or(WireError::Missing("settings"))?;
        let settings = RenderSettings::try_from(&settings)?;
        for file in std::iter::once(&main).chain(&request.assets) {
            if !is_sha256_hex(&file.sha256) {
                return Err(NodeError::MalformedHash {
                    path: file.path.clone(),
                    sha256: file.sha256.clone(),
                });
            }
        }
        let started = Instant::now();
        let assets = request.assets;
        let blobs = self.blobs.clone();
        let build =
            || LoadedScene::build_blocking(blobs, main, assets, settings, self.build_budget);
        let (loaded, built) = self.scenes.get_or_build(&scene_id, build).await?;
        self.metrics.scene_loaded(built);
        Ok(pb::LoadSceneReply {
            scene_id,
            triangle_count: loaded.triangle_count,
            build_seconds: if built {
                started.elapsed().as_secs_f64()
            } else {
                0.0
            },
            warnings: loaded.warnings.clone(),
        })
    }

    /// Renders one unit of a loaded scene.
    pub async fn render_unit(
        &self,
        request: pb::RenderUnitRequest,
    ) -> Result<pb::RenderUnitReply, NodeError> {
        self.refuse_if_draining(|| {
            let index = request.unit.as_ref().map_or(0, |u| u.index);
            format!("unit {index}")
        })?;
        let loaded = self
            .scenes
            .get(&request.scene_id)
            .ok_or(NodeError::SceneNotLoaded(request.scene_id))?;
        let unit = request.unit.as_ref().ok_or(WireError::Missing("unit"))?;
        let unit = unit_from_wire(unit, &loaded.settings)?;
        let rendered = self.pool.render(loaded, unit).await?;
        let sent = rendered.pixels.len() + rendered.layers.len() + rendered.splats.len();
        self.metrics
            .unit_rendered(rendered.stats.samples, sent as u64, rendered.elapsed);
        Ok(pb::RenderUnitReply {
            index: unit.index,
            pixels: rendered.pixels,
            stats: Some(rendered.stats.into()),
            render_seconds: rendered.elapsed.as_secs_f64(),
            light_splats: rendered.splats,
            layers: rendered.layers,
        })
    }

    /// The worker's counters since it started.
    pub fn stats(&self) -> pb::StatsReply {
        let c = self.metrics.stats_counters();
        pb::StatsReply {
            units_done: c.units,
            samples_done: c.samples,
            blob_bytes_received: c.upload_bytes,
            result_bytes_sent: c.result_bytes,
            blobs_cached: self.blobs.len() as u64,
            scenes_cached: self.scenes.len() as u64,
            units_in_flight: {
                let units = self.pool.counts();
                units.rendering + units.waiting
            },
            uptime_seconds: self.started.elapsed().as_secs_f64(),
        }
    }
}
