//! The worker over gRPC, started in-process with `serve` on a loopback port: what it refuses,
//! with which status codes (the contract `render.proto` documents).

use std::time::Duration;

use tokio::net::TcpListener;
use tonic::Code;
use yat_proto::drain::is_draining;
use yat_proto::hash::sha256_hex;
use yat_proto::{pb, RenderNodeClient, PROTOCOL_VERSION};
use yat_worker::{serve, ServeError, WorkerConfig};

mod support;
use support::*;

/// One render thread, no token, no TLS, and a 1000-byte blob limit.
fn config() -> WorkerConfig {
    WorkerConfig {
        memory_cache_bytes: 1 << 20,
        max_blob_bytes: 1000,
        ..WorkerConfig::default()
    }
}

/// A worker on a loopback port and a client to it; the worker serves until the test's runtime
/// ends.
async fn worker() -> RenderNodeClient<tonic::transport::Channel> {
    let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let address = listener.local_addr().unwrap();
    tokio::spawn(serve(listener, config(), std::future::pending()));
    RenderNodeClient::connect(format!("http://{address}"))
        .await
        .unwrap()
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

#[tokio::test]
async fn scene_loads_fail_with_the_documented_codes() {
    let mut client = worker().await;
    let settings = pb::RenderSettings {
        width: 8,
        height: 8,
        spp: 1,
        max_depth: 1,
        ..Default::default()
    };
    let load = |path: &str, text: &[u8]| pb::LoadSceneRequest {
        main: Some(pb::SceneFile {
            path: path.into(),
            sha256: sha256_hex(text),
        }),
        assets: vec![],
        settings: Some(settings),
    };
    let without_main = pb::LoadSceneRequest {
        main: None,
        ..load("a.lxs", b"")
    };
    let status = client.load_scene(without_main).await.unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
    assert_eq!(status.message(), "the request lacks its main file");

    let broken: &'static [u8] = b"Film \"fleximage\" \"integer xresolution\" [64\nWorldBegin\n";
    let status = client
        .load_scene(load("bad.lxs", broken))
        .await
        .unwrap_err();
    assert_eq!(status.code(), Code::FailedPrecondition, "not uploaded yet");
    assert!(status.message().contains("upload it first"), "{status:?}");

    let hash = sha256_hex(broken);
    client
        .put_blob(tokio_stream::iter(chunks(
            &hash,
            broken.len() as u64,
            &[broken],
        )))
        .await
        .unwrap();
    let status = client
        .load_scene(load("bad.lxs", broken))
        .await
        .unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
    assert!(status.message().starts_with("bad.lxs: "), "{status:?}");
}

#[tokio::test]
async fn serve_returns_once_its_shutdown_resolves() {
    let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let server = tokio::spawn(serve(listener, config(), async {
        let _ = stopped.await;
    }));
    stop.send(()).unwrap();
    let served = tokio::time::timeout(Duration::from_secs(10), server)
        .await
        .expect("serve returned")
        .unwrap();
    assert!(served.is_ok(), "{served:?}");
}

#[tokio::test]
async fn health_needs_no_token_and_a_drain_finishes_rendering_units_and_hands_back_the_rest() {
    use tonic_health::pb::health_check_response::ServingStatus;
    use tonic_health::pb::{health_client::HealthClient, HealthCheckRequest};
    let mut worker = Served::start(WorkerConfig {
        token: Some("t".into()),
        throttle: Duration::from_millis(1500),
        ..WorkerConfig::default()
    })
    .await;
    let health = HealthClient::new(worker.channel());
    let status = |service: &str| {
        let mut health = health.clone();
        let request = HealthCheckRequest {
            service: service.to_string(),
        };
        async move { health.check(request).await.unwrap().into_inner().status() }
    };
    for service in ["", "yat.render.v1.RenderNode"] {
        assert_eq!(status(service).await, ServingStatus::Serving, "{service:?}");
    }
    let unknown = HealthCheckRequest {
        service: "other".into(),
    };
    let unknown = health.clone().check(unknown).await.unwrap_err();
    assert_eq!(unknown.code(), Code::NotFound);
    let denied = worker.client(None).stats(pb::StatsRequest {}).await;
    assert_eq!(denied.unwrap_err().code(), Code::Unauthenticated);

    let mut client = worker.client(Some("t"));
    let scene = load_scene(&mut client, 4).await;
    // One thread: unit 0 renders (its throttle pause counts), unit 1 waits for the thread.
    let rendering = tokio::spawn({
        let mut c = client.clone();
        let request = unit(&scene, 0, 0..4);
        async move { c.render_unit(request).await }
    });
    wait_until(Duration::from_secs(5), async || {
        units_in_flight(&mut client).await == 1
    })
    .await;
    let waiting = tokio::spawn({
        let mut c = client.clone();
        let request = unit(&scene, 1, 0..4);
        async move { c.render_unit(request).await }
    });
    wait_until(Duration::from_secs(5), async || {
        units_in_flight(&mut client).await == 2
    })
    .await;

    let signalled = tokio::time::Instant::now();
    worker.signal();
    let handed_back = waiting.await.unwrap().unwrap_err();
    assert!(is_draining(&handed_back), "{handed_back:?}");
    assert!(
        signalled.elapsed() < Duration::from_millis(1000),
        "handed back at once"
    );
    for service in ["", "yat.render.v1.RenderNode"] {
        assert_eq!(status(service).await, ServingStatus::NotServing);
    }
    let refused = client.render_unit(unit(&scene, 2, 0..4)).await.unwrap_err();
    assert!(is_draining(&refused), "{refused:?}");
    let upload = chunks(&"a".repeat(64), 1, &[b"x"]);
    let refused = client
        .put_blob(tokio_stream::iter(upload))
        .await
        .unwrap_err();
    assert!(is_draining(&refused), "{refused:?}");

    let finished = rendering.await.unwrap().unwrap().into_inner();
    assert_eq!((finished.index, finished.pixels.len()), (0, 16 * 16 * 16));
    let served = tokio::time::timeout(Duration::from_secs(10), worker.server)
        .await
        .expect("serve returned after the drain")
        .unwrap();
    assert!(served.is_ok(), "{served:?}");
}

#[tokio::test]
async fn an_open_port_needs_a_token_or_client_certificates_or_insecure() {
    let listener = TcpListener::bind("0.0.0.0:0").await.unwrap();
    let refused = serve(listener, config(), std::future::ready(())).await;
    let error = refused.unwrap_err();
    assert!(matches!(error, ServeError::Exposed { .. }), "{error}");
    for flag in ["--token-file", "--tls-client-ca", "--insecure"] {
        assert!(error.to_string().contains(flag), "{error}");
    }
    for config in [
        WorkerConfig {
            insecure: true,
            ..config()
        },
        WorkerConfig {
            token: Some("t".into()),
            ..config()
        },
    ] {
        let listener = TcpListener::bind("0.0.0.0:0").await.unwrap();
        let served = serve(listener, config, std::future::ready(())).await;
        assert!(served.is_ok(), "{served:?}");
    }
}

#[tokio::test]
async fn units_beyond_the_queue_are_refused() {
    let worker = Served::start(WorkerConfig {
        max_queued_units: 1,
        throttle: Duration::from_secs(2),
        ..WorkerConfig::default()
    })
    .await;
    let mut client = worker.client(None);
    let scene = load_scene(&mut client, 1).await;
    let mut calls = Vec::new();
    for index in 0..2 {
        let mut c = client.clone();
        let request = unit(&scene, index, 0..1);
        calls.push(tokio::spawn(async move { c.render_unit(request).await }));
        wait_until(Duration::from_secs(5), async || {
            units_in_flight(&mut client).await == u64::from(index) + 1
        })
        .await;
    }
    let refused = client.render_unit(unit(&scene, 2, 0..1)).await.unwrap_err();
    assert_eq!(refused.code(), Code::ResourceExhausted, "{refused:?}");
    for call in calls {
        assert_eq!(call.await.unwrap().unwrap().into_inner().pixels.len(), 4096);
    }
}

#[tokio::test]
async fn with_a_client_ca_only_clients_with_its_certificates_are_served() {
    use rcgen::{BasicConstraints, CertificateParams, CertifiedIssuer, IsCa, KeyPair};
    use tonic::transport::{Certificate, ClientTlsConfig, Endpoint, Identity};
    let mut ca_params = CertificateParams::new(Vec::new()).unwrap();
    ca_params.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
    let ca = CertifiedIssuer::self_signed(ca_params, KeyPair::generate().unwrap()).unwrap();
    let issue = |name: &str| {
        let key = KeyPair::generate().unwrap();
        let cert = CertificateParams::new(vec![name.to_string()])
            .unwrap()
            .signed_by(&key, &ca)
            .unwrap();
        Identity::from_pem(cert.pem(), key.serialize_pem())
    };
    // No token, on every address: client certificates satisfy the secure-by-default rule.
    let listener = TcpListener::bind("0.0.0.0:0").await.unwrap();
    let port = listener.local_addr().unwrap().port();
    let config = WorkerConfig {
        tls: Some(issue("localhost")),
        tls_client_ca: Some(Certificate::from_pem(ca.pem())),
        ..config()
    };
    tokio::spawn(serve(listener, config, std::future::pending()));
    let handshake = |identity: Option<Identity>| {
        let mut tls = ClientTlsConfig::new()
            .ca_certificate(Certificate::from_pem(ca.pem()))
            .domain_name("localhost");
        if let Some(identity) = identity {
            tls = tls.identity(identity);
        }
        async move {
            let channel = Endpoint::from_shared(format!("https://127.0.0.1:{port}"))
                .unwrap()
                .tls_config(tls)
                .unwrap()
                .connect()
                .await;
            let hello = pb::HandshakeRequest {
                protocol_version: PROTOCOL_VERSION,
                client: "test".into(),
            };
            match channel {
                Ok(channel) => RenderNodeClient::new(channel)
                    .handshake(hello)
                    .await
                    .map(drop),
                Err(error) => Err(tonic::Status::unavailable(error.to_string())),
            }
        }
    };
    assert!(handshake(Some(issue("coordinator"))).await.is_ok());
    assert!(
        handshake(None).await.is_err(),
        "a client without a certificate"
    );
}
