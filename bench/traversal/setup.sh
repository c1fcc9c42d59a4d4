#!/bin/sh
# Builds Embree's side of the traversal benchmark: installs Debian's Embree 3 (libembree-dev,
# 3.13.5 on bookworm) when it is missing and compiles embree/trace.c into
# $CARGO_TARGET_DIR/embree-trace (default target/). Run from anywhere; needs root for apt.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
target=${CARGO_TARGET_DIR:-$here/../../target}
if [ ! -f /usr/include/embree3/rtcore.h ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y libembree-dev
fi
mkdir -p "$target"
cc -O2 -o "$target/embree-trace" "$here/embree/trace.c" -lembree3 -lm
echo "$target/embree-trace"
