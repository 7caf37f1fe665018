#!/usr/bin/env bash
# Shows that the test suite notices the loss of each legality rule (src/policy/legality/mod.rs).
#
# Builds the library with TINYDECIMATE_RULE_OFF set to each rule of its table in turn (cargo
# rebuilds the crate when the variable changes) and runs a fast subset of the tests, which must
# then FAIL; and once with every rule on, which must pass. Prints `rule | failing tests | verdict` and
# exits non-zero if the all-rules run fails or any rule's removal goes unnoticed.
#
#   scripts/rules-off.sh                 # every rule
#   scripts/rules-off.sh link fold       # some rules
#   RULES_OFF_TESTS="--test rules" scripts/rules-off.sh   # another subset
#   RULES_OFF_ENGINE=pipeline scripts/rules-off.sh        # the pipeline's rules (fast and lean
#                                                          # modes, float and integer)
set -uo pipefail
cd "$(dirname "$0")/.."

engine=${RULES_OFF_ENGINE:-exact}
if [ "$engine" = pipeline ]; then
  # The pipeline's rules: its `RULE_*` names in src/pipeline/perform.rs, switched off by
  # PIPELINE_RULE_OFF; its tests run both arithmetics (tests/pipeline.rs, tests/integer.rs).
  switch=PIPELINE_RULE_OFF
  read -r -a all_rules <<<"$(sed -n 's/^const RULE_[A-Z]*: &str = "\([a-z]*\)";$/\1/p' src/pipeline/perform.rs | paste -sd' ' -)"
  default_tests="--features fast,seams --test pipeline --test integer"
else
  # The rules' names, read from their one table (`RULES` in src/policy/legality/mod.rs: a
  # row's `name: "..."` line); a name the table does not hold is a build error, not a silent
  # pass.
  switch=TINYDECIMATE_RULE_OFF
  read -r -a all_rules <<<"$(sed -n 's/^ *name: "\([a-z_]*\)",$/\1/p' src/policy/legality/mod.rs | paste -sd' ' -)"
  default_tests="--features seams --test rules --test errors --test fuzz_regressions --test properties --test bound --test stored --test seams --test decimate"
fi
if [ ${#all_rules[@]} -eq 0 ]; then
  echo "no rule names found for the $engine engine" >&2
  exit 2
fi
rules=("$@")
[ ${#rules[@]} -eq 0 ] && rules=("${all_rules[@]}")
# The subset: the rule tests (tests/rules.rs, one or more per rule, all asserting properties of
# real output through the shared checker), bad input, the fuzz regressions and the property
# tests; the error bound's independent check (tests/bound.rs, for the `bound` veto); and the
# stored quadrics' validity over both placements, with and without the feature rule
# (tests/stored.rs: the engine's one-price re-keying runs there); welded seams (tests/seams.rs,
# for the `seam` rule, with the crate feature `seams`).
read -r -a tests <<<"${RULES_OFF_TESTS:-$default_tests}"
per_run_timeout=${RULES_OFF_TIMEOUT:-900}

log_dir=$(mktemp -d)
start=$SECONDS

# Runs the subset with $1 switched off ("" = none). Sets `failing` (test names, comma
# separated) and `status` (pass, fail, build-error, timeout).
run() {
  local rule=$1 log="$log_dir/${1:-none}.log" rc
  timeout "$per_run_timeout" env "$switch=$rule" \
    cargo test --release -p tinydecimate "${tests[@]}" --no-fail-fast >"$log" 2>&1
  rc=$?
  failing=$(grep -E '^test .* \.\.\. FAILED$' "$log" | sed -E 's/^test (.*) \.\.\. FAILED$/\1/' |
    sort -u | paste -sd, - | sed 's/,/, /g')
  if [ $rc -eq 124 ]; then
    status=timeout
  elif [ $rc -eq 0 ]; then
    status=pass
  elif [ -n "$failing" ]; then
    status=fail
  elif grep -q '^error\(\[E[0-9]*\]\)\?: ' "$log" && ! grep -q '^test result' "$log"; then
    status=build-error
  else
    status=fail
    failing="(test binary failed: see $log)"
  fi
}

rows=()
bad=0

t0=$SECONDS
run ""
if [ "$status" = pass ]; then
  rows+=("(none) | - | pass, as it must ($((SECONDS - t0)) s)")
else
  rows+=("(none) | ${failing:--} | FAILS WITH EVERY RULE ON: $status, see $log_dir/none.log")
  bad=1
fi

for rule in "${rules[@]}"; do
  t0=$SECONDS
  echo "-- $rule off" >&2
  run "$rule"
  case $status in
    fail) verdict="caught ($((SECONDS - t0)) s)" ;;
    timeout) verdict="caught: timed out after ${per_run_timeout} s" ;;
    pass)
      verdict="NOT CAUGHT ($((SECONDS - t0)) s)"
      bad=1
      ;;
    *)
      verdict="ERROR: $status, see $log_dir/$rule.log"
      bad=1
      ;;
  esac
  rows+=("$rule | ${failing:--} | $verdict")
done

echo
echo "rule | failing tests | verdict"
echo "---|---|---"
printf '%s\n' "${rows[@]}"
echo
echo "subset: cargo test --release -p tinydecimate ${tests[*]}; total $((SECONDS - start)) s; logs in $log_dir"
exit $bad
