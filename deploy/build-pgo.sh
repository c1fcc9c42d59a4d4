#!/bin/sh
# Builds target/pgo/yat: the release binary optimised with a profile of its own renders
# (profile-guided optimisation). The compiler lays out and inlines the code by how often each
# branch ran in renders of the repository's scenes; the arithmetic is the same, so the images are
# the same bytes as the plain release build's (`cargo build --release`); the seed scenes render
# some 4-10% sooner (medians of alternating renders in three runs; bench/RESULTS.md, session 13).
#
#   deploy/build-pgo.sh                      # then: target/pgo/yat render scene.lxs ...
#   deploy/build-pgo.sh my/scene.lxs ...     # also trained on your own scenes
#
# Scenes given on the command line are rendered for the profile too (at 160x90, 16 spp), so a
# farm's binary can be trained on the scenes it renders.
# Needs the toolchain's llvm-profdata (`rustup component add llvm-tools`, done here when missing).
# Two release builds (an instrumented one and the final one) and a few seconds of renders.
set -eu
# The training scenes given, as absolute paths (the script works from the repository's root).
for scene do
    shift
    case $scene in
    /*) set -- "$@" "$scene" ;;
    *) set -- "$@" "$PWD/$scene" ;;
    esac
done
cd "$(dirname "$0")/.."
root=$PWD
host=$(rustc -vV | sed -n 's/^host: //p')
profdata="$(rustc --print sysroot)/lib/rustlib/$host/bin/llvm-profdata"
if [ ! -x "$profdata" ]; then
    rustup component add llvm-tools
fi

profile="$root/target/pgo/profile"
rm -rf "$profile"
mkdir -p "$profile"
# --target keeps the flags off build scripts and proc macros (they would profile themselves).
RUSTFLAGS="-Cprofile-generate=$profile" \
    cargo build --release --locked -p yat --target "$host" --target-dir target/pgo/instrumented

# Training renders: matte and mirror under an area light (a mirror block's lamp images too),
# thin-lens depth of field, 8-bit and HDR environment maps, the glossy, metal and glass
# materials, procedural textures, analytic shapes, a bump map; small, so the whole profile
# takes seconds.
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for scene in cornell/cornell-box.lxs cornell/cornell-mirror.lxs cornell/cornell-fisheye-60.lxs \
    dof/dof-0.1.lxs envmap/envmap-png.lxs envmap/envmap-hdr.lxs materials/materials.lxs \
    materials2/materials2.lxs textures/procedural.lxs shapes/shapes.lxs bump/bump.lxs; do
    "target/pgo/instrumented/$host/release/yat" render "scenes/$scene" --quiet \
        --resolution 320x180 --spp 16 --threads 2 -o "$out/image.png" \
        --checkpoint-every 0 --preview-every 0
done
for scene in "$@"; do
    "target/pgo/instrumented/$host/release/yat" render "$scene" --quiet \
        --resolution 160x90 --spp 16 --threads 2 -o "$out/image.png" \
        --checkpoint-every 0 --preview-every 0
done
"$profdata" merge -o "$profile/merged.profdata" "$profile"

RUSTFLAGS="-Cprofile-use=$profile/merged.profdata -Cllvm-args=-pgo-warn-missing-function=false" \
    cargo build --release --locked -p yat --target "$host" --target-dir target/pgo/optimised
install -m 0755 "target/pgo/optimised/$host/release/yat" target/pgo/yat
echo "target/pgo/yat"
