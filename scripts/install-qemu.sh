#!/usr/bin/env bash
# Installs QEMU's Arm and RISC-V system emulators (qemu-system-arm, qemu-system-riscv32) with
# apt-get, as root. Used by .ci/run and scripts/test.sh; does nothing when both are there.
#
# Some machine images ship a newer qemu-utils (qemu-img) than their distribution's QEMU, from a
# package source the image no longer lists; the plain install then fails on qemu-utils'
# "Breaks: qemu-system-common (< ...)". The fallback installs the distribution's own
# qemu-utils beside the emulators (a downgrade of qemu-img, which nothing here uses).
set -euo pipefail
if command -v qemu-system-arm >/dev/null && command -v qemu-system-riscv32 >/dev/null; then
  exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null; then
  echo "needs QEMU for the golden checks on the boards: sudo apt-get install qemu-system-arm qemu-system-misc" >&2
  exit 2
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
if ! apt-get install -y -qq qemu-system-arm qemu-system-misc; then
  codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
  [ -n "$codename" ] || { echo "install-qemu.sh: no VERSION_CODENAME in /etc/os-release" >&2; exit 1; }
  echo "install-qemu.sh: retrying with the distribution's qemu-utils ($codename)" >&2
  apt-get install -y -qq --allow-downgrades qemu-system-arm qemu-system-misc "qemu-utils/$codename"
fi
qemu-system-arm --version | head -1
qemu-system-riscv32 --version | head -1
