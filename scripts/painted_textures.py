#!/usr/bin/env python3
"""Writes the two textures of examples/scenes/painted.toml (artist parameters).

* examples/scenes/painted-colour.png: 64 x 64 RGB, 8 bit sRGB (the scene reads it as colour):
  three soft discs (red, green, blue-ish) on a warm off-white ground, the subsurface_color.
* examples/scenes/painted-radius.png: 64 x 64 grey, 8 bit, stored linear (`linear = true`):
  the subsurface_radius in units of the scene's radius scale, 0.15 at the left edge rising
  to 1 at the right, with a dark band (0.05) across the middle.

Deterministic (no randomness), standard library only.

    python3 scripts/painted_textures.py
"""

import math
import os
import struct
import zlib

N = 64
HERE = os.path.join(os.path.dirname(__file__), "..", "examples", "scenes")


def png(path, width, height, channels, pixel):
    rows = []
    for y in range(height):
        row = bytearray([0])  # PNG filter type 0
        for x in range(width):
            row.extend(int(round(255 * max(0.0, min(1.0, c)))) for c in pixel(x, y))
        rows.append(bytes(row))
    colour_type = {1: 0, 3: 2}[channels]

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    data = (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(b"".join(rows), 9))
            + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)
    print(f"wrote {os.path.normpath(path)} ({len(data)} bytes)")


def colour(x, y):
    u, v = (x + 0.5) / N, (y + 0.5) / N
    c = [0.85, 0.75, 0.6]  # sRGB ground
    for (cx, cy, rgb) in [(0.3, 0.3, (0.8, 0.15, 0.1)),
                          (0.7, 0.35, (0.2, 0.7, 0.25)),
                          (0.5, 0.72, (0.2, 0.35, 0.85))]:
        w = math.exp(-((u - cx) ** 2 + (v - cy) ** 2) / (2 * 0.1 ** 2))
        c = [a * (1 - w) + b * w for a, b in zip(c, rgb)]
    return c


def radius(x, y):
    u, v = (x + 0.5) / N, (y + 0.5) / N
    r = 0.15 + 0.85 * u
    if abs(v - 0.5) < 0.06:
        r = 0.05
    return [r]


def main():
    png(os.path.join(HERE, "painted-colour.png"), N, N, 3, colour)
    png(os.path.join(HERE, "painted-radius.png"), N, N, 1, radius)


if __name__ == "__main__":
    main()
