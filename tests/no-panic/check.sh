#!/usr/bin/env bash
# Link-time no-panic proof for tinydecimate (see src/main.rs): every build below must link.
# A link error naming `rust_panic_reachable` means a panic path survived; the linker lists the
# function that refers to it (`>>> referenced by ...`). Exits non-zero on any failure.
#
# Variants: thumbv7em (reference board) with libm, with micromath, with defmt logging on
# (DEFMT_LOG=trace), opt-level "s" and 1 (the firmware's dev profile is "s"), and thumbv6m
# (Cortex-M0, soft float). Finally a self-test: a build with a deliberate panic must fail.
# Needs: rustup targets thumbv7em-none-eabihf and thumbv6m-none-eabi.
set -uo pipefail
cd "$(dirname "$0")"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
fail=0

build() { # name, env..., -- cargo args...
    local name=$1; shift
    local envs=()
    while [ "$1" != "--" ]; do envs+=("$1"); shift; done
    shift
    local log
    log=$(env "${envs[@]}" cargo build --release "$@" 2>&1)
    local rc=$?
    if [ $rc -eq 0 ]; then
        echo "ok      $name"
    else
        echo "FAILED  $name"
        echo "$log" | grep -E "error|undefined symbol|>>>" | head -40
        fail=1
    fi
    return $rc
}

build "thumbv7em libm"          -- --target thumbv7em-none-eabihf
build "thumbv7em micromath"     -- --target thumbv7em-none-eabihf --features micromath
build "thumbv7em defmt (trace)" DEFMT_LOG=trace -- --target thumbv7em-none-eabihf --features defmt
build "thumbv7em opt-level s"   CARGO_PROFILE_RELEASE_OPT_LEVEL=s -- --target thumbv7em-none-eabihf
build "thumbv7em opt-level 1"   CARGO_PROFILE_RELEASE_OPT_LEVEL=1 -- --target thumbv7em-none-eabihf
build "thumbv6m libm"           -- --target thumbv6m-none-eabi

# The method itself: one reachable panic of our own must break the link.
log=$(cargo build --release --target thumbv7em-none-eabihf --features selftest 2>&1)
if [ $? -ne 0 ] && grep -q "undefined symbol: rust_panic_reachable" <<<"$log"; then
    echo "ok      self-test (a deliberate panic fails to link)"
else
    echo "FAILED  self-test: a deliberate panic linked, so the check proves nothing"
    fail=1
fi
exit $fail
