#!/usr/bin/env bash
# What the status page costs a render: the same in-process render of the Cornell box without
# --status-addr, and with it while a client polls /api/status and /image.png once a second
# (what the page itself does), alternated RUNS times each so drift on a shared machine hits
# both alike.
#
# Prints each run's samples/s (from --stats-json) and the median of each side and their ratio
# (target: within noise, >= 0.99).
#
# Usage: bench/status.sh [SCENE.lxs]   (env: SPP=64, RUNS=3, THREADS=2, YAT=path/to/yat)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
scene=${1:-$root/scenes/cornell/cornell-box.lxs}
spp=${SPP:-64}
runs=${RUNS:-3}
threads=${THREADS:-2}
yat=${YAT:-$root/target/release/yat}

if [[ ! -x $yat ]]; then
    (cd "$root" && cargo build --release -p yat)
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

python3 - "$yat" "$scene" "$spp" "$runs" "$threads" "$out" <<'PY'
import json, statistics, subprocess, sys, threading, time, urllib.request
yat, scene, spp, runs, threads, out = sys.argv[1:]

def render(name, status):
    stats = f"{out}/{name}.json"
    cmd = [yat, "render", scene, "--spp", spp, "--threads", threads, "--quiet",
           "--checkpoint-every", "0", "--preview-every", "0", "-o", f"{out}/{name}.png",
           "--stats-json", stats]
    if status:
        cmd += ["--status-addr", "127.0.0.1:0"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)
    polls = 0
    if status:
        address = proc.stdout.readline().strip().removeprefix("status page on ")
        done = threading.Event()
        def poll():
            nonlocal polls
            while not done.is_set():
                try:
                    for path in ("api/status", "image.png"):
                        urllib.request.urlopen(address + path, timeout=5).read()
                    polls += 1
                except OSError:
                    pass
                done.wait(1.0)
        poller = threading.Thread(target=poll)
        poller.start()
    proc.stdout.read()
    if proc.wait() != 0:
        sys.exit(f"yat failed: {cmd}")
    if status:
        done.set()
        poller.join()
    return json.load(open(stats))["samples_per_second"], polls

plain, served = [], []
for i in range(int(runs)):
    for name, side, status in (("plain", plain, False), ("status", served, True)):
        rate, polls = render(f"{name}{i}", status)
        side.append(rate)
        print(f"run {i} {name:6}: {rate / 1e6:.3f} M samples/s" +
              (f" ({polls} polls of the JSON and the image)" if status else ""))
a, b = statistics.median(plain), statistics.median(served)
print(f"median without --status-addr: {a / 1e6:.3f} M samples/s")
print(f"median with it, polled 1/s:   {b / 1e6:.3f} M samples/s")
print(f"ratio: {b / a:.4f}")
PY
