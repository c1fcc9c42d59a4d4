//! A scene built from the blobs a coordinator sent, ready for units.

use std::time::Instant;

use yat_proto::pb;
use yat_tracer::assets::MemorySource;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{RenderScene, RenderSettings};

use crate::blobs::BlobStore;
use crate::error::NodeError;

/// A scene ready for units, with what its loading reported.
pub struct LoadedScene {
    pub scene: RenderScene,
    pub settings: RenderSettings,
    pub warnings: Vec<String>,
    pub triangle_count: u64,
}

impl LoadedScene {
    /// Parses and builds the scene whose files `blobs` holds. It can take long (a big mesh's
    /// BVH): call it off the async runtime.
    pub fn build(
        blobs: &BlobStore,
        main: &pb::SceneFile,
        assets: &[pb::SceneFile],
        settings: RenderSettings,
    ) -> Result<Self, NodeError> {
        let mut source = MemorySource::new();
        for file in std::iter::once(main).chain(assets) {
            let bytes = blobs
                .get(&file.sha256)
                .map_err(NodeError::BlobCache)?
                .ok_or_else(|| NodeError::BlobMissing {
                    sha256: file.sha256.clone(),
                    path: file.path.clone(),
                })?;
            source.insert(file.path.clone(), bytes);
        }
        let started = Instant::now();
        let desc = parse_scene(&main.path, &source).map_err(|source| NodeError::SceneParse {
            path: main.path.clone(),
            source: Box::new(source),
        })?;
        let scene = RenderScene::build(&desc, &source, &settings).map_err(|source| {
            NodeError::SceneBuild {
                path: main.path.clone(),
                source,
            }
        })?;
        tracing::info!(
            "built {} ({} triangles) in {:.2} s",
            main.path,
            scene.triangle_count(),
            started.elapsed().as_secs_f64()
        );
        Ok(Self {
            triangle_count: scene.triangle_count() as u64,
            scene,
            settings,
            warnings: desc.warnings.iter().map(ToString::to_string).collect(),
        })
    }
}
