#!/usr/bin/env sh
# Downloads the Stanford bunny from the Stanford 3D Scanning Repository (its original source),
# closes the holes in its base so that it bounds a volume, and writes
# examples/models/bunny.obj, which examples/scenes/bunny.toml renders:
#
#   sh scripts/fetch-bunny.sh
#   cargo run --release -- render examples/scenes/bunny.toml
#
# Needs curl or wget, tar and the Rust toolchain. The mesh is the full-resolution
# reconstruction `bun_zipper.ply` (35,947 vertices, 69,451 triangles); the repository's terms
# (http://graphics.stanford.edu/data/3Dscanrep/) ask that it be credited to the Stanford
# Computer Graphics Laboratory and not be used commercially without permission. The file is
# not committed (examples/models/bunny.obj is in .gitignore).
set -eu
cd "$(dirname "$0")/.."
url="${BUNNY_URL:-http://graphics.stanford.edu/pub/3Dscanrep/bunny.tar.gz}"
out="examples/models/bunny.obj"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT INT TERM
echo "downloading $url"
if command -v curl >/dev/null 2>&1; then
    curl -fL --retry 2 -o "$work/bunny.tar.gz" "$url"
elif command -v wget >/dev/null 2>&1; then
    wget -O "$work/bunny.tar.gz" "$url"
else
    echo "error: neither curl nor wget is installed; download $url by hand, extract" >&2
    echo "bunny/reconstruction/bun_zipper.ply and run:" >&2
    echo "  cargo run --release --example close_holes -- bun_zipper.ply $out" >&2
    exit 1
fi
tar -xzf "$work/bunny.tar.gz" -C "$work" bunny/reconstruction/bun_zipper.ply
cargo run --release --example close_holes -- "$work/bunny/reconstruction/bun_zipper.ply" "$out"
