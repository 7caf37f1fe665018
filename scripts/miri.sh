#!/usr/bin/env bash
# Miri on the tests that fit in a few minutes (about 2 min on one core after the first build;
# the first run also builds Miri's sysroot). Needs: rustup +nightly component add miri rust-src.
#
# * No features needed: the library no longer links libm (whose x86-64 `sqrtf` was inline
#   assembly that Miri cannot run); its math is `+ - *` and bit operations.
# * tests/errors.rs: only its small cases. The others each take 140 s to over 4 min under Miri
#   (icosphere(3), 8x8+ grids); run them with `MIRI_ALL=1` (an hour or more).
# * tests/properties.rs: out of reach (96 cases per property; its `ProptestConfig { cases: 96 }`
#   ignores PROPTEST_CASES).
# * `MIRI_BIG_ENDIAN=1`: the same on s390x-unknown-linux-gnu as well (big-endian).
set -euo pipefail
cd "$(dirname "$0")/.."
features=()
fast_errors=(
    too_many_vertices_or_triangles_is_a_capacity_error
    u16_links_cap_the_triangle_count
    index_out_of_range_names_the_triangle
    bad_configuration_is_refused
    degenerate_and_duplicate_triangles_are_dropped_and_counted
    empty_and_tiny_meshes
    all_zero_area_triangles_only_lose_whole_triangles
)
targets=("")
if [ -n "${MIRI_BIG_ENDIAN:-}" ]; then
    targets+=(s390x-unknown-linux-gnu)
fi
for target in "${targets[@]}"; do
    t=()
    [ -n "$target" ] && t=(--target "$target")
    echo "== miri ${target:-host}"
    if [ -n "${MIRI_ALL:-}" ]; then
        cargo +nightly miri test -p tinydecimate "${features[@]}" "${t[@]}" --test errors
    else
        cargo +nightly miri test -p tinydecimate "${features[@]}" "${t[@]}" --test errors -- "${fast_errors[@]}"
    fi
    cargo +nightly miri test -p tinydecimate "${features[@]}" "${t[@]}" --test fuzz_regressions
    cargo +nightly miri test -p tinydecimate "${features[@]}" "${t[@]}" --doc
done
