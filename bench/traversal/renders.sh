#!/bin/sh
# Render speed before/after a traversal change: the bench's three scenes (Cornell box 960x540
# 16 spp, depth-of-field-high 960x540 16 spp, Captain Falcon 1920x1080 4 spp; depth 10, 2
# threads, seed 0) rendered by two `yat` binaries, interleaved A/B for ROUNDS rounds, printing
# M samples/s per run and comparing the last round's EXRs (exr-diff: byte-identical, or mean
# ratio and MSE).
#
# usage: bench/traversal/renders.sh OLD_YAT NEW_YAT EXR_DIFF [ROUNDS] [OUT_DIR]
set -eu
old=$1 new=$2 diff=$3 rounds=${4:-2} out=${5:-/tmp/yat-traversal-renders}
scenes=${YAT_SEED_SCENES:-$(cd "$(dirname "$0")/../.." && pwd)/../shared/seed-project/scenes}
mkdir -p "$out"
for round in $(seq 1 "$rounds"); do
  for entry in CornellBox/cornell-box.lxs:16 DepthOfField/depth-of-field-high.lxs:16 \
               CaptainFalcon/captainfalcon.lxs:4; do
    scene=${entry%:*} spp=${entry#*:} name=$(basename "$scene" .lxs)
    for side in old new; do
      bin=$old; [ "$side" = new ] && bin=$new
      dir=$out/$name-$side
      mkdir -p "$dir"
      "$bin" render "$scenes/$scene" --quiet --spp "$spp" --maxdepth 10 --threads 2 --seed 0 \
        --stats-json "$dir/stats.json" -o "$dir/out.png" --exr --preview-every 0 \
        --checkpoint-every 0
      rate=$(sed -n 's/.*"samples_per_second": *\([0-9.e+]*\).*/\1/p' "$dir/stats.json")
      echo "round $round $name $side $(echo "$rate" | awk '{printf "%.3f", $1 / 1e6}') M samples/s"
    done
    [ "$round" = "$rounds" ] && echo "$name: $("$diff" "$out/$name-old/out.exr" "$out/$name-new/out.exr")"
  done
done
