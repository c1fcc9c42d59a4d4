#!/usr/bin/env bash
# Whether two yat builds render the same bytes: every scene in scenes/ (and the seed scenes
# named below when they are present) rendered by both at a small size, the PNG and the linear
# EXR compared with cmp; then the samples/s of both on the compared seed scenes, interleaved.
#
# Usage: bench/same-bytes.sh OLD_YAT NEW_YAT
#   env: RESOLUTION=160x90 SPP=4 (the bytes), SPEED_RESOLUTION=480x270 SPEED_SPP=16 ROUNDS=3
#        THREADS=2 (the speed), YAT_SEED_SCENES, TIMEOUT=120 (seconds a render may take)
# Prints one line a scene ("same", "DIFFERENT", or why it was skipped), then the speed table.
set -euo pipefail

old=${1:?usage: bench/same-bytes.sh OLD_YAT NEW_YAT}
new=${2:?usage: bench/same-bytes.sh OLD_YAT NEW_YAT}
root=$(cd "$(dirname "$0")/.." && pwd)
seeds=${YAT_SEED_SCENES:-$root/../shared/seed-project/scenes}
resolution=${RESOLUTION:-160x90}
spp=${SPP:-4}
threads=${THREADS:-2}
limit=${TIMEOUT:-120}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

scenes=()
while IFS= read -r scene; do scenes+=("$scene"); done < <(find "$root/scenes" -name '*.lxs' | sort)
compared=(CornellBox/cornell-box.lxs DepthOfField/depth-of-field-high.lxs
    MetalMario/metal-mario-bg1.lxs CaptainFalcon/captainfalcon.lxs)
for seed in "${compared[@]}"; do
    [[ -f $seeds/$seed ]] && scenes+=("$seeds/$seed")
done

render() { # BINARY SCENE OUT [flags...]
    local yat=$1 scene=$2 out=$3
    shift 3
    (cd "$work" && timeout "$limit" "$yat" render "$scene" -o "$out" --exr --quiet \
        --checkpoint-every 0 --preview-every 0 --threads "$threads" "$@" >/dev/null 2>&1)
}

same=0 different=0 skipped=0
for scene in "${scenes[@]}"; do
    name=${scene#"$root/"}
    name=${name#"$seeds/"}
    settings=(--resolution "$resolution" --spp "$spp")
    if ! render "$old" "$scene" "$work/old.png" "${settings[@]}"; then
        echo "skipped    $name (the old build cannot render it within ${limit} s)"
        skipped=$((skipped + 1))
        continue
    fi
    if ! render "$new" "$scene" "$work/new.png" "${settings[@]}"; then
        echo "DIFFERENT  $name (the new build failed where the old rendered)"
        different=$((different + 1))
        continue
    fi
    if cmp -s "$work/old.png" "$work/new.png" && cmp -s "$work/old.exr" "$work/new.exr"; then
        echo "same       $name"
        same=$((same + 1))
    else
        echo "DIFFERENT  $name"
        different=$((different + 1))
    fi
done
echo "bytes: $same same, $different different, $skipped skipped ($resolution, $spp spp)"

speed_settings=(--resolution "${SPEED_RESOLUTION:-480x270}" --spp "${SPEED_SPP:-16}")
echo "samples/s, median of ${ROUNDS:-3} interleaved rounds, ${speed_settings[*]}, $threads threads:"
for seed in "${compared[@]}"; do
    [[ -f $seeds/$seed ]] || continue
    rates_old=() rates_new=()
    for ((round = 0; round < ${ROUNDS:-3}; round++)); do
        for build in old new; do
            render "${!build}" "$seeds/$seed" "$work/speed.png" "${speed_settings[@]}" \
                --stats-json "$work/$build.json" || continue
            rate=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["samples_per_second"])' "$work/$build.json")
            if [[ $build == old ]]; then rates_old+=("$rate"); else rates_new+=("$rate"); fi
        done
    done
    median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR ? a[int((NR + 1) / 2)] : 0)}'; }
    printf '  %-40s old %.3f M  new %.3f M\n' "$seed" \
        "$(bc -l <<<"$(median "${rates_old[@]}") / 1000000")" \
        "$(bc -l <<<"$(median "${rates_new[@]}") / 1000000")"
done
