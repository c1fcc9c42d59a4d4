#!/bin/sh
# The benchmark's environment for its side by side with LuxCoreRender and Mitsuba 3, made or
# brought up to date (idempotent; bench/bench.py runs it before a comparison):
#   - bench/.venv: pyluxcore, mitsuba (scalar_rgb and llvm_ad_rgb variants), numpy, OpenEXR,
#     matplotlib (bench/scale.py's plot),
#     versions pinned to those measured in bench/RESULTS.md;
#   - Debian's libllvm19 for Mitsuba's llvm_ad_rgb (Dr.Jit JIT-compiles through libLLVM; the
#     system's LLVM 14 and 15 fail). bench/mitsuba3.py points DRJIT_LIBLLVM_PATH at it.
set -eu
cd "$(dirname "$0")/.."

have_llvm19() {
    for f in /usr/lib/*/libLLVM.so.19* /usr/lib/llvm-19/lib/libLLVM.so*; do
        [ -e "$f" ] && return 0
    done
    return 1
}
if ! have_llvm19; then
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get install -y libllvm19 || {
        $sudo apt-get update && $sudo apt-get install -y libllvm19
    }
fi

[ -x bench/.venv/bin/python ] || python3 -m venv bench/.venv
bench/.venv/bin/pip install --quiet --disable-pip-version-check \
    pyluxcore==2.11.2 mitsuba==3.9.1 drjit==1.5.0 "numpy>=1.26" "OpenEXR>=3.2" "matplotlib>=3.8"
