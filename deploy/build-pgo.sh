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
# Each build is one binary (YAT_BUILD_V3=0: not the release build's nested x86-64-v3 one, which
# this script makes profile-optimised itself).
# Needs the toolchain's llvm-profdata (`rustup component add llvm-tools`, done here when missing).
# On an x86-64 machine whose CPU has AVX2, FMA and BMI2 it also builds
# target/pgo/yat-x86-64-v3, the same compiled for such CPUs, which target/pgo/yat hands its
# process over to on one (coordinator/src/isa.rs; some 12% fewer instructions, the same image
# bytes, checked here: a difference removes it and fails). Per build: two release builds
# (an instrumented one and the final one) and a few seconds of renders.
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

# One profile-optimised build for the target CPU `$1` (`x86-64` or `generic`: any;
# `x86-64-v3`: AVX2, FMA, BMI2 and the rest), installed as `$2`, also trained on the scenes
# `$3...`. Each is trained on its own instrumented build, whose code differs where the
# features are known at compile time.
build_for() {
    cpu=$1
    dest=$2
    shift 2
    profile="$root/target/pgo/profile-$cpu"
    rm -rf "$profile"
    mkdir -p "$profile"
    # --target keeps the flags off build scripts and proc macros (they would profile
    # themselves).
    YAT_BUILD_V3=0 RUSTFLAGS="-Ctarget-cpu=$cpu -Cprofile-generate=$profile" \
        cargo build --release --locked -p yat --target "$host" \
        --target-dir "target/pgo/instrumented-$cpu"
    trainer="target/pgo/instrumented-$cpu/$host/release/yat"
    # Training renders: matte and mirror under an area light (a mirror block's lamp images
    # too), thin-lens depth of field, 8-bit and HDR environment maps, the glossy, metal and
    # glass materials, procedural textures, analytic shapes, a bump map; small, so the whole
    # profile takes seconds. YAT_ISA=baseline: the instrumented baseline build must not hand
    # over to an optimised x86-64-v3 one installed earlier.
    for scene in cornell/cornell-box.lxs cornell/cornell-mirror.lxs \
        cornell/cornell-fisheye-60.lxs dof/dof-0.1.lxs envmap/envmap-png.lxs \
        envmap/envmap-hdr.lxs materials/materials.lxs materials2/materials2.lxs \
        textures/procedural.lxs shapes/shapes.lxs bump/bump.lxs; do
        YAT_ISA=baseline "$trainer" render "scenes/$scene" --quiet \
            --resolution 320x180 --spp 16 --threads 2 -o "$out/image.png" \
            --checkpoint-every 0 --preview-every 0
    done
    for scene in "$@"; do
        YAT_ISA=baseline "$trainer" render "$scene" --quiet \
            --resolution 160x90 --spp 16 --threads 2 -o "$out/image.png" \
            --checkpoint-every 0 --preview-every 0
    done
    "$profdata" merge -o "$profile/merged.profdata" "$profile"
    YAT_BUILD_V3=0 RUSTFLAGS="-Ctarget-cpu=$cpu -Cprofile-use=$profile/merged.profdata -Cllvm-args=-pgo-warn-missing-function=false" \
        cargo build --release --locked -p yat --target "$host" \
        --target-dir "target/pgo/optimised-$cpu"
    install -m 0755 "target/pgo/optimised-$cpu/$host/release/yat" "$dest"
    echo "$dest"
}

# Whether this machine's CPU has x86-64-v3's features (the v3 build is trained by running it).
cpu_has_v3() {
    flags=$(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null) || return 1
    for feature in avx avx2 bmi1 bmi2 f16c fma abm movbe; do
        case " $flags " in
        *" $feature "*) ;;
        *) return 1 ;;
        esac
    done
}

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
case $host in
x86_64-*)
    # The baseline build runs anywhere and hands over to the x86-64-v3 one beside it where the
    # CPU has it (coordinator/src/isa.rs); a stale sibling must not outlive a rebuild.
    rm -f target/pgo/yat-x86-64-v3
    build_for x86-64 target/pgo/yat "$@"
    if ! cpu_has_v3; then
        echo "this CPU lacks x86-64-v3's features: built target/pgo/yat only" >&2
        exit 0
    fi
    build_for x86-64-v3 target/pgo/yat-x86-64-v3 "$@"
    # The two builds must render the same bytes (workers of both kinds share renders).
    for scene in dof/dof-0.1.lxs materials/materials.lxs envmap/envmap-hdr.lxs; do
        for build in yat yat-x86-64-v3; do
            YAT_ISA=baseline "target/pgo/$build" render "scenes/$scene" --quiet \
                --resolution 96x54 --spp 8 --threads 2 --exr -o "$out/$build.png" \
                --checkpoint-every 0 --preview-every 0
        done
        cmp "$out/yat.exr" "$out/yat-x86-64-v3.exr" || {
            echo "the x86-64 and x86-64-v3 builds render $scene differently" >&2
            rm -f target/pgo/yat-x86-64-v3
            exit 1
        }
    done
    ;;
*)
    build_for generic target/pgo/yat "$@"
    ;;
esac
