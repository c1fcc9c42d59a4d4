//! Progress for logs: run as a farm runs it, standard error a pipe and not a terminal, a render
//! writes progress lines at the interval asked for and, with `--progress-json`, one JSON object
//! a line whose figures only grow and end at the whole render.

use crate::util::*;

/// 3 million samples: some seconds, so several 0.2 s intervals pass.
const SETTINGS: [&str; 4] = ["--spp", "1024", "--resolution", "64x48"];

#[test]
fn without_a_terminal_a_render_logs_progress_lines_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("logged.png");
    let json = dir.path().join("progress.jsonl");
    let output = piped_render_command(
        &scene,
        &out,
        &SETTINGS,
        &[
            "--threads",
            "2",
            "--checkpoint-every",
            "0",
            "--progress-every",
            "0.2",
            "--progress-json",
            json.to_str().unwrap(),
        ],
    )
    .output()
    .unwrap();
    assert_success(&output);
    let stderr = stderr_of(&output);
    let percents: Vec<f64> = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("progress "))
        .map(|rest| {
            assert!(
                rest.contains("samples/s | ETA ") && rest.contains("| units "),
                "{rest}"
            );
            rest.split('%').next().unwrap().parse().unwrap()
        })
        .collect();
    assert!(!percents.is_empty(), "no progress line in\n{stderr}");
    assert!(
        percents.windows(2).all(|w| w[0] <= w[1])
            && percents.iter().all(|p| (0.0..=100.0).contains(p)),
        "{percents:?}"
    );

    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&json)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    assert!(
        lines.len() >= percents.len(),
        "{} JSON lines, {} text lines",
        lines.len(),
        percents.len()
    );
    let figure = |v: &serde_json::Value, name: &str| {
        v[name].as_u64().unwrap_or_else(|| panic!("{name} in {v}"))
    };
    let done: Vec<u64> = lines.iter().map(|v| figure(v, "samples_done")).collect();
    assert!(done.windows(2).all(|w| w[0] <= w[1]), "{done:?}");
    let last = lines.last().unwrap();
    assert_eq!(figure(last, "samples_done"), 64 * 48 * 1024, "{last}");
    assert_eq!(figure(last, "samples_total"), 64 * 48 * 1024, "{last}");
    assert_eq!(
        figure(last, "units_done"),
        figure(last, "units_total"),
        "{last}"
    );
    assert!(last["samples_per_second"].as_f64().unwrap() > 0.0, "{last}");
}
