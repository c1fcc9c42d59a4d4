//! What a distributed render reports at its end: the per-worker summary and its JSON form
//! (`--workers-json`).

use std::time::Duration;

use super::node::NodeReport;

/// `--workers-json`: the whole render's figures and each worker's.
#[derive(serde::Serialize)]
pub struct DistributedReport {
    pub wall_seconds: f64,
    /// CPU time this process spent during the distributed render (reading and hashing the
    /// scene files, scheduling, merging, previews).
    pub coordinator_cpu_seconds: f64,
    pub units: usize,
    /// End-game copies of units still out elsewhere (each rendered a unit a second time).
    pub units_copied: u64,
    pub samples: u64,
    pub samples_per_second: f64,
    /// Result bytes received per pixel of every unit (16 = four f32 per pixel).
    pub result_bytes_per_unit_pixel: f64,
    pub workers: Vec<NodeReport>,
}

impl DistributedReport {
    pub fn new(
        wall: Duration,
        cpu: Duration,
        units: usize,
        samples: u64,
        workers: Vec<NodeReport>,
    ) -> Self {
        let wall_seconds = wall.as_secs_f64().max(1e-9);
        let (bytes, pixels) = workers.iter().fold((0, 0), |(b, p), w| {
            (b + w.result_bytes, p + w.result_pixels)
        });
        Self {
            wall_seconds,
            coordinator_cpu_seconds: cpu.as_secs_f64(),
            units,
            units_copied: 0,
            samples,
            samples_per_second: samples as f64 / wall_seconds,
            result_bytes_per_unit_pixel: bytes as f64 / pixels.max(1) as f64,
            workers,
        }
    }

    pub fn print(&self) {
        println!(
            "{:<22} {:<16} {:>7} {:>6} {:>10} {:>8} {:>10} {:>10}",
            "worker", "host", "threads", "units", "samples/s", "failures", "sent", "received"
        );
        for w in &self.workers {
            println!(
                "{:<22} {:<16} {:>7} {:>6} {:>10} {:>8} {:>10} {:>10}{}",
                w.address,
                w.hostname,
                w.threads,
                w.units,
                format_count(w.samples as f64 / self.wall_seconds),
                w.failures,
                format_bytes(w.bytes_sent),
                format_bytes(w.bytes_received),
                w.gone
                    .as_ref()
                    .map_or(String::new(), |g| format!("  (gone: {g})"))
            );
        }
        println!(
            "coordinator: {:.3} s CPU over {:.3} s, {:.1} result bytes per pixel",
            self.coordinator_cpu_seconds, self.wall_seconds, self.result_bytes_per_unit_pixel
        );
    }
}

fn format_count(v: f64) -> String {
    match v {
        v if v >= 1e6 => format!("{:.2} M", v / 1e6),
        v if v >= 1e3 => format!("{:.1} k", v / 1e3),
        v => format!("{v:.0}"),
    }
}

fn format_bytes(b: u64) -> String {
    match b {
        b if b >= 1 << 20 => format!("{:.1} MiB", b as f64 / (1 << 20) as f64),
        b if b >= 1 << 10 => format!("{:.1} KiB", b as f64 / (1 << 10) as f64),
        b => format!("{b} B"),
    }
}

/// CPU time (user + system) this process has used so far.
pub fn process_cpu_time() -> Duration {
    // SAFETY: getrusage only writes the struct we pass.
    let usage = unsafe {
        let mut usage = std::mem::zeroed::<libc::rusage>();
        libc::getrusage(libc::RUSAGE_SELF, &mut usage);
        usage
    };
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, t.tv_usec as u32 * 1000);
    tv(usage.ru_utime) + tv(usage.ru_stime)
}
