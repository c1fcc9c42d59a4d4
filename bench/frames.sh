#!/usr/bin/env bash
# Frame throughput: a sequence of N frames (the repository's Cornell box, its camera moved a
# little each frame, its geometry file shared) rendered by one `yat render` on
# `--local-workers 2`, against the same N frames as N separate `yat render` runs, each starting
# its own two local workers and sending them every file.
#
# Prints: seconds and frames per second of both, their ratio, and whether every frame's image
# is byte-identical between the two.
#
# Usage: bench/frames.sh   (env: FRAMES=10, SPP=16, RESOLUTION=320x320, YAT=path/to/yat)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
frames=${FRAMES:-10}
spp=${SPP:-16}
resolution=${RESOLUTION:-320x320}
yat=${YAT:-$root/target/release/yat}
[[ -x $yat ]] || (cd "$root" && cargo build --release --locked -p yat)

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$root"/scenes/cornell/cornell-*.lxo "$work/"
for ((n = 1; n <= frames; n++)); do
    name=$(printf 'frame.%04d' "$n")
    sed -e "s/\"string filename\" \[\"cornell-box\"\]/\"string filename\" [\"$name\"]/" \
        -e "s/^LookAt 0 /LookAt $(printf '%.2f' "$(bc -l <<<"$n * 0.01")") /" \
        "$root/scenes/cornell/cornell-box.lxs" >"$work/frame$n.lxs"
    grep -q "\"$name\"" "$work/frame$n.lxs" && grep -q "^LookAt 0\.[0-9][0-9] " "$work/frame$n.lxs" ||
        { echo "the Cornell box's Film or camera is not as this script expects" >&2; exit 1; }
done
list=()
for ((n = 1; n <= frames; n++)); do list+=("$work/frame$n.lxs"); done
settings=(--spp "$spp" --resolution "$resolution" --quiet --checkpoint-every 0 --preview-every 0)

now() { date +%s.%N; }
start=$(now)
"$yat" render "${list[@]}" -o "$work/sequence/" --local-workers 2 "${settings[@]}"
sequence=$(bc -l <<<"$(now) - $start")

mkdir -p "$work/separate"
start=$(now)
for ((n = 1; n <= frames; n++)); do
    (cd "$work/separate" && "$yat" render "$work/frame$n.lxs" --local-workers 2 "${settings[@]}")
done
separate=$(bc -l <<<"$(now) - $start")

same=yes
for ((n = 1; n <= frames; n++)); do
    name=$(printf 'frame.%04d.png' "$n")
    cmp -s "$work/sequence/$name" "$work/separate/$name" || same=no
done
printf 'frames: %d at %s, %d spp, 2 local workers (%s)\n' "$frames" "$resolution" "$spp" \
    "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
printf 'one sequence:    %6.2f s  %6.2f frames/s\n' "$sequence" "$(bc -l <<<"$frames / $sequence")"
printf 'separate runs:   %6.2f s  %6.2f frames/s\n' "$separate" "$(bc -l <<<"$frames / $separate")"
printf 'sequence / separate throughput: %.2fx; images byte-identical: %s\n' \
    "$(bc -l <<<"$separate / $sequence")" "$same"
