//! The scene as workers receive it: the main file and every file it references, read once on
//! the coordinator and named by content hash.

use std::collections::HashMap;

use anyhow::Context;
use prost::bytes::Bytes;
use yat_proto::hash::sha256_hex;
use yat_proto::pb;
use yat_tracer::assets::{AssetError, AssetSource};
use yat_tracer::render::RenderSettings;

use crate::scene::ParsedScene;

pub struct SceneManifest {
    pub main: pb::SceneFile,
    pub assets: Vec<pb::SceneFile>,
    /// File contents by hash (files with the same content are sent once).
    pub blobs: HashMap<String, Bytes>,
}

impl SceneManifest {
    /// Reads the main file and the assets the parse listed, as the in-process render would. A
    /// referenced file that does not exist is left out: the worker then misses it exactly as an
    /// in-process render does.
    pub fn read(scene: &ParsedScene) -> anyhow::Result<Self> {
        let source = &scene.source;
        let mut blobs = HashMap::new();
        let mut add = |written: &str| -> anyhow::Result<Option<pb::SceneFile>> {
            let bytes = match source.read(written) {
                Ok(bytes) => bytes,
                Err(AssetError::NotFound { .. }) => return Ok(None),
                Err(e) => return Err(e.into()),
            };
            let sha256 = sha256_hex(&bytes);
            blobs
                .entry(sha256.clone())
                .or_insert_with(|| Bytes::from_owner(bytes));
            Ok(Some(pb::SceneFile {
                path: written.to_string(),
                sha256,
            }))
        };
        let main = add(&scene.main_name)?
            .with_context(|| format!("{} has vanished", scene.path.display()))?;
        let mut assets = Vec::with_capacity(scene.desc.assets.len());
        for asset in &scene.desc.assets {
            match add(&asset.path)? {
                Some(file) => assets.push(file),
                None => tracing::warn!("{}: not found, not sent to workers", asset.path),
            }
        }
        Ok(Self {
            main,
            assets,
            blobs,
        })
    }

    pub fn load_request(&self, settings: &RenderSettings) -> pb::LoadSceneRequest {
        pb::LoadSceneRequest {
            main: Some(self.main.clone()),
            assets: self.assets.clone(),
            settings: Some(settings.into()),
        }
    }
}
