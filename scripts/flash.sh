#!/usr/bin/env bash
# Flash of one instantiation of tinydecimate, measured as a user would: the minimal firmware in
# tests/flash (positions a static in flash, triangles a static RAM buffer, a static workspace)
# is built without and with the call `Workspace<u16, 512, 1024>::simplify(.., &Config::new())`
# (and with the fast mode's `FastWorkspace<u16, 512, 1024>::simplify` instead, the lean
# mode's `LeanWorkspace<u16, 512, 1024>::simplify`, and both in the integer arithmetic,
# `FastWorkspace<u16, 512, 1024, Integer>` and `LeanWorkspace<.., Integer>` on grid positions,
# whose image without the call holds those positions too),
# opt-level "s", fat LTO, one codegen unit, panic = abort (its Cargo.toml), and the difference
# of .text + .rodata is the library. `host-sim qemu --measure` reports the same figure per board.
#
# Usage: scripts/flash.sh [--all] [--out FILE] [--micromath] [--opt-level L] [--symbols N] [--target T]...
#   --all         also Config::paper(), a second triangle index type (u32 triangles on the same
#                 Workspace<u16, ..>), a second link type (Workspace<u32, ..> over u32) and the
#                 library features batched, seams and parts each compiled into the default call
#   --out FILE    also write the table to FILE (bench/FLASH.md is `--all --out bench/FLASH.md`)
#   --micromath   the library's micromath backend instead of libm
#   --opt-level L another opt-level than the "s" of tests/flash's Cargo.toml (e.g. z: smaller,
#                 and slower: docs/devices.md says why "s" is the default)
#   --symbols N   how many of the largest symbols the call adds to list per target (default 15)
#   --target T    a Rust target (repeatable; default thumbv7em-none-eabihf thumbv6m-none-eabi
#                 riscv32imc-unknown-none-elf)
# Needs the rustup targets and the llvm-tools component (rustup component add llvm-tools).
# Images are kept in $CARGO_TARGET_DIR/images (default tests/flash/target).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

all=0
out=
extra=()
opt=s
nsym=15
targets=()
while [ $# -gt 0 ]; do
    case $1 in
        --all | --paper) all=1 ;;
        --micromath) extra=(micromath) ;;
        --opt-level) opt=$2; shift ;;
        --out) out=$2; shift ;;
        --symbols) nsym=$2; shift ;;
        --target) targets+=("$2"); shift ;;
        -h | --help) sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "unknown argument: $1 (see --help)" >&2; exit 2 ;;
    esac
    shift
done
[ ${#targets[@]} -gt 0 ] || targets=(thumbv7em-none-eabihf thumbv6m-none-eabi riscv32imc-unknown-none-elf)

bin="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin"
for tool in llvm-size llvm-nm; do
    if [ ! -x "$bin/$tool" ]; then
        echo "$bin/$tool missing: rustup component add llvm-tools" >&2
        exit 2
    fi
done
installed=$(rustup target list --installed 2>/dev/null || true)
for t in "${targets[@]}"; do
    grep -qx "$t" <<<"$installed" || rustup target add "$t"
done

export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/tests/flash/target}"
# Cargo reads a profile setting from the environment over the manifest's.
export CARGO_PROFILE_RELEASE_OPT_LEVEL=$opt
images="$CARGO_TARGET_DIR/images"
mkdir -p "$images"
# Variants: name, cargo features (comma-separated, may be empty), what the row shows. The first
# two are the images without the call (the second with the integer calls' grid positions).
variants=("without||-" "without-grid|grid|-" "call|call|Workspace<u16, 512, 1024>::simplify, u16 triangles, Config::new()"
    "fast|fast|fast mode: FastWorkspace<u16, 512, 1024>::simplify, u16 triangles, Config::new()"
    "lean|lean|lean mode: LeanWorkspace<u16, 512, 1024>::simplify, u16 triangles, Config::new()"
    "fast-integer|fast-integer|fast mode, integer: FastWorkspace<u16, 512, 1024, Integer>::simplify, u16 triangles, Config::new()"
    "lean-integer|lean-integer|lean mode, integer: LeanWorkspace<u16, 512, 1024, Integer>::simplify, u16 triangles, Config::new()")
if [ $all = 1 ]; then
    variants+=(
        "paper|paper|Workspace<u16, 512, 1024>::simplify, u16 triangles, Config::paper()"
        "u32-triangles|u32-triangles|Config::new(), Workspace<u16, 512, 1024>: u16 triangles + u32 triangles"
        "u32-links|u32-links|Config::new(), Workspace<u16, ..> on u16 + Workspace<u32, 512, 1024> on u32"
        "batched|batched|Workspace<u16, 512, 1024>::simplify, Config::new(), feature batched"
        "seams|seams|Workspace<u16, 512, 1024>::simplify, Config::new(), feature seams"
        "parts|parts|Workspace<u16, 512, 1024>::simplify, Config::new(), feature parts"
    )
fi

# Builds one variant for one target and prints the image's path.
build() { # target name features
    local features=$3
    if [ ${#extra[@]} -gt 0 ]; then features=${features:+$features,}${extra[0]}; fi
    local args=(build --release --quiet --manifest-path "$root/tests/flash/Cargo.toml" --target "$1")
    [ -z "$features" ] || args+=(--features "$features")
    echo "  cargo ${args[*]}" >&2
    cargo "${args[@]}" >&2
    local elf="$images/$1-$2${extra[0]:+-${extra[0]}}-o$opt.elf"
    cp "$CARGO_TARGET_DIR/$1/release/tinydecimate-flash" "$elf"
    echo "$elf"
}

# .text + .rodata of an image, in bytes.
code() {
    "$bin/llvm-size" -A "$1" | awk '$1 == ".text" || $1 == ".rodata" { s += $2 } END { print s }'
}

# Bytes with thousands spaced, as bench/DEVICES.md writes them; signed with --sign.
spaced() {
    local n=$1 sign=
    if [ "${2:-}" = --sign ]; then sign=+; fi
    if [ "$n" -lt 0 ]; then sign=-; n=$((-n)); fi
    echo "$sign$(echo "$n" | sed -e ':a' -e 's/\([0-9]\)\([0-9]\{3\}\)\($\| \)/\1 \2\3/' -e 'ta')"
}

kb() { awk -v b="$1" 'BEGIN { printf "%.1f KB", b / 1024 }'; }

# Defined symbols of an image, "address size type name", sizes in decimal, names demangled
# (llvm-nm -C leaves Rust's legacy escapes and hashes, which also differ between builds).
symbols() {
    "$bin/llvm-nm" --print-size --size-sort --defined-only --radix=d -C "$1" |
        sed -e 's/\$LT\$/</g; s/\$GT\$/>/g; s/\$C\$/,/g; s/\$u20\$/ /g; s/\$RF\$/\&/g' \
            -e 's/\$BP\$/*/g; s/\$u7b\$/{/g; s/\$u7d\$/}/g; s/\.\./::/g; s/::h[0-9a-f]\{16\}$//'
}

# Code and read-only symbols of `with` that are new or bigger than in `without`, largest first.
added_symbols() { # without with n
    local tmp
    tmp=$(mktemp)
    symbols "$1" >"$tmp"
    symbols "$2" |
        awk -v old="$tmp" '
            function name(line) { sub(/^[^ ]+ +[^ ]+ +[^ ]+ +/, "", line); return line }
            BEGIN { while ((getline line < old) > 0) { split(line, f, " "); was[name(line)] += f[2] } }
            $3 ~ /^[tTrR]$/ { n = name($0); d = $2 - was[n]; was[n] = 0; if (d > 0) printf "%8d  %s\n", d, n }' |
        sort -rn | head -n "$3"
    rm -f "$tmp"
}

echo "building tests/flash (opt-level \"$opt\", fat LTO, codegen-units 1, panic = abort)${extra[0]:+, ${extra[0]}}:" >&2
declare -A size elf
for t in "${targets[@]}"; do
    for v in "${variants[@]}"; do
        IFS='|' read -r name features _ <<<"$v"
        elf[$t/$name]=$(build "$t" "$name" "$features")
        size[$t/$name]=$(code "${elf[$t/$name]}")
    done
done

# The table: each variant's library flash, and (with --all) what it adds over the default call.
table() {
    echo "flash of the library (.text + .rodata; image with the call - image without; opt-level \"$opt\", fat LTO, one codegen unit, panic = abort)${extra[0]:+, ${extra[0]} backend}"
    echo
    echo "| target | instantiation | without | with | library (difference) | over the default call |"
    echo "|---|---|---:|---:|---:|---:|"
    for t in "${targets[@]}"; do
        one=${size[$t/call]}
        for v in "${variants[@]:2}"; do
            IFS='|' read -r name _ what <<<"$v"
            case $name in
                *-integer) base=${size[$t/without-grid]} ;;
                *) base=${size[$t/without]} ;;
            esac
            s=${size[$t/$name]}
            d=$((s - base))
            case $name in
                call | fast | lean | fast-integer | lean-integer) over=- ;;
                *) over="$(spaced $((s - one)) --sign) B" ;;
            esac
            echo "| $t | $what | $(spaced "$base") B | $(spaced "$s") B | **$(spaced "$d") B** ($(kb "$d")) | $over |"
        done
    done
}

echo
table
if [ -n "$out" ]; then
    {
        echo "# Flash of one instantiation"
        echo
        echo "Written by \`scripts/flash.sh$([ $all = 1 ] && echo " --all") --out $out\`${extra[0]:+ (--${extra[0]})}; do not edit. The firmware in tests/flash is built without and with each call; [docs/devices.md](../docs/devices.md#flash) says what the figures mean."
        echo
        table
    } >"$out"
    echo "wrote $out" >&2
fi

for t in "${targets[@]}"; do
    echo
    echo "largest symbols the call adds, $t (bytes, llvm-nm --size-sort; inlined code counts in its caller):"
    added_symbols "${elf[$t/without]}" "${elf[$t/call]}" "$nsym"
done
