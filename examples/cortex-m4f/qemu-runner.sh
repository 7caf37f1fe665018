#!/usr/bin/env bash
# Cargo runner (.cargo/config.toml): runs the image Cargo hands over ($1) on QEMU's mps2-an386
# (Cortex-M4F) and decodes its defmt log with defmt-print, the defmt project's decoder, using
# the image's own string table. Exits with the firmware's semihosting exit code (0: success),
# 124 if it has not exited after QEMU_TIMEOUT seconds (default 60). Further arguments
# (`cargo run … -- ARGS`) go to QEMU, e.g. `-- -d guest_errors`.
set -euo pipefail
elf=$1
shift

if ! command -v qemu-system-arm >/dev/null; then
  echo "qemu-runner.sh: needs qemu-system-arm (Debian/Ubuntu: apt-get install qemu-system-arm; macOS: brew install qemu)" >&2
  exit 127
fi

# defmt-print, installed once per machine into Cargo's bin folder.
defmt_print=$(command -v defmt-print || echo "${CARGO_HOME:-$HOME/.cargo}/bin/defmt-print")
if [ ! -x "$defmt_print" ]; then
  echo "qemu-runner.sh: installing defmt-print, which decodes the firmware's defmt log (once per machine; a few minutes): cargo install defmt-print --locked" >&2
  # The host build must not inherit flags meant for the firmware.
  env -u CARGO_BUILD_TARGET -u RUSTFLAGS -u CARGO_ENCODED_RUSTFLAGS \
    cargo install defmt-print --locked
  defmt_print=$(command -v defmt-print || echo "${CARGO_HOME:-$HOME/.cargo}/bin/defmt-print")
fi

# QEMU's stdout carries the binary defmt frames (semihosting writes), so its UART goes nowhere;
# -icount makes the run deterministic.
qemu=(qemu-system-arm -machine mps2-an386 -nographic -monitor none -serial null -icount shift=0
  -semihosting-config enable=on,target=native -kernel "$elf" "$@")
if command -v timeout >/dev/null; then
  qemu=(timeout "${QEMU_TIMEOUT:-60}" "${qemu[@]}")
fi
set +e
"${qemu[@]}" | "$defmt_print" -e "$elf"
status=("${PIPESTATUS[@]}")
set -e
case ${status[0]} in
  124) echo "qemu-runner.sh: killed QEMU after ${QEMU_TIMEOUT:-60} s" >&2 ;;
  134) echo "qemu-runner.sh: QEMU aborted (a lockup: no vector table without -Tlink.x in" \
    ".cargo/config.toml, or a memory.x that is not the board's)" >&2 ;;
esac
if [ "${status[0]}" = 0 ] && [ "${status[1]}" != 0 ]; then
  exit "${status[1]}" # the firmware succeeded but its log could not be decoded
fi
exit "${status[0]}"
