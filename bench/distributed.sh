#!/usr/bin/env bash
# Distributed rendering overhead on one machine: `--local-workers 2` (one thread each) against
# an in-process render with `--threads 2`, same scene, same spp.
#
# Prints: wall-clock and samples/s of both and their ratio (target >= 95%), the coordinator's
# own CPU time as a share of all CPU the render used (target < 2%), result bytes per pixel of
# every unit (target ~16), and whether the two EXR files are byte-identical.
#
# Usage: bench/distributed.sh [SCENE.lxs]   (env: SPP=16, YAT=path/to/yat, YAT_SEED_SCENES)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
seeds=${YAT_SEED_SCENES:-$root/../shared/seed-project/scenes}
scene=${1:-$seeds/DepthOfField/depth-of-field-high.lxs}
spp=${SPP:-16}
yat=${YAT:-$root/target/release/yat}

if [[ ! -f $scene ]]; then
    echo "scene not found: $scene (pass one, or set YAT_SEED_SCENES)" >&2
    exit 1
fi
if [[ ! -x $yat ]]; then
    (cd "$root" && cargo build --release -p yat)
fi
for tool in /usr/bin/time python3; do
    command -v "$tool" >/dev/null || { echo "needs $tool" >&2; exit 1; }
done

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# Runs yat, recording elapsed, user and system seconds (children included: the local workers
# are reaped by the coordinator, so their CPU counts here).
timed() {
    local name=$1
    shift
    /usr/bin/time -f "%e %U %S" -o "$out/$name.time" "$yat" render "$scene" --spp "$spp" \
        --quiet --exr -o "$out/$name.png" --stats-json "$out/$name.json" "$@"
}

echo "scene $scene, $spp spp, $(nproc) cores"
timed in-process --threads 2
timed distributed --local-workers 2 --workers-json "$out/workers.json"

python3 - "$out" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
def run(name):
    elapsed, user, system = map(float, (out / f"{name}.time").read_text().split())
    stats = json.loads((out / f"{name}.json").read_text())
    return elapsed, user + system, stats
e_in, cpu_in, s_in = run("in-process")
e_d, cpu_d, s_d = run("distributed")
workers = json.loads((out / "workers.json").read_text())
sps_in = s_in["samples"] / e_in
sps_d = s_d["samples"] / e_d
print(f"in-process : {e_in:7.2f} s wall, {cpu_in:7.2f} s CPU, {sps_in / 1e6:6.3f} M samples/s (whole command)")
print(f"distributed: {e_d:7.2f} s wall, {cpu_d:7.2f} s CPU, {sps_d / 1e6:6.3f} M samples/s (whole command)")
print(f"samples/s ratio distributed / in-process: {100 * sps_d / sps_in:.1f} % (target >= 95 %)")
print(f"  render phase only: in-process {s_in['samples_per_second'] / 1e6:.3f} M/s (after build), "
      f"distributed {workers['samples_per_second'] / 1e6:.3f} M/s (incl. worker start, upload, builds)")
share = workers["coordinator_cpu_seconds"] / cpu_d
print(f"coordinator CPU: {workers['coordinator_cpu_seconds']:.3f} s of {cpu_d:.2f} s = {100 * share:.2f} % (target < 2 %)")
print(f"result bytes per unit pixel: {workers['result_bytes_per_unit_pixel']:.2f} (target ~16)")
for w in workers["workers"]:
    print(f"  worker {w['address']}: {w['units']} units, {w['failures']} failures, "
          f"{w['blob_bytes_sent']} scene bytes sent, {w['bytes_received']} bytes received")
same = (out / "in-process.exr").read_bytes() == (out / "distributed.exr").read_bytes()
print(f"EXR byte-identical: {same}")
PY
