#!/usr/bin/env bash
# What the status page costs a render: the same in-process render of the Cornell box without
# --status-addr, and with it while a client polls /api/status and /image.png once a second
# (what the page itself does), RUNS times each in the order ABBA..., so drift on a shared
# machine hits both alike.
#
# Prints each run's samples/s (from --stats-json) and CPU seconds (user + system, from
# getrusage of the child), the median of each side and their ratios (target: within noise,
# >= 0.99). On a shared, loaded machine the wall-clock rate is noisy; the CPU seconds are what
# the page adds to the render's work whatever the load.
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
import json, resource, statistics, subprocess, sys, threading, urllib.request
yat, scene, spp, runs, threads, out = sys.argv[1:]

def render(name, status):
    stats = f"{out}/{name}.json"
    cmd = [yat, "render", scene, "--spp", spp, "--threads", threads, "--quiet",
           "--checkpoint-every", "0", "--preview-every", "0", "-o", f"{out}/{name}.png",
           "--stats-json", stats]
    if status:
        cmd += ["--status-addr", "127.0.0.1:0"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
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
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if status:
        done.set()
        poller.join()
    return json.load(open(stats))["samples_per_second"], cpu, polls

sides = {"plain": ([], []), "status": ([], [])}
for i in range(int(runs)):
    # Alternated (ABBA...) so a machine slowing down or speeding up hits both sides alike.
    order = (("plain", False), ("status", True))
    for name, status in order if i % 2 == 0 else order[::-1]:
        rate, cpu, polls = render(f"{name}{i}", status)
        sides[name][0].append(rate)
        sides[name][1].append(cpu)
        print(f"run {i} {name:6}: {rate / 1e6:.3f} M samples/s, {cpu:.2f} CPU s" +
              (f" ({polls} polls of the JSON and the image)" if status else ""))
(ra, ca), (rb, cb) = [tuple(map(statistics.median, sides[n])) for n in ("plain", "status")]
print(f"median without --status-addr: {ra / 1e6:.3f} M samples/s, {ca:.2f} CPU s")
print(f"median with it, polled 1/s:   {rb / 1e6:.3f} M samples/s, {cb:.2f} CPU s")
print(f"samples/s ratio {rb / ra:.4f}, CPU seconds ratio {cb / ca:.4f}")
PY
