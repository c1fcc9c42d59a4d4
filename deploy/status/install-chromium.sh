#!/usr/bin/env bash
# Installs Debian's Chromium for the status page's headless browser test
# (tests/e2e/status.rs), unless a chromium is already on the PATH. Needs root (apt-get);
# without root or apt-get it says so and exits 0: the test then skips, saying why.
set -euo pipefail
if command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1; then
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1 || [ "$(id -u)" -ne 0 ]; then
    echo "install-chromium: not root or no apt-get: the headless browser test will skip" >&2
    exit 0
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends chromium fonts-dejavu-core >/dev/null
command -v chromium
