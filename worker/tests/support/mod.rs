//! What the worker's integration tests share: a worker served in-process on a loopback port,
//! clients with or without the token, and a small scene uploaded and loaded.

#![allow(dead_code)] // Each test binary uses its own part of these helpers.

use std::net::SocketAddr;
use std::time::Duration;

use tokio::net::TcpListener;
use tokio::sync::oneshot;
use tokio::task::JoinHandle;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::Channel;
use yat_proto::auth::AttachToken;
use yat_proto::hash::sha256_hex;
use yat_proto::{pb, RenderNodeClient};
use yat_worker::{serve, ServeError, WorkerConfig};

pub type Client = RenderNodeClient<InterceptedService<Channel, AttachToken>>;

/// A worker serving on a loopback port until `stop` is sent (or the test's runtime ends).
pub struct Served {
    pub address: SocketAddr,
    pub stop: Option<oneshot::Sender<()>>,
    pub server: JoinHandle<Result<(), ServeError>>,
}

impl Served {
    pub async fn start(config: WorkerConfig) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
        let address = listener.local_addr().unwrap();
        let (stop, stopped) = oneshot::channel::<()>();
        let server = tokio::spawn(serve(listener, config, async {
            let _ = stopped.await;
        }));
        Self {
            address,
            stop: Some(stop),
            server,
        }
    }

    pub fn channel(&self) -> Channel {
        tonic::transport::Endpoint::from_shared(format!("http://{}", self.address))
            .unwrap()
            .connect_lazy()
    }

    /// A client sending `token`.
    pub fn client(&self, token: Option<&str>) -> Client {
        RenderNodeClient::with_interceptor(self.channel(), AttachToken::new(token).unwrap())
    }

    /// The shutdown signal.
    pub fn signal(&mut self) {
        self.stop.take().expect("signalled once").send(()).unwrap();
    }
}

#[path = "../../../tests/fixtures/lit_sphere.rs"]
mod lit_sphere;
pub use lit_sphere::LIT_SPHERE as SCENE;

/// Chunks of one blob: the first names it.
pub fn chunks(hash: &str, size: u64, parts: &[&'static [u8]]) -> Vec<pb::BlobChunk> {
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

/// A stranger's host on loopback: connections from 127.0.0.2, so the worker's allowance of
/// unauthenticated connections per address does not count them against the tests' own clients
/// on 127.0.0.1.
pub async fn connect_from_elsewhere(address: SocketAddr) -> std::io::Result<tokio::net::TcpStream> {
    let socket = tokio::net::TcpSocket::new_v4()?;
    socket.bind("127.0.0.2:0".parse().unwrap())?;
    socket.connect(address).await
}

/// Uploads [`SCENE`] and loads it as a 16x16 image of `spp` samples per pixel; the scene id.
pub async fn load_scene(client: &mut Client, spp: u32) -> String {
    let hash = sha256_hex(SCENE);
    let upload = chunks(&hash, SCENE.len() as u64, &[SCENE]);
    client.put_blob(tokio_stream::iter(upload)).await.unwrap();
    let request = pb::LoadSceneRequest {
        main: Some(pb::SceneFile {
            path: "sphere.lxs".into(),
            sha256: hash,
        }),
        assets: vec![],
        settings: Some(pb::RenderSettings {
            width: 16,
            height: 16,
            spp,
            max_depth: 4,
            ..Default::default()
        }),
    };
    client
        .load_scene(request)
        .await
        .unwrap()
        .into_inner()
        .scene_id
}

/// Unit `index`: the whole 16x16 image, samples `samples`.
pub fn unit(scene_id: &str, index: u32, samples: std::ops::Range<u32>) -> pb::RenderUnitRequest {
    pb::RenderUnitRequest {
        scene_id: scene_id.to_string(),
        unit: Some(pb::WorkUnit {
            index,
            x0: 0,
            y0: 0,
            x1: 16,
            y1: 16,
            sample_start: samples.start,
            sample_end: samples.end,
            block_mask: None,
        }),
    }
}

/// Polls `probe` every 10 ms until it holds; panics after `limit`. Returns the time it took.
pub async fn wait_until(limit: Duration, mut probe: impl AsyncFnMut() -> bool) -> Duration {
    let started = tokio::time::Instant::now();
    while !probe().await {
        assert!(started.elapsed() < limit, "not within {limit:?}");
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    started.elapsed()
}

/// The worker's units in flight, over Stats.
pub async fn units_in_flight(client: &mut Client) -> u64 {
    let stats = client.stats(pb::StatsRequest {}).await.unwrap();
    stats.into_inner().units_in_flight
}
