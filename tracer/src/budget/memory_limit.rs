//! The memory this process may still use, and which limit says so: the default of the build
//! budget's memory figure.
//!
//! Three limits can stop an allocation, and the smallest wins:
//! - the control group's (cgroup v2 `memory.max`, v1 `memory.limit_in_bytes`, the least of the
//!   process's group and its ancestors), against which the process's resident memory counts;
//! - the address space (`RLIMIT_AS`), against which everything mapped counts, resident or not
//!   (`VmSize`: the allocator's arenas and the threads' stacks reserve much more than they use);
//! - the machine's memory (`MemTotal`), the last resort, against the resident memory.
//!
//! What the build may hold is the room under the smallest, times [`SAFETY_FRACTION`].

use std::fmt;
use std::path::Path;

/// The share of the room under the limit that the build's estimate may take: the rest is for
/// what the estimate leaves out (arenas and stacks of threads started later, the unused
/// capacity of growing vectors, unit buffers, the allocator's own rounding).
pub const SAFETY_FRACTION: (u64, u64) = (3, 4);

/// Values of `memory.max` / `memory.limit_in_bytes` at or above this mean no limit (cgroup v1
/// writes 2^63 rounded down to a page).
const NO_LIMIT: u64 = 1 << 60;

/// Which limit bounds the process.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MemorySource {
    /// A control group's limit (the file it was read from).
    Cgroup(String),
    /// `RLIMIT_AS`.
    AddressSpace,
    /// The machine's memory (`MemTotal` in /proc/meminfo).
    Physical,
    /// None was found (not Linux, or /proc unreadable).
    Unknown,
}

/// The smallest limit on this process's memory and what the process already uses of it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryLimit {
    pub source: MemorySource,
    /// Bytes (u64::MAX for [`MemorySource::Unknown`]).
    pub limit: u64,
    /// What already counts against `limit`.
    pub in_use: u64,
}

impl MemoryLimit {
    /// The limits of this process now.
    pub fn detect() -> Self {
        let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
        let vm_size = status_bytes(&status, "VmSize:").unwrap_or(0);
        let vm_rss = status_bytes(&status, "VmRSS:").unwrap_or(0);
        let mut candidates = Vec::new();
        let cgroups = std::fs::read_to_string("/proc/self/cgroup").unwrap_or_default();
        if let Some((file, limit)) = cgroup_limit(&cgroups, Path::new("/sys/fs/cgroup")) {
            candidates.push(Self {
                source: MemorySource::Cgroup(file),
                limit,
                in_use: vm_rss,
            });
        }
        if let Some(limit) = address_space_limit() {
            candidates.push(Self {
                source: MemorySource::AddressSpace,
                limit,
                in_use: vm_size,
            });
        }
        let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
        if let Some(limit) = status_bytes(&meminfo, "MemTotal:") {
            candidates.push(Self {
                source: MemorySource::Physical,
                limit,
                in_use: vm_rss,
            });
        }
        candidates
            .into_iter()
            .min_by_key(Self::room)
            .unwrap_or(Self {
                source: MemorySource::Unknown,
                limit: u64::MAX,
                in_use: 0,
            })
    }

    /// Bytes the process may still take under the limit.
    pub fn room(&self) -> u64 {
        self.limit.saturating_sub(self.in_use)
    }

    /// What the build may hold: [`SAFETY_FRACTION`] of the room.
    pub fn build_bytes(&self) -> u64 {
        let (num, den) = SAFETY_FRACTION;
        if self.source == MemorySource::Unknown {
            return u64::MAX;
        }
        (u128::from(self.room()) * u128::from(num) / u128::from(den)) as u64
    }
}

impl fmt::Display for MemoryLimit {
    /// Where the figure comes from, e.g. "3/4 of the 1843 MiB left under RLIMIT_AS (2048 MiB,
    /// 205 MiB of address space in use)".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mib = |b: u64| b >> 20;
        let (num, den) = SAFETY_FRACTION;
        let (what, used) = match &self.source {
            MemorySource::Cgroup(file) => {
                (format!("the control group's limit ({file})"), "resident")
            }
            MemorySource::AddressSpace => ("RLIMIT_AS".to_string(), "address space"),
            MemorySource::Physical => ("the machine's memory (MemTotal)".to_string(), "resident"),
            MemorySource::Unknown => return write!(f, "no memory limit found: unbounded"),
        };
        write!(
            f,
            "{num}/{den} of the {} MiB left under {what} ({} MiB, {} MiB {used} in use at start)",
            mib(self.room()),
            mib(self.limit),
            mib(self.in_use)
        )
    }
}

/// A "Key:   123 kB" line of /proc/self/status or /proc/meminfo, in bytes.
fn status_bytes(text: &str, key: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let mut words = line[key.len()..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

/// A limit file's value: None for "max", values meaning no limit, and unreadable text.
fn limit_value(text: &str) -> Option<u64> {
    text.trim().parse::<u64>().ok().filter(|&v| v < NO_LIMIT)
}

/// The smallest memory limit of the groups /proc/self/cgroup (`cgroups`) names, and of their
/// ancestors, under the cgroup mount `root`: (the file that holds it, bytes).
fn cgroup_limit(cgroups: &str, root: &Path) -> Option<(String, u64)> {
    let mut limits = Vec::new();
    for line in cgroups.lines() {
        let mut fields = line.splitn(3, ':');
        let (Some(id), Some(controllers), Some(path)) =
            (fields.next(), fields.next(), fields.next())
        else {
            continue;
        };
        let (base, file) = if id == "0" && controllers.is_empty() {
            // cgroup v2; on a hybrid host its hierarchy is mounted at `unified`.
            if root.join("cgroup.controllers").exists() {
                (root.to_path_buf(), "memory.max")
            } else {
                (root.join("unified"), "memory.max")
            }
        } else if controllers.split(',').any(|c| c == "memory") {
            (root.join("memory"), "memory.limit_in_bytes")
        } else {
            continue;
        };
        let mut group = Path::new(path.trim_start_matches('/'));
        loop {
            let at = base.join(group).join(file);
            if let Some(v) = std::fs::read_to_string(&at)
                .ok()
                .as_deref()
                .and_then(limit_value)
            {
                limits.push((at.display().to_string(), v));
            }
            match group.parent() {
                Some(parent) => group = parent,
                None => break,
            }
        }
    }
    limits.into_iter().min_by_key(|&(_, v)| v)
}

/// `RLIMIT_AS`'s soft limit, if there is one.
fn address_space_limit() -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given and nothing else.
    let ok = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } == 0;
    (ok && limit.rlim_cur != libc::RLIM_INFINITY).then_some(limit.rlim_cur)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_lines_read_in_bytes() {
        let status = "Name:\tyat\nVmSize:\t  222028 kB\nVmRSS:\t    9164 kB\n";
        assert_eq!(status_bytes(status, "VmSize:"), Some(222_028 * 1024));
        assert_eq!(status_bytes(status, "VmRSS:"), Some(9164 * 1024));
        assert_eq!(status_bytes(status, "VmHWM:"), None);
        assert_eq!(status_bytes("VmSize: lots kB", "VmSize:"), None);
    }

    #[test]
    fn limit_files_say_max_or_a_number() {
        assert_eq!(limit_value("max\n"), None);
        assert_eq!(limit_value("9223372036854771712\n"), None);
        assert_eq!(limit_value("536870912\n"), Some(512 << 20));
        assert_eq!(limit_value(""), None);
    }

    /// The least limit of the group and its ancestors, in v2's and v1's layouts.
    #[test]
    fn a_cgroup_limit_is_the_least_of_the_group_and_its_ancestors() {
        let root = tempfile::tempdir().unwrap();
        let v2 = root.path().join("unified/job/step");
        std::fs::create_dir_all(&v2).unwrap();
        std::fs::write(root.path().join("unified/job/memory.max"), "1073741824\n").unwrap();
        std::fs::write(v2.join("memory.max"), "max\n").unwrap();
        let (file, bytes) = cgroup_limit("0::/job/step\n", root.path()).unwrap();
        assert_eq!(bytes, 1 << 30);
        assert!(file.ends_with("unified/job/memory.max"), "{file}");

        let v1 = root.path().join("memory/box");
        std::fs::create_dir_all(&v1).unwrap();
        std::fs::write(v1.join("memory.limit_in_bytes"), "268435456\n").unwrap();
        let lines = "4:memory:/box\n3:cpu,cpuacct:/box\n0::/job/step\n";
        assert_eq!(cgroup_limit(lines, root.path()).unwrap().1, 256 << 20);
        assert_eq!(cgroup_limit("1:cpu:/box\n", root.path()), None);
    }

    #[test]
    fn the_build_may_take_the_safety_fraction_of_the_room() {
        let limit = MemoryLimit {
            source: MemorySource::AddressSpace,
            limit: 2048 << 20,
            in_use: 448 << 20,
        };
        assert_eq!(limit.room(), 1600 << 20);
        assert_eq!(limit.build_bytes(), 1200 << 20);
        let text = limit.to_string();
        assert!(
            text.contains("RLIMIT_AS") && text.contains("1600 MiB"),
            "{text}"
        );
        let detected = MemoryLimit::detect();
        assert!(detected.build_bytes() > 0, "{detected}");
    }
}
