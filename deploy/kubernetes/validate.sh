#!/usr/bin/env bash
# Validates the Kubernetes manifests of this folder offline against the Kubernetes OpenAPI
# schema, strictly (unknown fields are errors); exits non-zero on any error. The validator,
# the PyPI package kubernetes-validate (which ships the schemas), is installed on first use
# into a virtual environment under the repository's target/ folder.
#
#   deploy/kubernetes/validate.sh [FOLDER] [--kubernetes-version X.Y.Z ...]
#
# FOLDER defaults to this script's folder. Needs python3 with the venv module (Debian:
# python3-venv) and access to PyPI on first use.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
validator_version=1.37.0
venv="${YAT_VALIDATOR_VENV:-$repo/target/kubernetes-validate-$validator_version}"

if ! "$venv/bin/python" -c "import kubernetes_validate" 2>/dev/null; then
    echo "installing kubernetes-validate $validator_version into $venv" >&2
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
        "kubernetes-validate==$validator_version"
fi

exec "$venv/bin/python" "$here/validate.py" "$@"
