#!/usr/bin/env bash
# Checks that this folder works as a project template, as README.md tells users to start one:
# copies it out of the repository (away from the repository's .cargo/config.toml and
# memory.x), points its `tinydecimate` dependency at this checkout, and builds and runs the
# firmware under QEMU with the copy's own configuration (`cargo run` without `--target`).
# scripts/test.sh runs it; so can anyone, from anywhere. It checks the repository's copy and is
# no part of the template: a project started from this folder can delete it.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
if ! grep -q '^name = "tinydecimate"$' "$repo/Cargo.toml" 2>/dev/null; then
  echo "check-template.sh: checks examples/cortex-m4f inside the tinydecimate repository; not needed in a project started from it" >&2
  exit 2
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
app=$tmp/my-app
mkdir "$app"
tar -C "$here" --exclude=./target --exclude=./check-template.sh -cf - . | tar -C "$app" -xf -

# The one line a user changes: the dependency, here an absolute path to this checkout.
sed -i.orig "s|^tinydecimate = { path = \"[^\"]*\"|tinydecimate = { path = \"$repo\"|" "$app/Cargo.toml"
rm "$app/Cargo.toml.orig"
if ! grep -q "^tinydecimate = { path = \"$repo\"" "$app/Cargo.toml"; then
  echo "check-template.sh: no 'tinydecimate = { path = ... }' line to rewrite in Cargo.toml" >&2
  exit 1
fi
# Nothing else may reach back into the repository.
if grep -rn '\.\./' "$app" --exclude-dir=.git; then
  echo "check-template.sh: the template refers to files outside itself (above)" >&2
  exit 1
fi

# A target folder of its own inside the repository's: the dependencies are built once, not on
# every run.
export CARGO_TARGET_DIR=$repo/target/template-check
status=0
log=$(cd "$app" && cargo run -q --release --example simplify_in_flash) || status=$?
echo "$log"
if [ "$status" != 0 ]; then
  echo "check-template.sh: the copied example failed (exit status $status)" >&2
  exit 1
fi
grep -q "in flash at 0x" <<<"$log"
grep -q "target_reached: true" <<<"$log"
echo "check-template.sh: the example works when copied out of the repository"
