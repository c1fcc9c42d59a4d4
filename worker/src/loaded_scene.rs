//! A scene built from the blobs a coordinator sent, ready for units.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use yat_proto::pb;
use yat_tracer::assets::MemorySource;
use yat_tracer::budget::{BuildBudget, BuildGuard};
use yat_tracer::parse::parse_scene_guarded;
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

/// Sets the build's cancel flag when dropped: a LoadScene call whose caller went away drops
/// its future, and the build on the blocking thread stops at its next check.
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

impl LoadedScene {
    /// [`LoadedScene::build`] on a blocking thread, abandoned (at the build's next check) if
    /// this future is dropped before it finishes.
    pub async fn build_blocking(
        blobs: Arc<BlobStore>,
        main: pb::SceneFile,
        assets: Vec<pb::SceneFile>,
        settings: RenderSettings,
        budget: BuildBudget,
    ) -> Result<Self, NodeError> {
        let cancel = Arc::new(AtomicBool::new(false));
        let _cancel_on_drop = CancelOnDrop(cancel.clone());
        tokio::task::spawn_blocking(move || {
            let guard = BuildGuard {
                budget: &budget,
                cancel: &cancel,
            };
            Self::build(&blobs, &main, &assets, settings, guard)
        })
        .await
        .map_err(NodeError::BuildTask)?
    }

    /// Parses and builds the scene whose files `blobs` holds, under `guard`'s budget. It can
    /// take long (a big mesh's BVH): call it off the async runtime.
    pub fn build(
        blobs: &BlobStore,
        main: &pb::SceneFile,
        assets: &[pb::SceneFile],
        settings: RenderSettings,
        guard: BuildGuard,
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
        let desc = parse_scene_guarded(&main.path, &source, guard).map_err(|source| {
            NodeError::SceneParse {
                path: main.path.clone(),
                source: Box::new(source),
            }
        })?;
        let scene =
            RenderScene::build_guarded(&desc, &source, &settings, guard).map_err(|source| {
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
