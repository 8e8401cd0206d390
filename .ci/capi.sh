#!/usr/bin/env bash
# The C ABI from C: compile examples/pair.c against the checked-in header and the static
# library with gcc, run it, and check that the bits of its S equal those the Rust crates print
# for the same pair (`cargo run -p het-bssrdf-capi --example pair`). The header itself is
# regenerated and compared by `cargo test -p het-bssrdf-capi --test header`.
set -euo pipefail
cd "$(dirname "$0")/.."
target="${CARGO_TARGET_DIR:-target}"
cargo build --locked -q -p het-bssrdf-capi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
gcc -std=c11 -O2 -Wall -Wextra -Werror -ffp-contract=off -Icrates/capi/include \
    crates/capi/examples/pair.c "$target/debug/libhet_bssrdf_capi.a" -lm -lpthread -ldl \
    -o "$tmp/pair"
if command -v g++ >/dev/null; then
    # The header is valid C++ too (C++ renderers include it as is).
    echo '#include "het_bssrdf.h"' | g++ -std=c++17 -fsyntax-only -Wall -Werror \
        -Icrates/capi/include -x c++ -
fi
echo "C:"
"$tmp/pair" | tee "$tmp/c.txt"
echo "Rust:"
cargo run --locked -q -p het-bssrdf-capi --example pair | tee "$tmp/rust.txt"
c_bits="$(grep '^bits' "$tmp/c.txt")"
rust_bits="$(grep '^bits' "$tmp/rust.txt")"
if [ "$c_bits" != "$rust_bits" ]; then
    echo "the C example's S differs from the Rust S: '$c_bits' against '$rust_bits'" >&2
    exit 1
fi
echo "C example: S equals the Rust S bit for bit ($c_bits)"
