#!/usr/bin/env bash
# The whole test suite, as README.md and CI run it.
set -euo pipefail
cd "$(dirname "$0")/.."

# Library and harness tests on the host (release: the real-mesh tests simplify 86k triangles).
cargo test --workspace --release
