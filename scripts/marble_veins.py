#!/usr/bin/env python3
"""Writes examples/scenes/marble-veins.png, the vein texture of examples/scenes/marble.toml.

A 256 x 256 grey PNG (8 bit, stored linear: the scene reads it with `linear = true`): value
0.05 in the stone and up to 1.0 in the veins, which the scene scales to σa. The veins are the
level set sin(x + 3·turbulence) = 0 of a few octaves of value noise, tileable, from a fixed
seed, so the file is the same on every run. Standard library only.

    python3 scripts/marble_veins.py
"""

import math
import os
import random
import struct
import zlib

N = 256
SEED = 7
OCTAVES = 5


def lattice(size, rng):
    return [[rng.random() for _ in range(size)] for _ in range(size)]


def smooth(t):
    return t * t * (3.0 - 2.0 * t)


def value_noise(grid, size, x, y):
    """Tileable bilinear value noise with period `size` lattice cells over [0, 1)^2."""
    fx, fy = x * size, y * size
    i, j = int(math.floor(fx)), int(math.floor(fy))
    tx, ty = smooth(fx - i), smooth(fy - j)
    a = grid[j % size][i % size]
    b = grid[j % size][(i + 1) % size]
    c = grid[(j + 1) % size][i % size]
    d = grid[(j + 1) % size][(i + 1) % size]
    return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty


def main():
    rng = random.Random(SEED)
    grids = [(4 << k, lattice(4 << k, rng)) for k in range(OCTAVES)]
    rows = []
    for py in range(N):
        row = bytearray([0])  # PNG filter type 0
        for px in range(N):
            x, y = px / N, py / N
            turb = sum(value_noise(g, s, x, y) / (1 << k) for k, (s, g) in enumerate(grids))
            v = abs(math.sin(2.0 * math.pi * (2.0 * x + y) + 3.0 * turb))
            vein = max(0.0, 1.0 - v / 0.18) ** 2  # thin veins where the sine crosses zero
            value = 0.05 + 0.95 * vein
            row.append(int(round(255 * value)))
        rows.append(bytes(row))
    raw = b"".join(rows)

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n"
           + chunk(b"IHDR", struct.pack(">IIBBBBB", N, N, 8, 0, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 9))
           + chunk(b"IEND", b""))
    out = os.path.join(os.path.dirname(__file__), "..", "examples", "scenes", "marble-veins.png")
    with open(out, "wb") as f:
        f.write(png)
    print(f"wrote {os.path.normpath(out)} ({len(png)} bytes)")


if __name__ == "__main__":
    main()
