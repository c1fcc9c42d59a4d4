//! Which workers a render uses, and how that set follows the cluster. A `--workers` entry is an
//! IP literal with a port (one worker) or a DNS name with a port (every address the name
//! resolves to is a worker: a Kubernetes headless Service, a round-robin record). Names are
//! resolved again every `--resolve-every` seconds: an address new in the answer joins the
//! running render as a node with its own session loop, an address no longer in the answer
//! leaves it and is reported as removed from DNS, and an address that comes back is a worker
//! again. A leaving worker takes no more units but may finish the ones it holds, for up to the
//! unit deadline: a Kubernetes pod leaves its Service's answer the moment it is deleted, while
//! its drain is still finishing those units; after the deadline its session is aborted and what
//! it still holds goes back to the queue. A name that
//! fails to resolve keeps its last good answer. Which worker renders which unit never changes
//! the image, so none of this touches the bit-identical promise.

use std::collections::{BTreeSet, HashSet};
use std::net::{IpAddr, SocketAddr};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use hickory_resolver::config::{NameServerConfigGroup, ResolverConfig, ResolverOpts};
use hickory_resolver::name_server::TokioConnectionProvider;
use hickory_resolver::{Name, ResolveError, TokioResolver};
use tokio::sync::watch;
use tokio::task::JoinHandle;
use tonic::transport::ClientTlsConfig;

use super::client::ClientConfig;
use super::node::Node;
use super::session::run_node;
use super::session_context::SessionContext;

/// A name's resolution (every attempt and name server included) is abandoned after this long.
const RESOLVE_DEADLINE: Duration = Duration::from_secs(5);
/// Addresses taken from one answer; more are ignored (and said so), so a hostile or broken
/// name server cannot make the coordinator open unbounded connections.
pub const MAX_ADDRESSES_PER_NAME: usize = 1024;
/// Why a worker that left the answer of its name is no longer used.
pub const REMOVED_FROM_DNS: &str = "removed from DNS";

/// One `--workers` entry.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WorkerTarget {
    /// An IP literal and a port: one worker, never resolved.
    Address(SocketAddr),
    /// A DNS name and a port: a worker at every address the name resolves to.
    Name { host: String, port: u16 },
}

#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    #[error("bad worker address {0:?}: expected HOST:PORT")]
    NoPort(String),
    #[error("bad worker address {0:?}: the port must be a number from 1 to 65535")]
    BadPort(String),
    #[error("bad worker address {entry:?}: {host:?} is not a host name ({why})")]
    BadName {
        entry: String,
        host: String,
        why: String,
    },
}

impl WorkerTarget {
    pub fn parse(entry: &str) -> Result<Self, TargetError> {
        let entry = entry.trim();
        if let Ok(address) = entry.parse::<SocketAddr>() {
            return Ok(Self::Address(address));
        }
        let (host, port) = entry
            .rsplit_once(':')
            .ok_or_else(|| TargetError::NoPort(entry.to_string()))?;
        let port = port
            .parse::<u16>()
            .ok()
            .filter(|&p| p != 0)
            .ok_or_else(|| TargetError::BadPort(entry.to_string()))?;
        let bad_name = |why: String| TargetError::BadName {
            entry: entry.to_string(),
            host: host.to_string(),
            why,
        };
        // An IPv6 literal needs brackets to carry a port; without them it is no name either.
        if host.is_empty() || host.contains(':') || host.parse::<IpAddr>().is_ok() {
            return Err(bad_name(
                "empty, or an IP literal in a form without a port".into(),
            ));
        }
        Name::from_ascii(host).map_err(|e| bad_name(e.to_string()))?;
        Ok(Self::Name {
            host: host.to_string(),
            port,
        })
    }
}

/// A failed resolution of one name.
#[derive(Debug, thiserror::Error)]
pub enum ResolveFailure {
    #[error("no answer within {:.0} s", RESOLVE_DEADLINE.as_secs_f64())]
    Deadline,
    #[error("{0}")]
    Dns(#[from] ResolveError),
}

/// The DNS resolver the render's names are looked up with: the system's configuration, or one
/// name server (UDP and TCP) for tests.
pub struct NameResolver {
    resolver: TokioResolver,
}

impl NameResolver {
    pub fn new(dns_server: Option<SocketAddr>) -> Result<Self, ResolveError> {
        let mut builder = match dns_server {
            Some(server) => TokioResolver::builder_with_config(
                ResolverConfig::from_parts(
                    None,
                    Vec::new(),
                    NameServerConfigGroup::from_ips_clear(&[server.ip()], server.port(), true),
                ),
                TokioConnectionProvider::default(),
            ),
            None => TokioResolver::builder_tokio()?,
        };
        let options: &mut ResolverOpts = builder.options_mut();
        // Each round asks again: the point of re-resolving is to see the cluster change.
        options.cache_size = 0;
        options.timeout = options.timeout.min(RESOLVE_DEADLINE / 2);
        Ok(Self {
            resolver: builder.build(),
        })
    }

    /// The addresses `host` resolves to, each with `port`, sorted, at most
    /// `MAX_ADDRESSES_PER_NAME` (the second value says how many more the answer held). A name
    /// with no address record is an empty answer, not a failure.
    pub async fn resolve(
        &self,
        host: &str,
        port: u16,
    ) -> Result<(BTreeSet<SocketAddr>, usize), ResolveFailure> {
        let lookup = tokio::time::timeout(RESOLVE_DEADLINE, self.resolver.lookup_ip(host))
            .await
            .map_err(|_| ResolveFailure::Deadline)?;
        let ips: Vec<IpAddr> = match lookup {
            Ok(answer) => answer.iter().collect(),
            Err(e) if e.is_no_records_found() => Vec::new(),
            Err(e) => return Err(e.into()),
        };
        Ok(cap_answer(ips, port))
    }
}

/// The answer as worker addresses, the first `MAX_ADDRESSES_PER_NAME` distinct ones in address
/// order (the same subset every round), and how many were left out.
fn cap_answer(ips: impl IntoIterator<Item = IpAddr>, port: u16) -> (BTreeSet<SocketAddr>, usize) {
    let all: BTreeSet<SocketAddr> = ips
        .into_iter()
        .map(|ip| SocketAddr::new(ip, port))
        .collect();
    let left_out = all.len().saturating_sub(MAX_ADDRESSES_PER_NAME);
    (
        all.into_iter().take(MAX_ADDRESSES_PER_NAME).collect(),
        left_out,
    )
}

/// How to reach a worker found under a name: the render's token and TLS settings; TLS checks
/// the worker's certificate against the name unless `--tls-domain` says otherwise.
pub struct ClientTemplate {
    pub token: Option<String>,
    pub tls: Option<ClientTlsConfig>,
    pub tls_domain_given: bool,
}

impl ClientTemplate {
    fn for_address(&self, host: &str, address: SocketAddr) -> ClientConfig {
        let tls = self.tls.clone().map(|tls| {
            if self.tls_domain_given {
                tls
            } else {
                tls.domain_name(host)
            }
        });
        ClientConfig {
            address: address.to_string(),
            token: self.token.clone(),
            tls,
        }
    }
}

/// A worker of the render and the task serving it.
struct ServedWorker {
    node: Arc<Node>,
    /// The `--workers` entry (name and port) it was found under; `None` for a listed address
    /// or a local worker.
    entry: Option<String>,
    address: Option<SocketAddr>,
    task: Option<JoinHandle<()>>,
    /// Tells the task to leave: no more units, finish the ones held.
    leave: watch::Sender<bool>,
    removed: bool,
}

/// Starts serving `node` in a task of its own; the sender asks it to leave.
fn spawn_session(
    node: &Arc<Node>,
    context: &Arc<SessionContext>,
) -> (JoinHandle<()>, watch::Sender<bool>) {
    let (leave, asked) = watch::channel(false);
    let task = tokio::spawn(run_node(node.clone(), context.clone(), asked));
    (task, leave)
}

/// The workers of a render, each served by its own session loop (`run_node`). It only grows:
/// a worker removed from DNS stays listed (as gone) for the final report.
pub struct Roster {
    context: Arc<SessionContext>,
    workers: Mutex<Vec<ServedWorker>>,
    /// The resolution task, while names are followed.
    follower: Mutex<Option<JoinHandle<()>>>,
}

impl Roster {
    pub fn new(context: Arc<SessionContext>) -> Self {
        Self {
            context,
            workers: Mutex::new(Vec::new()),
            follower: Mutex::new(None),
        }
    }

    /// Adds a listed or local worker and starts serving it (inside the runtime).
    pub fn add(&self, node: Node) {
        let node = Arc::new(node);
        let (task, leave) = spawn_session(&node, &self.context);
        self.workers.lock().unwrap().push(ServedWorker {
            node,
            entry: None,
            address: None,
            task: Some(task),
            leave,
            removed: false,
        });
    }

    /// Every worker the render has had, removed ones included.
    pub fn nodes(&self) -> Vec<Arc<Node>> {
        let workers = self.workers.lock().unwrap();
        workers.iter().map(|m| m.node.clone()).collect()
    }

    /// Workers currently in the render (not removed from DNS).
    pub fn current_count(&self) -> usize {
        let workers = self.workers.lock().unwrap();
        workers.iter().filter(|m| !m.removed).count()
    }

    /// Whether a followed name may still bring workers: the render should wait for them
    /// rather than fail when every worker it has is gone.
    pub fn may_grow(&self) -> bool {
        self.follower.lock().unwrap().is_some()
    }

    /// Stops every session and the resolution (the render is over).
    pub fn stop_all(&self) {
        if let Some(follower) = self.follower.lock().unwrap().take() {
            follower.abort();
        }
        for served in self.workers.lock().unwrap().iter_mut() {
            if let Some(task) = served.task.take() {
                task.abort();
            }
        }
    }

    /// Makes the workers found under `host`:`port` exactly `answer`: new addresses join,
    /// addresses that came back rejoin, missing ones are removed. Returns (joined, removed).
    fn follow_answer(
        &self,
        client: &ClientTemplate,
        (host, port): (&str, u16),
        answer: &BTreeSet<SocketAddr>,
    ) -> (usize, usize) {
        let entry = format!("{host}:{port}");
        let ours = |m: &ServedWorker| m.entry.as_deref() == Some(entry.as_str());
        let mut workers = self.workers.lock().unwrap();
        let mut removed = 0;
        for served in workers.iter_mut().filter(|m| ours(m)) {
            let in_answer = served.address.is_some_and(|a| answer.contains(&a));
            if !in_answer && !served.removed {
                served.removed = true;
                served.leave.send_replace(true);
                // Past the deadline, aborting the session gives what it still holds back to the
                // queue.
                if let Some(task) = served.task.take() {
                    let grace = self.context.deadline.current();
                    let session = task.abort_handle();
                    tokio::spawn(async move {
                        tokio::time::sleep(grace).await;
                        session.abort();
                    });
                }
                served.node.update(|r| {
                    r.connected = false;
                    r.gone = Some(REMOVED_FROM_DNS.to_string());
                });
                removed += 1;
            }
        }
        // An address already in the render (listed, or under another entry) is one worker.
        let elsewhere: HashSet<String> = workers
            .iter()
            .filter(|m| !ours(m) && !m.removed)
            .map(|m| m.node.address().to_string())
            .collect();
        let mut joined = 0;
        for &address in answer {
            if elsewhere.contains(&address.to_string()) {
                continue;
            }
            let existing = workers
                .iter_mut()
                .find(|m| ours(m) && m.address == Some(address));
            let node = match existing {
                Some(served) if served.removed => {
                    served.removed = false;
                    served.node.update(|r| r.gone = None);
                    // A new session; the old one, if still finishing its units, ends by itself.
                    let (task, leave) = spawn_session(&served.node, &self.context);
                    served.task = Some(task);
                    served.leave = leave;
                    joined += 1;
                    continue;
                }
                Some(_) => continue,
                None => Arc::new(Node::new(client.for_address(host, address), None)),
            };
            node.update(|r| r.dns_name = Some(host.to_string()));
            let (task, leave) = spawn_session(&node, &self.context);
            workers.push(ServedWorker {
                node,
                entry: Some(entry.clone()),
                address: Some(address),
                task: Some(task),
                leave,
                removed: false,
            });
            joined += 1;
        }
        (joined, removed)
    }
}

/// One followed name and what the last rounds found.
struct FollowedName {
    host: String,
    port: u16,
    /// Whether the last round failed (said once, until it succeeds again).
    failing: bool,
    /// Whether the last answer was cut to `MAX_ADDRESSES_PER_NAME` (said once).
    capped: bool,
    /// Whether the last answer had no address (said when it becomes so).
    empty: bool,
}

/// The DNS names of a render, resolved once at the start and then every `every` (if not zero).
pub struct Discovery {
    names: Vec<FollowedName>,
    resolver: NameResolver,
    client: ClientTemplate,
    every: Duration,
}

impl Discovery {
    pub fn new(
        targets: &[WorkerTarget],
        client: ClientTemplate,
        every: Duration,
        dns_server: Option<SocketAddr>,
    ) -> Result<Self, ResolveError> {
        let names = targets
            .iter()
            .filter_map(|t| match t {
                WorkerTarget::Name { host, port } => Some(FollowedName {
                    host: host.clone(),
                    port: *port,
                    failing: false,
                    capped: false,
                    empty: false,
                }),
                WorkerTarget::Address(_) => None,
            })
            .collect();
        Ok(Self {
            names,
            resolver: NameResolver::new(dns_server)?,
            client,
            every,
        })
    }

    /// Resolves every name once; then, when re-resolution is on, keeps following them in a
    /// task the roster owns. Resolved once only, a name that does not resolve, or resolves to
    /// no address, fails the render.
    pub async fn start(mut self, roster: &Arc<Roster>) -> anyhow::Result<()> {
        if self.names.is_empty() {
            return Ok(());
        }
        let resolve_once = self.every.is_zero();
        for index in 0..self.names.len() {
            let found = self.round(index, roster).await;
            if resolve_once {
                let host = &self.names[index].host;
                match found {
                    Err(e) => anyhow::bail!("cannot resolve worker name {host}: {e}"),
                    Ok(0) => anyhow::bail!("worker name {host} resolves to no address"),
                    Ok(_) => {}
                }
            }
        }
        if resolve_once {
            return Ok(());
        }
        let follower = {
            let roster = roster.clone();
            tokio::spawn(async move {
                let mut tick = tokio::time::interval(self.every);
                tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
                tick.tick().await;
                loop {
                    tick.tick().await;
                    for index in 0..self.names.len() {
                        let _ = self.round(index, &roster).await;
                    }
                }
            })
        };
        *roster.follower.lock().unwrap() = Some(follower);
        Ok(())
    }

    /// Resolves one name and makes the roster follow its answer; returns how many addresses it
    /// has. A failure keeps the last good answer and is said once.
    async fn round(&mut self, index: usize, roster: &Roster) -> Result<usize, ResolveFailure> {
        let name = &mut self.names[index];
        let context = &roster.context;
        let (answer, left_out) = match self.resolver.resolve(&name.host, name.port).await {
            Ok(answer) => answer,
            Err(e) => {
                if !std::mem::replace(&mut name.failing, true) {
                    context.notice(format!(
                        "cannot resolve {} ({e}); keeping its last answer",
                        name.host
                    ));
                }
                return Err(e);
            }
        };
        if std::mem::take(&mut name.failing) {
            context.notice(format!("{} resolves again", name.host));
        }
        if left_out > 0 && !std::mem::replace(&mut name.capped, true) {
            context.notice(format!(
                "{} resolves to {} addresses; using the first {MAX_ADDRESSES_PER_NAME}",
                name.host,
                MAX_ADDRESSES_PER_NAME + left_out
            ));
        }
        if answer.is_empty() && !std::mem::replace(&mut name.empty, true) {
            context.notice(format!("{} resolves to no address (yet)", name.host));
        }
        name.empty = answer.is_empty();
        let (joined, removed) =
            roster.follow_answer(&self.client, (&name.host, name.port), &answer);
        if joined + removed > 0 {
            context.notice(format!(
                "{} resolves to {} address(es): {joined} joined, {removed} removed",
                name.host,
                answer.len()
            ));
        }
        Ok(answer.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ip_literals_are_addresses_and_the_rest_names() {
        assert_eq!(
            WorkerTarget::parse(" 10.0.0.5:7878").unwrap(),
            WorkerTarget::Address("10.0.0.5:7878".parse().unwrap())
        );
        assert_eq!(
            WorkerTarget::parse("[::1]:7878").unwrap(),
            WorkerTarget::Address("[::1]:7878".parse().unwrap())
        );
        assert_eq!(
            WorkerTarget::parse("yat-workers.default.svc.cluster.local:7878").unwrap(),
            WorkerTarget::Name {
                host: "yat-workers.default.svc.cluster.local".into(),
                port: 7878
            }
        );
        for bad in [
            "node1",
            "node1:",
            "node1:0",
            "node1:70000",
            ":7878",
            "::1:7878",
            "bad name:7878",
        ] {
            assert!(WorkerTarget::parse(bad).is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn an_answer_is_deduplicated_sorted_and_capped() {
        let ips = (0..MAX_ADDRESSES_PER_NAME as u32 + 10)
            .rev()
            .map(|i| IpAddr::from(std::net::Ipv4Addr::from(0x0a00_0000_u32 + i)))
            .chain([IpAddr::from([10, 0, 0, 0])]);
        let (answer, left_out) = cap_answer(ips, 7878);
        assert_eq!((answer.len(), left_out), (MAX_ADDRESSES_PER_NAME, 10));
        assert_eq!(
            answer.first().unwrap(),
            &"10.0.0.0:7878".parse::<SocketAddr>().unwrap()
        );
        assert!(answer.iter().all(|a| a.port() == 7878));
    }

    #[test]
    fn a_worker_under_a_name_is_reached_at_its_address_with_the_render_token() {
        let address: SocketAddr = "10.0.0.5:7878".parse().unwrap();
        let plain = ClientTemplate {
            token: Some("t".into()),
            tls: None,
            tls_domain_given: false,
        };
        let config = plain.for_address("w.example", address);
        assert_eq!(config.address, "10.0.0.5:7878");
        assert_eq!(config.token.as_deref(), Some("t"));
        assert!(config.tls.is_none());
        config.validate().unwrap();
    }

    fn roster() -> Roster {
        use super::super::schedule::{Schedule, UnitDeadline};
        use crate::manifest::SceneManifest;
        use yat_tracer::filter::{FilterDesc, FilterKind, PixelFilter};
        Roster::new(Arc::new(SessionContext {
            schedule: Schedule::new(Vec::new(), |_| false, true),
            deadline: UnitDeadline::new(None),
            manifest: SceneManifest {
                main: Default::default(),
                assets: Vec::new(),
                blobs: Default::default(),
            },
            load_request: Default::default(),
            frame: yat_tracer::render::unit::FilmFrame::unbordered(1, 1),
            weights: PixelFilter::new(&FilterDesc {
                kind: FilterKind::Box,
                xwidth: 0.5,
                ywidth: 0.5,
            })
            .weight_bounds(),
            events: tokio::sync::mpsc::unbounded_channel().0,
        }))
    }

    #[tokio::test]
    async fn the_roster_follows_each_answer_and_takes_returning_addresses_back() {
        let roster = roster();
        let client = ClientTemplate {
            token: None,
            tls: None,
            tls_domain_given: false,
        };
        let [a, b]: [SocketAddr; 2] = [
            "127.0.0.1:1".parse().unwrap(),
            "127.0.0.2:1".parse().unwrap(),
        ];
        let follow = |answer: &[SocketAddr]| {
            roster.follow_answer(&client, ("w.test", 1), &answer.iter().copied().collect())
        };
        let gone = |i: usize| roster.nodes()[i].report.lock().unwrap().gone.clone();
        assert_eq!(follow(&[a, b]), (2, 0));
        assert_eq!(follow(&[b, a]), (0, 0), "the same answer changes nothing");
        assert_eq!(follow(&[b]), (0, 1));
        assert_eq!(gone(0).as_deref(), Some(REMOVED_FROM_DNS));
        assert_eq!((roster.nodes().len(), roster.current_count()), (2, 1));
        assert!(
            roster.workers.lock().unwrap()[0].task.is_none(),
            "its session is stopped"
        );
        assert_eq!(
            follow(&[a, b]),
            (1, 0),
            "a returning address is a worker again"
        );
        assert_eq!(gone(0), None);
        assert_eq!((roster.nodes().len(), roster.current_count()), (2, 2));
        assert_eq!(follow(&[]), (0, 2));
        assert_eq!(roster.current_count(), 0);
        let listed = client.for_address("listed", a);
        roster.add(Node::new(listed, None));
        assert_eq!(
            follow(&[a]),
            (0, 0),
            "a listed address is not a second worker"
        );
        assert_eq!(roster.current_count(), 1);
        let other_port = BTreeSet::from(["127.0.0.1:2".parse().unwrap()]);
        assert_eq!(
            roster.follow_answer(&client, ("w.test", 2), &other_port),
            (1, 0),
            "the name with another port is another entry, leaving the first alone"
        );
        assert_eq!(roster.current_count(), 2);
        let reports: Vec<_> = roster
            .nodes()
            .iter()
            .map(|n| n.report.lock().unwrap().clone())
            .collect();
        assert!(reports[..2]
            .iter()
            .all(|r| r.dns_name.as_deref() == Some("w.test")));
        assert_eq!(reports[2].dns_name, None);
        assert_eq!(reports[1].address, "127.0.0.2:1");
        roster.stop_all();
    }
}
