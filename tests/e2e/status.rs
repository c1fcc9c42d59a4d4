//! The status page (`yat render --status-addr`): every endpoint over a real socket during a
//! distributed render with a worker killed midway, the token, the paths it must not serve,
//! and a real headless Chromium loading the page.

use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::http::{http, metric, parse_prometheus, Response};
use crate::util::*;

/// A `yat render` with its status page; killed when dropped.
struct Coordinator {
    child: Child,
    /// host:port of the status page.
    address: String,
}

impl Coordinator {
    /// Starts `command` (a `yat render` with `--status-addr 127.0.0.1:0`) and reads the
    /// address it prints first.
    fn start(mut command: Command) -> Self {
        let mut child = command
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("start yat render");
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let page = next_line_after(&mut stdout, "status page on http://");
        let address = page
            .strip_suffix('/')
            .unwrap_or_else(|| panic!("no / after the address: {page:?}"))
            .to_string();
        // The rest of stdout (the summary) is drained so the process never blocks on it.
        std::thread::spawn(move || std::io::copy(&mut stdout, &mut std::io::sink()));
        Self { child, address }
    }

    fn get(&self, path: &str, headers: &[(&str, &str)]) -> Response {
        http(&self.address, "GET", path, headers)
    }

    fn status(&self) -> serde_json::Value {
        let response = self.get("/api/status", &[]);
        assert_eq!(response.code, 200, "{}", response.text());
        serde_json::from_slice(&response.body).unwrap()
    }

    /// Polls `/api/status` until `done` holds, handing each snapshot to `each`.
    fn poll_until(
        &self,
        what: &str,
        mut each: impl FnMut(&serde_json::Value),
        done: impl Fn(&serde_json::Value) -> bool,
    ) -> serde_json::Value {
        let started = Instant::now();
        loop {
            let status = self.status();
            each(&status);
            if done(&status) {
                return status;
            }
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "waited 60 s for {what}: {status:#}"
            );
            std::thread::sleep(Duration::from_millis(40));
        }
    }

    /// Ctrl-C ends the lingering page; the render had succeeded.
    fn stop(mut self) {
        signal(self.child.id(), "INT");
        let exit = self.child.wait().unwrap();
        assert!(exit.success(), "{exit}");
    }
}

impl Drop for Coordinator {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn status_command(scene: &Path, out: &Path, settings: &[&str], extra: &[&str]) -> Command {
    let mut command = render_command_with(scene, out, settings, extra);
    command.args([
        "--status-addr",
        "127.0.0.1:0",
        "--status-linger",
        "120",
        "--preview-every",
        "0",
    ]);
    command
}

#[test]
fn the_status_page_follows_a_distributed_render_with_a_worker_killed() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let mut a = Worker::start(&["--throttle-ms", "100"]);
    let b = Worker::start(&["--throttle-ms", "100"]);
    let a_address = a.address.clone();
    let out = dir.path().join("status.png");
    let workers = format!("{},{}", a.address, b.address);
    let coordinator = Coordinator::start(status_command(
        &scene,
        &out,
        &SETTINGS,
        &["--workers", &workers, "--quiet"],
    ));

    let mut last = (0, 0);
    let mut monotone = |s: &serde_json::Value| {
        let now = (
            s["progress"]["samples_done"].as_u64().unwrap(),
            s["progress"]["units_done"].as_u64().unwrap(),
        );
        assert!(now.0 >= last.0 && now.1 >= last.1, "{last:?} -> {now:?}");
        last = now;
    };
    let early = coordinator.poll_until("both workers rendering", &mut monotone, |s| {
        s["progress"]["units_done"].as_u64().unwrap() >= 8
            && s["workers"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|w| w["state"] == "connected")
                .count()
                == 2
    });
    assert_eq!(early["state"], "rendering");
    assert_eq!(early["settings"]["executor"], "distributed");
    assert_eq!(early["settings"]["width"], 128);
    assert_eq!(early["scene"]["name"], "box.lxs");
    assert_eq!(early["progress"]["units_total"], 32);
    assert!(early["progress"]["eta_seconds"].as_f64().unwrap() > 0.0);
    assert!(early["progress"]["samples_per_second"].as_f64().unwrap() > 0.0);
    assert_eq!(early["progress"]["round"], serde_json::Value::Null);
    let a_row = worker_entry(&early, &a_address);
    assert_eq!(a_row["threads"], 1);
    assert!(a_row["bytes_sent"].as_u64().unwrap() >= scene_bytes(dir.path()));
    assert!(a_row["bytes_received"].as_u64().unwrap() > 0);
    assert!(early["events"]
        .as_array()
        .unwrap()
        .iter()
        .any(|e| e["kind"] == "worker_joined" && e["worker"] == a_address));

    a.kill();
    let gone = coordinator.poll_until("the killed worker gone", &mut monotone, |s| {
        worker_entry(s, &a_address)["state"] == "gone"
    });
    assert!(
        worker_entry(&gone, &a_address)["reason"].is_string(),
        "{gone:#}"
    );
    let done = coordinator.poll_until("the end", &mut monotone, |s| s["state"] != "rendering");
    assert_eq!(done["state"], "finished", "{done:#}");
    let progress = &done["progress"];
    assert_eq!(progress["units_done"], 32);
    assert_eq!(progress["ratio"], 1.0);
    assert_eq!(progress["eta_seconds"], serde_json::Value::Null);
    let killed = worker_entry(&done, &a_address);
    assert_eq!(killed["state"], "gone", "{done:#}");
    assert!(killed["failures"].as_u64().unwrap() >= 1, "{done:#}");
    let requeued = killed["units_requeued"].as_u64().unwrap();
    assert!(requeued >= 1, "{done:#}");
    assert!(progress["units_requeued"].as_u64().unwrap() >= requeued);
    assert_eq!(worker_entry(&done, &b.address)["state"], "done", "{done:#}");
    let merged: u64 = done["workers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["units"].as_u64().unwrap())
        .sum();
    assert_eq!(merged, 32, "each unit merged once: {done:#}");
    let kinds: Vec<_> = done["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["worker"] == a_address)
        .map(|e| e["kind"].as_str().unwrap())
        .collect();
    assert!(
        kinds.contains(&"worker_left") && kinds.contains(&"units_requeued"),
        "{done:#}"
    );
    let summary = &done["summary"];
    assert_eq!(summary["output"], out.display().to_string());
    assert_eq!(summary["error"], serde_json::Value::Null);
    assert_eq!(summary["samples"], progress["samples_total"]);

    // /metrics: well-formed, and the same figures.
    let response = coordinator.get("/metrics", &[]);
    assert_eq!(response.code, 200);
    assert!(response
        .header("content-type")
        .unwrap()
        .starts_with("text/plain; version=0.0.4"));
    let samples = parse_prometheus(&response.text());
    assert_eq!(
        metric(&samples, "yat_samples_total"),
        progress["samples_done"].as_f64().unwrap()
    );
    assert_eq!(metric(&samples, "yat_units_done_total"), 32.0);
    assert_eq!(metric(&samples, "yat_progress_ratio"), 1.0);
    assert_eq!(metric(&samples, "yat_up"), 0.0, "the render has ended");
    assert_eq!(
        metric(&samples, "yat_units_requeued_total"),
        progress["units_requeued"].as_f64().unwrap()
    );
    let host = killed["hostname"].as_str().unwrap();
    assert_eq!(
        metric(
            &samples,
            &format!("yat_worker_state{{worker=\"{a_address}\",host=\"{host}\",state=\"gone\"}}")
        ),
        1.0
    );
    assert_eq!(
        metric(
            &samples,
            &format!("yat_worker_failures_total{{worker=\"{a_address}\"}}")
        ),
        killed["failures"].as_f64().unwrap()
    );
    assert_eq!(
        metric(
            &samples,
            &format!("yat_worker_units_total{{worker=\"{}\"}}", b.address)
        ),
        worker_entry(&done, &b.address)["units"].as_f64().unwrap()
    );

    // /image.png: the final image, pixel for pixel the PNG written.
    let response = coordinator.get("/image.png", &[]);
    assert_eq!(response.code, 200);
    assert_eq!(response.header("content-type"), Some("image/png"));
    let served = image::load_from_memory(&response.body).unwrap().to_rgb8();
    assert_eq!(served.dimensions(), (128, 96));
    let written = image::open(&out).unwrap().to_rgb8();
    assert!(served == written, "the page shows the final image");

    // The page itself: generated, self-contained.
    let page = coordinator.get("/", &[]);
    assert_eq!(page.code, 200);
    assert!(page
        .header("content-type")
        .unwrap()
        .starts_with("text/html"));
    let html = page.text();
    assert!(
        html.contains("/api/status") && !html.contains("http://") && !html.contains("https://")
    );
    assert!(page
        .header("content-security-policy")
        .unwrap()
        .contains("default-src 'none'"));

    // Nothing else: no file by a path from the request, no other method.
    for path in [
        "/../../etc/passwd",
        "/Cargo.toml",
        "/coordinator/src/status/page.html",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/api/status/../../../etc/passwd",
        "/image.png/..",
    ] {
        let response = coordinator.get(path, &[]);
        assert_eq!(response.code, 404, "{path}: {}", response.head);
        assert!(!response.text().contains("root:"), "{path}");
    }
    for method in ["POST", "PUT", "DELETE"] {
        assert_eq!(
            http(&coordinator.address, method, "/api/status", &[]).code,
            405
        );
    }
    coordinator.stop();
}

#[test]
fn a_token_protects_the_status_page() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("token.png");
    let mut command = status_command(&scene, &out, &SETTINGS, &["--quiet", "--threads", "2"]);
    command.env("YAT_TOKEN", "s3cret token;=");
    let coordinator = Coordinator::start(command);

    for (headers, code) in [
        (vec![], 401),
        (vec![("Authorization", "Bearer wrong")], 401),
        (vec![("Cookie", "yat_status=00")], 401),
        (vec![("Authorization", "Bearer s3cret token;=")], 200),
    ] {
        let response = coordinator.get("/api/status", &headers);
        assert_eq!(response.code, code, "{headers:?}: {}", response.head);
        if code == 401 {
            assert!(response
                .header("www-authenticate")
                .unwrap()
                .starts_with("Bearer"));
            let text = response.text();
            assert!(
                text.contains("<form") && !text.contains("samples"),
                "{text}"
            );
        }
    }
    for path in [
        "/",
        "/metrics",
        "/image.png",
        "/Cargo.toml",
        "/?token=wrong",
    ] {
        assert_eq!(coordinator.get(path, &[]).code, 401, "{path}");
    }
    // The token in the URL once: a cookie, and the address without the token.
    let login = coordinator.get("/?token=s3cret%20token%3B%3D", &[]);
    assert_eq!(login.code, 303, "{}", login.head);
    assert_eq!(login.header("location"), Some("/"));
    let set_cookie = login.header("set-cookie").unwrap();
    assert!(set_cookie.contains("HttpOnly") && set_cookie.contains("SameSite=Strict"));
    assert!(
        !set_cookie.contains("s3cret"),
        "the cookie holds a digest, not the token"
    );
    let cookie = set_cookie.split(';').next().unwrap();
    let page = coordinator.get("/", &[("Cookie", cookie)]);
    assert_eq!(page.code, 200);
    assert!(page.text().contains("<script>"));

    let cookie = [("Cookie", cookie)];
    let started = Instant::now();
    let done = loop {
        let response = coordinator.get("/api/status", &cookie);
        assert_eq!(response.code, 200);
        let status: serde_json::Value = serde_json::from_slice(&response.body).unwrap();
        if status["state"] != "rendering" {
            break status;
        }
        assert!(started.elapsed() < Duration::from_secs(60), "{status:#}");
        std::thread::sleep(Duration::from_millis(50));
    };
    assert_eq!(done["state"], "finished");
    assert_eq!(done["settings"]["executor"], "in-process");
    assert_eq!(done["settings"]["threads"], 2);
    assert_eq!(done["progress"]["units_done"], 32);
    assert_eq!(done["workers"].as_array().unwrap().len(), 0);
    let image = coordinator.get("/image.png", &cookie);
    assert_eq!(image.code, 200);
    let served = image::load_from_memory(&image.body).unwrap().to_rgb8();
    assert!(served == image::open(&out).unwrap().to_rgb8());
    coordinator.stop();
}

/// Debian's Chromium, if installed (deploy/status/install-chromium.sh).
fn chromium() -> Option<PathBuf> {
    ["chromium", "chromium-browser"].iter().find_map(|name| {
        let output = Command::new("sh")
            .args(["-c", &format!("command -v {name}")])
            .output()
            .ok()?;
        let path = String::from_utf8(output.stdout).ok()?;
        (output.status.success() && !path.trim().is_empty()).then(|| PathBuf::from(path.trim()))
    })
}

/// Runs headless Chromium on `url` with `mode` (`--dump-dom`, `--screenshot=...`), pages given
/// `budget_ms` of virtual time (the page's polling runs in it); returns stdout.
fn run_chromium(chromium: &Path, profile: &Path, mode: &str, url: &str, budget_ms: u32) -> String {
    let output = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-dev-shm-usage",
            "--hide-scrollbars",
            "--window-size=1280,900",
            &format!("--user-data-dir={}", profile.display()),
            &format!("--virtual-time-budget={budget_ms}"),
            mode,
            url,
        ])
        .stdin(Stdio::null())
        .output()
        .expect("run chromium");
    assert!(
        output.status.success(),
        "chromium failed ({}): {}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

#[test]
fn headless_chromium_shows_the_image_and_the_workers() {
    let Some(chromium) = chromium() else {
        eprintln!(
            "skipped: no chromium on the PATH (deploy/status/install-chromium.sh installs \
             Debian's)"
        );
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    // Slow enough that the render is still going while the browser looks.
    let a = Worker::start(&["--throttle-ms", "250"]);
    let b = Worker::start(&["--throttle-ms", "250"]);
    let workers = format!("{},{}", a.address, b.address);
    let out = dir.path().join("browser.png");
    let coordinator = Coordinator::start(status_command(
        &scene,
        &out,
        &["--spp", "64", "--resolution", "128x96"],
        &["--workers", &workers, "--quiet"],
    ));
    coordinator.poll_until(
        "an image",
        |_| {},
        |s| {
            s["image"]["generation"].as_u64().unwrap() >= 1
                && s["progress"]["units_done"].as_u64().unwrap() >= 4
        },
    );
    let url = format!("http://{}/", coordinator.address);

    let dom = run_chromium(
        &chromium,
        &dir.path().join("profile"),
        "--dump-dom",
        &url,
        3000,
    );
    let rendering = coordinator.status()["state"] == "rendering";
    let table = dom
        .split("<tbody id=\"workers\">")
        .nth(1)
        .and_then(|t| t.split("</tbody>").next())
        .unwrap_or_else(|| panic!("no worker table in {dom}"));
    assert!(
        table.contains(&a.address) && table.contains(&b.address),
        "the worker table lists both workers: {table}"
    );
    assert!(
        dom.contains("src=\"/image.png?v="),
        "the image is loaded: {dom}"
    );
    assert!(dom.contains("box.lxs"), "{dom}");

    // The page fetches the image after the DOM is up; on a loaded machine that may take more
    // than the browser's virtual-time budget, so a screenshot without the render is taken
    // again with twice the budget (three tries), and the last one is judged.
    let shot = dir.path().join("status-page.png");
    let mut budget_ms = 3000;
    let (screenshot, colours) = loop {
        run_chromium(
            &chromium,
            &dir.path().join("profile"),
            &format!("--screenshot={}", shot.display()),
            &url,
            budget_ms,
        );
        let screenshot = image::open(&shot).unwrap().to_rgb8();
        let (w, h) = screenshot.dimensions();
        // The image area: the left half of the top, where the page puts the render.
        let colours: std::collections::HashSet<[u8; 3]> = (0..h / 2)
            .flat_map(|y| (0..w / 2).map(move |x| (x, y)))
            .map(|(x, y)| screenshot.get_pixel(x, y).0)
            .collect();
        if colours.len() > 1000 || budget_ms >= 12_000 {
            break (screenshot, colours);
        }
        budget_ms *= 2;
    };
    if let Ok(keep) = std::env::var("YAT_STATUS_SCREENSHOT") {
        std::fs::copy(&shot, keep).unwrap();
    }
    // Not blank: the page's pixels vary, and the image area holds many colours, as a
    // path-traced image does and the page's flat panels and text do not.
    let (w, h) = screenshot.dimensions();
    let luma: Vec<f64> = screenshot
        .pixels()
        .map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64)
        .collect();
    let mean = luma.iter().sum::<f64>() / luma.len() as f64;
    let variance = luma.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / luma.len() as f64;
    assert!(
        variance > 100.0,
        "the screenshot is nearly flat: variance {variance}"
    );
    assert!(
        colours.len() > 1000,
        "the image area holds {} colours: no render shown",
        colours.len()
    );
    eprintln!(
        "chromium: screenshot {w}x{h} (virtual-time budget {budget_ms} ms), luma variance \
         {variance:.0}, {} colours in the image area, render {} when the DOM was dumped",
        colours.len(),
        if rendering { "running" } else { "finished" }
    );
    coordinator.poll_until("the end", |_| {}, |s| s["state"] != "rendering");
    coordinator.stop();
}
