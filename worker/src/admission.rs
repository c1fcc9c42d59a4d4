//! Which connections a worker keeps before they have authenticated. Anyone who reaches the
//! port can open connections and send nothing; left alone they would fill every connection
//! slot. So a connection counts as *pending* from its accept until its first request passes the
//! token check (or it closes), and pending connections are held to two caps well below the
//! connection cap:
//!
//! - per peer (an IPv4 address, or an IPv6 /64, what one host usually has): a connection beyond
//!   the peer's allowance is closed at once;
//! - in total: a new connection when the pending ones are at the cap closes the oldest pending
//!   connection of the peer with the most of them, so a newcomer always gets in and a flood
//!   from a few peers evicts its own connections first.
//!
//! Authenticated connections are not counted here; the connection cap and the idle timeout
//! bound them. The handshake deadline (`connection.rs`) closes a pending connection that stays
//! pending too long.

use std::collections::{BTreeMap, HashMap};
use std::net::IpAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::task::Waker;

use futures_util::task::AtomicWaker;

/// The caps on pending connections.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AdmissionLimits {
    /// Pending connections at once, all peers together.
    pub total: usize,
    /// Pending connections at once from one peer.
    pub per_peer: usize,
}

/// A connection refused at admission.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
#[error("{peer} already has {max} connections that have not authenticated")]
pub struct PeerFull {
    pub peer: PeerKey,
    pub max: usize,
}

/// What one peer's connections are counted under: an IPv4 address, or the /64 prefix of an
/// IPv6 one (IPv4-mapped IPv6 addresses count as their IPv4 address).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PeerKey(IpAddr);

impl PeerKey {
    pub fn of(address: IpAddr) -> Self {
        match address.to_canonical() {
            IpAddr::V4(v4) => Self(IpAddr::V4(v4)),
            IpAddr::V6(v6) => {
                let prefix = u128::from(v6) & !((1u128 << 64) - 1);
                Self(IpAddr::V6(prefix.into()))
            }
        }
    }
}

impl std::fmt::Display for PeerKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            IpAddr::V4(v4) => write!(f, "{v4}"),
            IpAddr::V6(v6) => write!(f, "{v6}/64"),
        }
    }
}

/// The pending connections of one listener.
#[derive(Debug)]
pub struct Admission {
    limits: AdmissionLimits,
    pending: Mutex<Pending>,
}

#[derive(Debug, Default)]
struct Pending {
    next_id: u64,
    per_peer: HashMap<PeerKey, usize>,
    /// By admission order, so the first of a peer's is its oldest.
    by_age: BTreeMap<u64, Arc<Standing>>,
}

/// One connection's standing, shared by the connection and the requests it carries.
#[derive(Debug)]
struct Standing {
    id: u64,
    peer: PeerKey,
    authenticated: AtomicBool,
    evicted: AtomicBool,
    /// The connection's reader, woken when admission evicts it.
    reader: AtomicWaker,
}

impl Admission {
    pub fn new(limits: AdmissionLimits) -> Arc<Self> {
        Arc::new(Self {
            limits: AdmissionLimits {
                total: limits.total.max(1),
                per_peer: limits.per_peer.max(1),
            },
            pending: Mutex::new(Pending::default()),
        })
    }

    /// Admits a new connection from `peer` as pending, evicting another pending one when the
    /// total is at its cap; refuses it when `peer` is at its own cap.
    pub fn admit(self: &Arc<Self>, peer: IpAddr) -> Result<ConnectionStanding, PeerFull> {
        let peer = PeerKey::of(peer);
        let mut pending = self.lock();
        let of_peer = pending.per_peer.get(&peer).copied().unwrap_or(0);
        if of_peer >= self.limits.per_peer {
            return Err(PeerFull {
                peer,
                max: self.limits.per_peer,
            });
        }
        if pending.by_age.len() >= self.limits.total {
            pending.evict_one();
        }
        let id = pending.next_id;
        pending.next_id += 1;
        let standing = Arc::new(Standing {
            id,
            peer,
            authenticated: AtomicBool::new(false),
            evicted: AtomicBool::new(false),
            reader: AtomicWaker::new(),
        });
        *pending.per_peer.entry(peer).or_default() += 1;
        pending.by_age.insert(id, standing.clone());
        Ok(ConnectionStanding {
            admission: self.clone(),
            standing,
        })
    }

    /// Pending connections now.
    #[cfg(test)]
    fn pending(&self) -> usize {
        self.lock().by_age.len()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Pending> {
        self.pending.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Pending {
    /// Evicts the oldest pending connection of the peer with the most of them.
    fn evict_one(&mut self) {
        let Some((&busiest, _)) = self.per_peer.iter().max_by_key(|(_, &count)| count) else {
            return;
        };
        let Some(victim) = self.by_age.values().find(|s| s.peer == busiest).cloned() else {
            return;
        };
        self.remove(&victim);
        victim.evicted.store(true, Ordering::Release);
        victim.reader.wake();
    }

    fn remove(&mut self, standing: &Standing) {
        if self.by_age.remove(&standing.id).is_none() {
            return;
        }
        if let Some(count) = self.per_peer.get_mut(&standing.peer) {
            *count -= 1;
            if *count == 0 {
                self.per_peer.remove(&standing.peer);
            }
        }
    }
}

/// One connection's standing: pending, authenticated or evicted. The connection holds one and
/// hands a clone to every request it carries (in the request's extensions), so the token check
/// can mark it authenticated.
#[derive(Clone, Debug)]
pub struct ConnectionStanding {
    admission: Arc<Admission>,
    standing: Arc<Standing>,
}

impl ConnectionStanding {
    /// A request on this connection passed the token check: it is no longer pending.
    pub fn authenticated(&self) {
        if !self.standing.authenticated.swap(true, Ordering::AcqRel) {
            self.admission.lock().remove(&self.standing);
        }
    }

    pub fn is_authenticated(&self) -> bool {
        self.standing.authenticated.load(Ordering::Acquire)
    }

    /// Whether admission closed it to make room; `reader` is woken when that happens.
    pub fn is_evicted(&self, reader: &Waker) -> bool {
        self.standing.reader.register(reader);
        self.standing.evicted.load(Ordering::Acquire)
    }

    /// The connection closed.
    pub fn closed(&self) {
        self.admission.lock().remove(&self.standing);
    }
}

#[cfg(test)]
mod tests {
    use std::task::Waker;

    use super::*;

    fn ip(text: &str) -> IpAddr {
        text.parse().unwrap()
    }

    fn evicted(c: &ConnectionStanding) -> bool {
        c.is_evicted(Waker::noop())
    }

    #[test]
    fn a_peer_past_its_allowance_is_refused_and_others_are_not() {
        let admission = Admission::new(AdmissionLimits {
            total: 100,
            per_peer: 3,
        });
        let held: Vec<_> = (0..3)
            .map(|_| admission.admit(ip("10.0.0.1")).unwrap())
            .collect();
        let refused = admission.admit(ip("10.0.0.1")).unwrap_err();
        assert_eq!(refused.max, 3);
        assert!(refused.to_string().contains("10.0.0.1"), "{refused}");
        admission.admit(ip("10.0.0.2")).unwrap();
        // Authenticating or closing one gives the peer its allowance back.
        held[0].authenticated();
        admission.admit(ip("10.0.0.1")).unwrap();
        admission.admit(ip("10.0.0.1")).unwrap_err();
        held[1].closed();
        admission.admit(ip("10.0.0.1")).unwrap();
        assert_eq!(admission.pending(), 4);
    }

    #[test]
    fn at_the_total_cap_the_busiest_peer_loses_its_oldest_pending_connection() {
        let admission = Admission::new(AdmissionLimits {
            total: 4,
            per_peer: 8,
        });
        let attacker: Vec<_> = (0..3)
            .map(|_| admission.admit(ip("192.0.2.9")).unwrap())
            .collect();
        let honest = admission.admit(ip("198.51.100.1")).unwrap();
        // Each new connection from the attacker evicts the attacker's own oldest.
        let more: Vec<_> = (0..5)
            .map(|_| admission.admit(ip("192.0.2.9")).unwrap())
            .collect();
        assert!(!evicted(&honest));
        assert!(attacker.iter().all(evicted));
        assert_eq!(more.iter().filter(|c| evicted(c)).count(), 2);
        assert_eq!(admission.pending(), 4);
        // Once authenticated, the honest connection is out of reach of admission.
        honest.authenticated();
        assert!(honest.is_authenticated());
        for _ in 0..10 {
            admission.admit(ip("203.0.113.7")).unwrap();
        }
        assert!(!evicted(&honest));
    }

    #[test]
    fn an_ipv6_host_is_its_64_prefix_and_mapped_ipv4_is_ipv4() {
        assert_eq!(
            PeerKey::of(ip("2001:db8:1:2:aaaa::1")),
            PeerKey::of(ip("2001:db8:1:2:ffff::9"))
        );
        assert_ne!(
            PeerKey::of(ip("2001:db8:1:2::1")),
            PeerKey::of(ip("2001:db8:1:3::1"))
        );
        assert_eq!(
            PeerKey::of(ip("::ffff:10.0.0.1")),
            PeerKey::of(ip("10.0.0.1"))
        );
        let admission = Admission::new(AdmissionLimits {
            total: 100,
            per_peer: 1,
        });
        let _first = admission.admit(ip("2001:db8::1")).unwrap();
        admission.admit(ip("2001:db8::2")).unwrap_err();
    }
}
