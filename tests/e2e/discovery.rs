//! DNS discovery end to end: a real DNS server in this process (hickory's in-memory authority
//! for `yat.test.` on UDP and TCP loopback), real `yat worker` processes on 127.0.0.2-4 (one
//! port, several loopback addresses, as a headless Service's pods share one), and the
//! coordinator (the library's render in this process) following the name while its answer
//! changes mid-render.

use std::collections::BTreeMap;
use std::net::{Ipv4Addr, SocketAddr, TcpListener};
use std::str::FromStr;
use std::sync::Arc;
use std::time::{Duration, Instant};

use hickory_server::authority::{AuthorityObject, Catalog, ZoneType};
use hickory_server::proto::rr::rdata::{A, SOA};
use hickory_server::proto::rr::{LowerName, Name, RData, Record, RecordSet, RecordType, RrKey};
use hickory_server::store::in_memory::InMemoryAuthority;
use hickory_server::ServerFuture;
use yat::exec::distributed::config::DistributedConfig;
use yat::render::{Executor, Observers};
use yat::shutdown::Interrupt;

use crate::util::*;

const ZONE: &str = "yat.test.";
const WORKERS_NAME: &str = "workers.yat.test.";

/// An authoritative DNS server for `yat.test.` whose A records for `workers.yat.test.` the test
/// sets; served by its own runtime until dropped.
struct DnsServer {
    address: SocketAddr,
    authority: Arc<InMemoryAuthority>,
    runtime: tokio::runtime::Runtime,
}

impl DnsServer {
    fn start() -> Self {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .unwrap();
        let origin = Name::from_str(ZONE).unwrap();
        let soa = SOA::new(
            Name::from_str("ns.yat.test.").unwrap(),
            Name::from_str("admin.yat.test.").unwrap(),
            1,
            60,
            60,
            60,
            0,
        );
        let mut soa_set = RecordSet::new(origin.clone(), RecordType::SOA, 1);
        soa_set.insert(Record::from_rdata(origin.clone(), 0, RData::SOA(soa)), 1);
        let records = BTreeMap::from([(
            RrKey::new(LowerName::new(&origin), RecordType::SOA),
            soa_set,
        )]);
        let authority = Arc::new(
            InMemoryAuthority::new(origin.clone(), records, ZoneType::Primary, false).unwrap(),
        );
        let mut catalog = Catalog::new();
        catalog.upsert(
            LowerName::new(&origin),
            vec![authority.clone() as Arc<dyn AuthorityObject>],
        );
        // UDP and TCP on one port, as a resolver expects: retry while TCP finds it taken.
        let address = runtime.block_on(async move {
            let mut server = ServerFuture::new(catalog);
            let (udp, tcp) = loop {
                let udp = tokio::net::UdpSocket::bind("127.0.0.1:0").await.unwrap();
                if let Ok(tcp) = tokio::net::TcpListener::bind(udp.local_addr().unwrap()).await {
                    break (udp, tcp);
                }
            };
            let address = udp.local_addr().unwrap();
            server.register_socket(udp);
            server.register_listener(tcp, Duration::from_secs(5));
            tokio::spawn(async move { server.block_until_done().await });
            address
        });
        Self {
            address,
            authority,
            runtime,
        }
    }

    /// Makes `workers.yat.test.` resolve to exactly `ips` (TTL 0: nobody caches it).
    fn set_workers(&self, ips: &[Ipv4Addr]) {
        let name = Name::from_str(WORKERS_NAME).unwrap();
        let key = RrKey::new(LowerName::new(&name), RecordType::A);
        let mut set = RecordSet::with_ttl(name, RecordType::A, 0);
        for &ip in ips {
            set.add_rdata(RData::A(A(ip)));
        }
        self.runtime.block_on(async {
            let mut records = self.authority.records_mut().await;
            records.insert(key, Arc::new(set));
        });
    }
}

/// One port free on every address of `ips` at once (bound together, then released).
fn port_free_on(ips: &[Ipv4Addr]) -> u16 {
    loop {
        let first = TcpListener::bind((ips[0], 0)).unwrap();
        let port = first.local_addr().unwrap().port();
        let others: Result<Vec<_>, _> = ips[1..]
            .iter()
            .map(|&ip| TcpListener::bind((ip, port)))
            .collect();
        if others.is_ok() {
            return port;
        }
    }
}

/// Throttled single-thread workers listening on `ips`, all on one port (another is tried if
/// one of them finds its port taken meanwhile).
fn workers_on(ips: &[Ipv4Addr]) -> (u16, Vec<Worker>) {
    for _ in 0..10 {
        let port = port_free_on(ips);
        let started: Result<Vec<Worker>, _> = ips
            .iter()
            .map(|ip| {
                let listen = format!("{ip}:{port}");
                std::panic::catch_unwind(|| Worker::start_on(&listen, &["--throttle-ms", "150"]))
            })
            .collect();
        if let Ok(workers) = started {
            return (port, workers);
        }
    }
    panic!("no port free on every one of {ips:?}");
}

/// Waits until `worker` has rendered `units` units.
fn wait_for(worker: &Worker, units: u64) {
    let started = Instant::now();
    while worker.stats(None).units_done < units {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "{} stalled",
            worker.address
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn workers_join_and_leave_as_the_name_resolves() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference_image(dir.path(), &scene);
    let ips = [
        Ipv4Addr::new(127, 0, 0, 2),
        Ipv4Addr::new(127, 0, 0, 3),
        Ipv4Addr::new(127, 0, 0, 4),
    ];
    let (port, workers) = workers_on(&ips);
    let [a, b, c] = &workers[..] else {
        unreachable!()
    };
    let dns = DnsServer::start();
    dns.set_workers(&ips[..1]);

    let out = dir.path().join("dns.png");
    let json = dir.path().join("dns.json");
    let by_name = DistributedConfig {
        resolve_every: Duration::from_millis(500),
        dns_server: Some(dns.address),
        workers_json: Some(json.clone()),
        ..workers_at(&[&format!("workers.yat.test:{port}")])
    };
    let coordinator = spawn_render(
        request(&scene, &out),
        Executor::from(by_name),
        Observers::none(),
        Interrupt::default(),
    );

    wait_for(a, 3);
    dns.set_workers(&ips[..2]);
    wait_for(b, 2);
    // A leaves the answer while it holds units; C joins.
    dns.set_workers(&ips[1..]);
    let removed = Instant::now();
    coordinator.join().unwrap().unwrap();
    // A unit presumed lost waits 30 s (the deadline floor): A finished what it held at once.
    assert!(
        removed.elapsed() < Duration::from_secs(25),
        "the render waited {:.1} s after A left",
        removed.elapsed().as_secs_f64()
    );

    let (png, exr) = image_bytes(&out);
    assert!(exr == expected.1, "EXR differs from in-process");
    assert!(png == expected.0, "PNG differs from in-process");
    let report = workers_report(&json);
    let entry = |worker: &Worker| worker_entry(&report, &worker.address).clone();
    let (a, b, c) = (entry(a), entry(b), entry(c));
    for w in [&a, &b, &c] {
        assert_eq!(w["dns_name"], "workers.yat.test", "{report:#}");
    }
    assert_eq!(a["gone"], "removed from DNS", "{report:#}");
    // A was still up (as a draining pod is): it finished the units it held instead of
    // throwing them back.
    assert_eq!(a["units_requeued"], 0, "{report:#}");
    assert!(a["units"].as_u64().unwrap() >= 3, "{report:#}");
    assert!(
        b["units"].as_u64().unwrap() >= 1,
        "B merged units: {report:#}"
    );
    assert!(b["gone"].is_null() && c["gone"].is_null(), "{report:#}");
    let merged: u64 = [&a, &b, &c]
        .iter()
        .map(|w| w["units"].as_u64().unwrap())
        .sum();
    assert_eq!(merged, 32, "each unit merged once: {report:#}");
}
