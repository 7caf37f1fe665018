#!/usr/bin/env bash
# CI smoke run of every fuzz target: ~30 s each (SECONDS_PER_TARGET to change), one worker,
# starting from the checked-in corpus. New inputs go to a temporary directory, so the corpus
# is not changed. Exits non-zero on the first crash; the reproducer is in fuzz/artifacts/<target>/.
# Needs: the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`).
set -euo pipefail
cd "$(dirname "$0")"
secs="${SECONDS_PER_TARGET:-30}"
targets=(simplify pipeline envelope obj ply stl gltf case result stream roundtrip tdpm)
# -O: optimised; -a: debug assertions (overflow checks) on; no sanitizer: the code is safe Rust.
flags=(-O -a -s none)
cargo +nightly fuzz build "${flags[@]}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t" "$tmp/$t"
    echo "== $t (${secs}s)"
    rc=0
    cargo +nightly fuzz run "${flags[@]}" "$t" "$tmp/$t" "corpus/$t" -- \
        -max_total_time="$secs" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
        >"$tmp/$t.log" 2>&1 || rc=$?
    grep -E "^stat::(number_of_executed_units|average_exec_per_sec)" "$tmp/$t.log" || true
    if [ "$rc" -ne 0 ]; then
        grep -E -A12 "panicked|ERROR: libFuzzer" "$tmp/$t.log" | head -40
        grep -E "Test unit written to" "$tmp/$t.log" || true
        echo "FAILED: $t (exit $rc)"
        exit 1
    fi
done
echo "all targets ok"
