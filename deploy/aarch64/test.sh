#!/bin/bash
# Tests that an aarch64 build of yat renders the bytes the x86-64 build renders, so that a farm
# may mix the two kinds of machine (Kubernetes or Slurm nodes of both) and still promise the
# same image as one machine gives:
#
#   1. every scene in scenes/ (and the seed project's compared scenes, when present) rendered
#      in-process by both builds, the aarch64 one run by qemu-user: the same EXR bytes; a few
#      of them with bidirectional path tracing as well;
#   2. a render over gRPC on an aarch64 worker, merged by the x86-64 coordinator: the same EXR
#      bytes as the x86-64 in-process render, path-traced and bidirectional.
#
# What used to differ: the C library's float functions (glibc's acosf, tanf, atanf, sinhf,
# expm1f, ... give other last bits on aarch64) and glam's f32 matrix inverses (SSE2 and NEON
# forms); see clippy.toml.
#
# Needs an x86-64 host, rustup (it adds the aarch64-unknown-linux-gnu target) and root to
# install Debian's gcc-aarch64-linux-gnu, libc6-dev-arm64-cross and qemu-user when missing:
# otherwise it says why and exits 77, the usual "skipped" code. Exits 0 when every check passed,
# 1 when one failed.
#
# Environment: YAT_BIN (the x86-64 yat binary, built from this tree; default: cargo build -p yat),
# YAT_SEED_SCENES (default ../shared/seed-project/scenes beside the repository).
set -euo pipefail

readonly SKIPPED=77
readonly TARGET=aarch64-unknown-linux-gnu
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
target_dir=${CARGO_TARGET_DIR:-$repo/target}
# shellcheck source=../stop-processes.sh
source "$here/../stop-processes.sh"

now_ms() { date +%s%3N; }
test_start=$(now_ms)
say() { printf '[%6.1fs] %s\n' "$(($(now_ms) - test_start))e-3" "$*" >&2; }

skip() {
    echo "skipped: $*"
    exit "$SKIPPED"
}

passed=0
tmp=
workers=()

fail() {
    say "FAIL: $*"
    local file
    for file in "$tmp"/*.log; do
        [[ -s $file ]] || continue
        echo "----- last lines of $file"
        tail -n 30 "$file"
    done
    echo "aarch64: $passed passed, 1 failed"
    exit 1
}

cleanup() {
    local status=$?
    trap - EXIT
    stop_processes 30 "${workers[@]}"
    [[ -n $tmp ]] && rm -rf "$tmp"
    exit "$status"
}
trap cleanup EXIT
trap 'fail "interrupted"' INT TERM

[[ $(uname -m) == x86_64 ]] || skip "needs an x86-64 host (it compares against an aarch64 build under qemu)"
command -v rustup >/dev/null || skip "needs rustup to add the $TARGET target"

# ---------------------------------------------------------------------------------- tools
missing=()
for tool in aarch64-linux-gnu-gcc qemu-aarch64; do
    command -v "$tool" >/dev/null || missing+=("$tool")
done
[[ -d /usr/aarch64-linux-gnu/lib ]] || missing+=("the aarch64 C library")
if ((${#missing[@]})); then
    ((EUID == 0)) || skip "needs root to install ${missing[*]} (gcc-aarch64-linux-gnu, libc6-dev-arm64-cross, qemu-user)"
    say "missing ${missing[*]}: installing gcc-aarch64-linux-gnu, libc6-dev-arm64-cross and qemu-user"
    export DEBIAN_FRONTEND=noninteractive
    apt_log=$(mktemp /tmp/yat-aarch64-test-apt.XXXXXX)
    if ! { timeout 600 apt-get update -q &&
        timeout 900 apt-get install -y -q --no-install-recommends \
            gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user; } >"$apt_log" 2>&1; then
        tail -n 30 "$apt_log"
        rm -f "$apt_log"
        fail "apt-get could not install the cross compiler and qemu-user"
    fi
    rm -f "$apt_log"
fi
if ! rustup target list --installed | grep -qx "$TARGET"; then
    say "adding the $TARGET target"
    timeout 600 rustup target add "$TARGET" >&2 || fail "rustup could not add $TARGET"
fi

# ---------------------------------------------------------------------------------- builds
cd "$repo"
x86=${YAT_BIN:-}
if [[ -z $x86 ]]; then
    say "building the x86-64 yat"
    cargo build --locked -p yat --bin yat >&2
    x86=$target_dir/debug/yat
fi
say "building the aarch64 yat"
# The renderer's crates keep the dev profile's opt-level 3 (Cargo.toml); the rest (gRPC, CLI)
# builds unoptimised and without debug info here: 2.6 instead of 3.7 minutes on 2 cores, and
# optimisation does not change float results.
CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc \
    CARGO_PROFILE_DEV_OPT_LEVEL=0 CARGO_PROFILE_DEV_DEBUG=0 \
    cargo build --locked --target "$TARGET" -p yat --bin yat >&2
arm_bin=$target_dir/$TARGET/debug/yat
arm=(env QEMU_LD_PREFIX=/usr/aarch64-linux-gnu qemu-aarch64 "$arm_bin")
# Every render is bounded: a hang fails the test instead of holding CI.
readonly RENDER_SECONDS=300
arm_version=$("${arm[@]}" --version) || fail "the aarch64 build does not run under qemu-aarch64"
x86_version=$("$x86" --version)
# The versions name the renderer build: both binaries come from the same sources.
[[ $arm_version == "$x86_version" ]] || fail "the builds differ: $x86_version (x86-64), $arm_version (aarch64)"

tmp=$(mktemp -d /tmp/yat-aarch64-test.XXXXXX)
render_flags=(-q --spp 4 --seed 1 --resolution 40x24 --threads 2 --exr --preview-every 0 --checkpoint-every 0)

# ---------------------------------------------------------------------------------- 1. scenes
scenes=()
for scene in scenes/*/*.lxs; do
    # The heavy scene's mesh is generated (cargo run --example make_scene_assets), not kept.
    if [[ $scene == scenes/heavy/* && ! -f scenes/heavy/heavy.ply ]]; then
        say "scenes/heavy: its mesh is not generated here, left out"
        continue
    fi
    scenes+=("$scene")
done
seed=${YAT_SEED_SCENES:-$repo/../shared/seed-project/scenes}
if [[ -d $seed ]]; then
    for scene in CornellBox/cornell-box.lxs DepthOfField/depth-of-field-high.lxs \
        MetalMario/metal-mario-bg1.lxs CaptainFalcon/captainfalcon.lxs; do
        [[ -f $seed/$scene ]] && scenes+=("$seed/$scene")
    done
else
    say "no seed scenes at $seed: the repository's scenes only"
fi
differ=()
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .lxs)
    timeout "$RENDER_SECONDS" "$x86" render "$scene" "${render_flags[@]}" -o "$tmp/$name-x86.png" \
        2>>"$tmp/x86.log" || fail "$scene: the x86-64 render failed"
    timeout "$RENDER_SECONDS" "${arm[@]}" render "$scene" "${render_flags[@]}" -o "$tmp/$name-arm.png" \
        2>>"$tmp/arm.log" ||
        fail "$scene: the aarch64 render failed"
    cmp -s "$tmp/$name-x86.exr" "$tmp/$name-arm.exr" || differ+=("$scene")
done
# Bidirectional path tracing too: its light subpaths' splats land anywhere on the film.
for scene in scenes/cornell/cornell-box.lxs scenes/cornell/cornell-fisheye-90.lxs scenes/dof/dof-0.1.lxs \
    scenes/envmap/envmap-hdr.lxs scenes/sunroom/sunroom.lxs; do
    [[ -f $scene ]] || continue
    name=$(basename "$scene" .lxs)-bidirectional
    timeout "$RENDER_SECONDS" "$x86" render "$scene" "${render_flags[@]}" --integrator bidirectional \
        -o "$tmp/$name-x86.png" 2>>"$tmp/x86.log" || fail "$scene: the x86-64 bidirectional render failed"
    timeout "$RENDER_SECONDS" "${arm[@]}" render "$scene" "${render_flags[@]}" --integrator bidirectional \
        -o "$tmp/$name-arm.png" 2>>"$tmp/arm.log" ||
        fail "$scene: the aarch64 bidirectional render failed"
    cmp -s "$tmp/$name-x86.exr" "$tmp/$name-arm.exr" || differ+=("$scene (bidirectional)")
    scenes+=("$scene (bidirectional)")
done
if ((${#differ[@]})); then
    fail "aarch64 renders other bytes than x86-64 for: ${differ[*]}"
fi
passed=$((passed + 1))
say "PASS: ${#scenes[@]} scenes, the same EXR bytes from the x86-64 and the aarch64 build"

# ---------------------------------------------------------------------------------- 2. a worker
# An aarch64 worker serving an x86-64 coordinator: its sample buffers, merged, give the bytes of
# the in-process render. (Beside an x86-64 worker it would mostly lose the end game's races,
# running under emulation, and have few of its own results merged.)
"${arm[@]}" worker --listen 127.0.0.1:0 --threads 2 >"$tmp/arm-worker.out" 2>"$tmp/arm-worker.log" &
workers+=($!)
arm_worker=
for _ in $(seq 600); do
    line=$(head -n 1 "$tmp/arm-worker.out")
    if [[ $line == "listening on "* ]]; then
        arm_worker=${line#listening on }
        break
    fi
    sleep 0.1
done
[[ -n $arm_worker ]] || fail "the aarch64 worker did not start listening"
scene=scenes/dof/dof-0.1.lxs
cluster_flags=(-q --spp 8 --seed 1 --resolution 96x54 --exr --preview-every 0 --checkpoint-every 0)
timeout "$RENDER_SECONDS" "$x86" render "$scene" "${cluster_flags[@]}" --threads 2 \
    -o "$tmp/alone.png" 2>>"$tmp/x86.log" || fail "the in-process render failed"
timeout "$RENDER_SECONDS" "$x86" render "$scene" "${cluster_flags[@]}" --workers "$arm_worker" \
    --workers-json "$tmp/workers.json" -o "$tmp/worker.png" 2>"$tmp/coordinator.log" ||
    fail "the render on the aarch64 worker failed"
python3 - "$tmp/workers.json" <<'EOF' || fail "the aarch64 worker's units were not all merged"
import json, sys
figures = json.load(open(sys.argv[1]))
merged = sum(w["units"] for w in figures["workers"])
print(f"units: {figures['units']}, merged from the aarch64 worker: {merged}", file=sys.stderr)
sys.exit(0 if merged == figures["units"] > 1 else 1)
EOF
cmp -s "$tmp/alone.exr" "$tmp/worker.exr" ||
    fail "the render on the aarch64 worker differs from the in-process render"
# A bidirectional render: its units' light splats travel with their results.
timeout "$RENDER_SECONDS" "$x86" render "$scene" "${cluster_flags[@]}" --integrator bidirectional \
    --threads 2 -o "$tmp/alone-bidirectional.png" 2>>"$tmp/x86.log" ||
    fail "the in-process bidirectional render failed"
timeout "$RENDER_SECONDS" "$x86" render "$scene" "${cluster_flags[@]}" --integrator bidirectional \
    --workers "$arm_worker" -o "$tmp/worker-bidirectional.png" 2>>"$tmp/coordinator.log" ||
    fail "the bidirectional render on the aarch64 worker failed"
cmp -s "$tmp/alone-bidirectional.exr" "$tmp/worker-bidirectional.exr" ||
    fail "the bidirectional render on the aarch64 worker differs from the in-process render"
passed=$((passed + 1))
say "PASS: path-traced and bidirectional renders on an aarch64 worker equal the x86-64 in-process renders byte for byte"

echo "aarch64: $passed passed, 0 failed"
