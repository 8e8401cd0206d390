#!/usr/bin/env python3
"""Writes examples/scenes/sky.hdr, the environment map of examples/scenes/sky-wax.toml.

A 64 x 32 equirectangular (latitude-longitude) Radiance RGBE image, linear radiance, row 0
straight up (the scene's up axis, z), column 0 at azimuth 0 (+x), azimuth growing with the
column (docs/lighting-and-surfaces.md):

* sky (above the horizon): blue at the zenith, paler and brighter toward the horizon;
* sun: a small disc (radius 4 degrees, so it covers a few texels) 35 degrees above the
  horizon at azimuth 60 degrees, radiance 400: about as much irradiance on a face toward it
  as the whole sky gives;
* ground (below the horizon): a dull brown, darker toward the nadir.

Each texel holds the mean of 4 x 4 samples over its solid angle. Deterministic (no
randomness), standard library only. The file uses new-style RLE scanlines written as
literal dumps (no runs), which every Radiance reader accepts.

    python3 scripts/make_sky_hdr.py
"""

import math
import os

W, H = 64, 32
HERE = os.path.join(os.path.dirname(__file__), "..", "examples", "scenes")

SUN_ELEVATION = math.radians(35.0)
SUN_AZIMUTH = math.radians(60.0)
SUN_RADIUS = math.radians(4.0)
SUN_RADIANCE = (400.0, 380.0, 340.0)


def direction(theta, phi):
    s = math.sin(theta)
    return (s * math.cos(phi), s * math.sin(phi), math.cos(theta))


SUN = direction(math.pi / 2 - SUN_ELEVATION, SUN_AZIMUTH)


def radiance(theta, phi):
    """Radiance arriving from the direction (theta from up, phi azimuth)."""
    d = direction(theta, phi)
    if d[2] >= 0.0:
        cos_sun = sum(a * b for a, b in zip(d, SUN))
        if cos_sun >= math.cos(SUN_RADIUS):
            return SUN_RADIANCE
        # Toward the horizon (d_z -> 0) the sky pales and brightens.
        h = 1.0 - d[2]
        zenith = (0.25, 0.45, 0.95)
        horizon = (0.85, 0.9, 1.0)
        return tuple(z + (hz - z) * h ** 2 for z, hz in zip(zenith, horizon))
    g = 0.5 + 0.5 * (1.0 + d[2])  # 1 at the horizon, 0.5 straight down
    return tuple(c * g for c in (0.16, 0.12, 0.08))


def texel(i, j, n=4):
    acc = [0.0, 0.0, 0.0]
    for a in range(n):
        for b in range(n):
            u = (i + (a + 0.5) / n) / W
            v = (j + (b + 0.5) / n) / H
            for c, x in enumerate(radiance(math.pi * v, 2.0 * math.pi * u)):
                acc[c] += x / (n * n)
    return acc


def rgbe(c):
    v = max(c)
    if v < 1e-32:
        return (0, 0, 0, 0)
    m, e = math.frexp(v)  # v = m * 2^e, m in [0.5, 1)
    scale = m * 256.0 / v
    return tuple(int(x * scale) for x in c) + (e + 128,)


def main():
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    out += ("-Y %d +X %d\n" % (H, W)).encode()
    for j in range(H):
        row = [rgbe(texel(i, j)) for i in range(W)]
        out += bytes([2, 2, W >> 8, W & 255])
        for ch in range(4):
            values = [p[ch] for p in row]
            for k in range(0, W, 128):
                chunk = values[k:k + 128]
                out.append(len(chunk))
                out += bytes(chunk)
    path = os.path.join(HERE, "sky.hdr")
    with open(path, "wb") as f:
        f.write(out)
    print("wrote", os.path.normpath(path), len(out), "bytes")


if __name__ == "__main__":
    main()
