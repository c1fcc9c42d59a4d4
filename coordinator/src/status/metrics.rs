//! `/metrics`: the snapshot in the Prometheus text exposition format (version 0.0.4), the
//! figures a farm operator graphs: samples and units over time, the progress ratio, and per
//! worker its state, samples, units, failures and bytes. Written with the worker crate's
//! `prometheus_text`, which a worker's own `/metrics` uses too.

use yat_worker::prometheus_text::{labels, Exposition, MetricType};

use super::snapshot::{RenderState, Snapshot, WorkerRow, WorkerState};

pub use yat_worker::prometheus_text::CONTENT_TYPE;

use MetricType::{Counter, Gauge};

/// A family with one sample per worker: name, type, help, the value of the worker's row.
type WorkerFamily = (
    &'static str,
    MetricType,
    &'static str,
    fn(&WorkerRow) -> f64,
);

/// The exposition of `snap`.
pub fn render(snap: &Snapshot) -> String {
    let mut out = Exposition::new();
    let p = &snap.progress;
    // The render's families, one sample each: name, type, help, value.
    let totals = [
        (
            "yat_up",
            Gauge,
            "1 while the render runs, 0 once it has ended.",
            f64::from(u8::from(snap.state == RenderState::Rendering)),
        ),
        (
            "yat_render_failed",
            Gauge,
            "1 if the render ended in an error.",
            f64::from(u8::from(snap.state == RenderState::Failed)),
        ),
        (
            "yat_samples_total",
            Counter,
            "Camera samples merged into the image (a resumed checkpoint's included).",
            p.samples_done as f64,
        ),
        (
            "yat_samples_planned",
            Gauge,
            "Camera samples of the whole render.",
            p.samples_total as f64,
        ),
        (
            "yat_units_done_total",
            Counter,
            "Work units merged.",
            p.units_done as f64,
        ),
        (
            "yat_units_planned",
            Gauge,
            "Work units of the whole render.",
            p.units_total as f64,
        ),
        (
            "yat_units_requeued_total",
            Counter,
            "Work units a worker lost or gave back, sent again.",
            p.units_requeued as f64,
        ),
        (
            "yat_progress_ratio",
            Gauge,
            "Samples merged over samples planned, 0 to 1.",
            p.ratio,
        ),
        (
            "yat_samples_per_second",
            Gauge,
            "Samples this run merged per second so far.",
            p.samples_per_second,
        ),
        (
            "yat_elapsed_seconds",
            Gauge,
            "Seconds since the render started.",
            p.elapsed_seconds,
        ),
    ];
    for (name, kind, help, value) in totals {
        out.single(name, kind, help, value);
    }
    let per_worker = |value: fn(&WorkerRow) -> f64| -> Vec<(String, f64)> {
        snap.workers
            .iter()
            .map(|w| (labels(&[("worker", &w.address)]), value(w)))
            .collect()
    };
    out.family(
        "yat_worker_up",
        Gauge,
        "1 while the worker is connected (stalled included).",
        per_worker(|w| {
            f64::from(u8::from(matches!(
                w.state,
                WorkerState::Connected | WorkerState::Stalled
            )))
        }),
    );
    let states: Vec<_> = snap
        .workers
        .iter()
        .flat_map(|w| {
            WorkerState::ALL.iter().map(|&state| {
                (
                    labels(&[
                        ("worker", &w.address),
                        ("host", &w.hostname),
                        ("state", state.name()),
                    ]),
                    f64::from(u8::from(w.state == state)),
                )
            })
        })
        .collect();
    out.family(
        "yat_worker_state",
        Gauge,
        "1 for the worker's state: connecting, connected, stalled, gone or done.",
        states,
    );
    let worker_families: [WorkerFamily; 7] = [
        (
            "yat_worker_threads",
            Gauge,
            "Render threads the worker reported.",
            |w| f64::from(w.threads),
        ),
        (
            "yat_worker_samples_total",
            Counter,
            "Camera samples of the worker's units that were merged.",
            |w| w.samples as f64,
        ),
        (
            "yat_worker_units_total",
            Counter,
            "Work units of the worker that were merged.",
            |w| w.units as f64,
        ),
        (
            "yat_worker_failures_total",
            Counter,
            "Sessions the worker lost and bad replies it sent.",
            |w| w.failures as f64,
        ),
        (
            "yat_worker_units_requeued_total",
            Counter,
            "Work units the worker held that went back to the queue.",
            |w| w.units_requeued as f64,
        ),
        (
            "yat_worker_sent_bytes_total",
            Counter,
            "Bytes of every request sent to the worker, scene files included.",
            |w| w.bytes_sent as f64,
        ),
        (
            "yat_worker_received_bytes_total",
            Counter,
            "Bytes of every reply received from the worker.",
            |w| w.bytes_received as f64,
        ),
    ];
    for (name, kind, help, value) in worker_families {
        out.family(name, kind, help, per_worker(value));
    }
    out.finish()
}

#[cfg(test)]
mod tests {
    use super::super::board::StatusBoard;
    use super::super::snapshot::{SceneInfo, SettingsInfo};
    use super::*;

    #[test]
    fn figures_and_escaped_labels() {
        let board = StatusBoard::new(SceneInfo::default(), SettingsInfo::default(), false);
        board.plan(4, 0, 400, 0);
        board.unit_merged(100);
        let worker = WorkerRow {
            address: "10.0.0.1:7000".into(),
            hostname: "evil\"\\\nhost".into(),
            threads: 8,
            state: WorkerState::Gone,
            units: 1,
            samples: 100,
            samples_per_second: 0.0,
            failures: 2,
            units_requeued: 3,
            bytes_sent: 10,
            bytes_received: 20,
            reason: None,
        };
        board.set_workers(vec![worker], std::time::Duration::ZERO);
        let text = render(&board.snapshot());
        assert!(text.contains("\nyat_samples_total 100\n"), "{text}");
        assert!(text.contains("\nyat_progress_ratio 0.25\n"), "{text}");
        assert!(text.contains("\nyat_units_requeued_total 3\n"), "{text}");
        assert!(text.contains("yat_worker_failures_total{worker=\"10.0.0.1:7000\"} 2\n"));
        assert!(text.contains(
            "yat_worker_state{worker=\"10.0.0.1:7000\",host=\"evil\\\"\\\\\\nhost\",state=\"gone\"} 1\n"
        ));
        assert!(text.contains("state=\"connected\"} 0\n"));
        // Every line is a comment or `name{labels} value` with a number.
        for line in text.lines().filter(|l| !l.starts_with('#')) {
            let value = line.rsplit(' ').next().unwrap();
            assert!(value.parse::<f64>().is_ok(), "{line}");
        }
    }
}
