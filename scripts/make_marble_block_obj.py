#!/usr/bin/env python3
"""Writes examples/models/marble-block.obj: the 100 x 100 x 50 mm block of
examples/scenes/marble.toml as a 12-triangle mesh with texture coordinates, for
examples/scenes/marble-uv.toml (the vein texture read through UVs instead of a planar
projection).

Each face has its own four vertices and maps its own plane at 1 / 80 mm per unit of u and v
(the planar scene's 80 mm tiles). The top face's coordinates are the planar projection's
(u = x/80 + 1/2, v = y/80 + 1/2), so the top reads the veins where marble.toml does; the sides
show the texture flat on each face instead of the planar projection's streaks down them.

Standard library only; deterministic:

    python3 scripts/make_marble_block_obj.py
"""

import os

OUT = os.path.join(os.path.dirname(__file__), "..", "examples", "models", "marble-block.obj")
LO = (-50.0, -50.0, -50.0)
HI = (50.0, 50.0, 0.0)
TILE = 80.0


def main():
    x0, y0, z0 = LO
    x1, y1, z1 = HI
    # Each face: its corners counter-clockwise seen from outside, and the two axes its
    # texture coordinates follow (u along the first, v along the second).
    faces = [
        ([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], (0, 1)),  # top, +z
        ([(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)], (0, 1)),  # bottom, -z
        ([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], (0, 2)),  # front, -y
        ([(x1, y1, z0), (x0, y1, z0), (x0, y1, z1), (x1, y1, z1)], (0, 2)),  # back, +y
        ([(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)], (1, 2)),  # right, +x
        ([(x0, y1, z0), (x0, y0, z0), (x0, y0, z1), (x0, y1, z1)], (1, 2)),  # left, -x
    ]
    lines = [
        "# The marble block of examples/scenes/marble.toml with per-face texture coordinates.",
        "# Written by scripts/make_marble_block_obj.py; do not edit.",
    ]
    for corners, _ in faces:
        for p in corners:
            lines.append("v {:.1f} {:.1f} {:.1f}".format(*p))
    for corners, (a, b) in faces:
        for p in corners:
            lines.append("vt {:.6f} {:.6f}".format(p[a] / TILE + 0.5, p[b] / TILE + 0.5))
    for f in range(len(faces)):
        k = 4 * f + 1
        for tri in ((k, k + 1, k + 2), (k, k + 2, k + 3)):
            lines.append("f " + " ".join("{0}/{0}".format(i) for i in tri))
    with open(OUT, "w", newline="\n") as out:
        out.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
