#!/usr/bin/env bash
# A long fuzz campaign: each target runs until it has executed RUNS inputs (default 10 million),
# one worker, growing its corpus in place; then the corpus is minimised (`cargo fuzz cmin`) so only
# inputs that add coverage stay. The libFuzzer final statistics of every run are appended to
# campaign/LOG.md with the date and commit, so the figures quoted elsewhere can be checked.
#   ./campaign.sh                 # every target, 10 M executions each
#   RUNS=1000000 ./campaign.sh obj ply
#   WORKERS=2 ./campaign.sh simplify    # two processes (-jobs), RUNS split between them
#   MAX_TIME=3600 ./campaign.sh simplify # stop after an hour even if RUNS is not reached
# `simplify` is built without compare tracing (`--no-trace-compares`, its own target dir): it
# costs about 3x the time per input there (400 corpus inputs, same load: 3.1-4.1 s with it,
# 1.0-1.1 s without), and that input is decoded through `arbitrary` into sizes and choices, not
# matched against magic values, which is what compare tracing is for. The format readers keep
# it: their inputs are keywords.
# Exits non-zero on the first crash; the reproducer is in fuzz/artifacts/<target>/.
set -euo pipefail
cd "$(dirname "$0")"
runs="${RUNS:-10000000}"
workers="${WORKERS:-1}"
limit=()
if [ -n "${MAX_TIME:-}" ]; then limit=(-max_total_time="$MAX_TIME"); fi
if [ "$#" -gt 0 ]; then targets=("$@"); else targets=(simplify pipeline obj ply stl gltf case result stream roundtrip tdpm); fi
base=(-O -a -s none)
flags_for() {
    if [ "$1" = simplify ]; then echo "${base[*]} --no-trace-compares --target-dir target/ntc"
    else echo "${base[*]}"; fi
}
mkdir -p campaign
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
if ! git diff --quiet HEAD -- ../src ../cli ../host-sim src fuzz_targets 2>/dev/null; then
    commit="$commit+changes"
fi
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t"
    before=$(find "corpus/$t" -type f | wc -l)
    log="campaign/$t.log"
    echo "== $t: $runs executions, corpus $before files"
    read -r -a flags <<<"$(flags_for "$t")"
    cargo +nightly fuzz build "${flags[@]}" "$t"
    start=$(date +%s)
    rc=0
    rm -f fuzz-*.log
    if [ "$workers" -gt 1 ]; then
        # -jobs: independent processes sharing the corpus directory, each logging to fuzz-N.log.
        per=$(( (runs + workers - 1) / workers ))
        cargo +nightly fuzz run "${flags[@]}" "$t" "corpus/$t" -- -jobs="$workers" \
            -workers="$workers" -runs="$per" "${limit[@]}" -timeout=20 -rss_limit_mb=2048 \
            -print_final_stats=1 >"$log" 2>&1 || rc=$?
        # The parent echoes each job's log into $log when the job exits; fuzz-N.log are only
        # checked here (appending them too would count every stat line twice).
        if grep -q -E "panicked|ERROR: libFuzzer" fuzz-*.log; then rc=1; fi
        rm -f fuzz-*.log
    else
        cargo +nightly fuzz run "${flags[@]}" "$t" "corpus/$t" -- \
            -runs="$runs" "${limit[@]}" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 >"$log" 2>&1 || rc=$?
    fi
    secs=$(( $(date +%s) - start ))
    if [ "$rc" -ne 0 ]; then
        grep -E -A12 "panicked|ERROR: libFuzzer" "$log" | head -40
        grep -E "Test unit written to" "$log" || true
        echo "FAILED: $t (exit $rc)"
        exit 1
    fi
    grown=$(find "corpus/$t" -type f | wc -l)
    cargo +nightly fuzz cmin "${flags[@]}" "$t" "corpus/$t" >"campaign/$t.cmin.log" 2>&1
    after=$(find "corpus/$t" -type f | wc -l)
    # Summed over the workers; the rate is the whole campaign's (executions / wall time).
    execs=$(sed -n 's/^stat::number_of_executed_units:[[:space:]]*//p' "$log" | awk '{s+=$1} END {print s}')
    rate=$(( execs / (secs > 0 ? secs : 1) ))
    cov=$(grep -E "^#[0-9]+[[:space:]]+(DONE|INITED)" "$log" | tail -1 |
        sed -E 's/.*cov: ([0-9]+).*ft: ([0-9]+).*/cov \1, ft \2/')
    line="| $(date -u +%F) | $commit | $t | $execs | $workers | $rate | ${secs} s | $cov | $before → $grown → $after | none |"
    echo "$line"
    if [ ! -f campaign/LOG.md ]; then
        {
            echo "# Fuzz campaigns (written by campaign.sh)"
            echo
            echo "| date | commit | target | executions | workers | exec/s | time | coverage at end (one worker) | corpus files (start → grown → minimised) | crashes |"
            echo "|---|---|---|---:|---:|---:|---:|---|---|---|"
        } >campaign/LOG.md
    fi
    # The row goes at the end of the table, above the footnotes.
    awk -v row="$line" 'NR == FNR { if ($0 ~ /^\| /) last = FNR; next }
        { print } FNR == last { print row }' campaign/LOG.md campaign/LOG.md >campaign/LOG.md.new
    mv campaign/LOG.md.new campaign/LOG.md
done
