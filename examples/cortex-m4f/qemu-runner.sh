#!/usr/bin/env bash
# Cargo runner of the firmware examples: runs the image Cargo hands over ($1) on QEMU's
# mps2-an386 (Cortex-M4F) through `host-sim run-elf`, which decodes the defmt log with the
# image's own table and exits with the firmware's exit code.
set -euo pipefail
elf=$(realpath "$1")
shift
cd "$(dirname "$0")/../.."
# The host build must not inherit the firmware build's target or flags.
exec env -u CARGO_BUILD_TARGET -u RUSTFLAGS -u CARGO_ENCODED_RUSTFLAGS \
  cargo run -q -p host-sim --release -- run-elf "$elf" "$@"
