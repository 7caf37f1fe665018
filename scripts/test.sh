#!/usr/bin/env bash
# The whole test suite, as README.md and CI run it:
#   1. library and harness tests on the host (property tests, real meshes, bad input, ...);
#   2. golden outputs on the host, with both math backends (libm, micromath);
#   3. the same golden files under QEMU on five Cortex-M cores and two RISC-V cores (rv32imc
#      400 KB, rv32imac 32 KB), both backends: the same bytes on every core and on the host;
#   4. streaming clustering of a mesh larger than RAM (the Stanford bunny, 69 451 triangles,
#      read through semihosting on the 16 KB micro:bit) on the host and the seven cores, both
#      backends, against tests/golden/cluster.toml's golden files;
#   5. the firmware example (examples/cortex-m4f) under QEMU, as its README line runs it, in
#      the repository and copied out of it as a project template.
# The link-time proof that no panic path is left in the library (tests/no-panic/check.sh), the
# fuzz smoke run and Miri are not run here: CI runs them after this script (see .ci/run).
# It installs the rustup targets it needs and defmt-print (the example's defmt decoder); QEMU
# comes from `apt-get install qemu-system-arm qemu-system-misc` (qemu-system-riscv32), installed
# here when missing and running as root (scripts/install-qemu.sh).
set -euo pipefail
cd "$(dirname "$0")/.."

need_targets="thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf thumbv8m.main-none-eabihf
  riscv32imc-unknown-none-elf riscv32imac-unknown-none-elf"
installed=$(rustup target list --installed)
for t in $need_targets; do
  grep -qx "$t" <<<"$installed" || rustup target add "$t"
done
bash scripts/install-qemu.sh
command -v defmt-print >/dev/null || cargo install defmt-print --locked

echo "== host tests"
# The command line and host-sim enable the library's `fast` feature, so the fast mode's tests
# (tests/pipeline.rs, tests/error_limit.rs) run here too.
cargo test --workspace --release

echo "== golden outputs on the host (libm, micromath)"
cargo run -q -p host-sim --release -- golden --check --backend libm
cargo run -q -p host-sim --release -- golden --check --backend micromath

echo "== golden outputs under QEMU: Cortex-M0, M3, M4F, M7, M33, RISC-V rv32imc, rv32imac (libm, micromath)"
cargo run -q -p host-sim --release -- qemu --check --backend libm
cargo run -q -p host-sim --release -- qemu --check --backend micromath

echo "== clustering a mesh larger than RAM under QEMU: the bunny on the micro:bit and every core (libm, micromath)"
cargo run -q -p host-sim --release -- qemu --cluster --backend libm
cargo run -q -p host-sim --release -- qemu --cluster --backend micromath

echo "== the firmware example under QEMU: examples/cortex-m4f, cargo run --example simplify_in_flash"
example_log=$(cd examples/cortex-m4f && cargo run -q --release --example simplify_in_flash --target thumbv7em-none-eabihf)
echo "$example_log"
grep -q "in flash at 0x" <<<"$example_log"
grep -q "target_reached: true" <<<"$example_log"
# The report's refusals by rule name, as defmt prints them (not a bare array of counts).
grep -q "rejected: locked [0-9]*, feature [0-9]*" <<<"$example_log"

echo "== the firmware example as a project template: copied out of the repository, built and run under QEMU"
bash examples/cortex-m4f/check-template.sh
