#!/usr/bin/env python3
"""Writes examples/models/jade.gltf: a self-contained glTF 2.0 file (buffers and image embedded
as data URIs) with two materials, for the glTF material import (docs/gltf.md):

* `jade`: a UV sphere of radius 1 (scene units: cm) whose material is a translucent volume:
  KHR_materials_volume (thicknessFactor 1, attenuationDistance 0.01, a green attenuation
  colour), KHR_materials_diffuse_transmission, KHR_materials_ior (1.3), and a base-colour
  texture of dark veins on green (64 x 32 PNG, sRGB);
* `stand`: a 6 x 6 floor quad under it, plain base colour (read as a diffuse surface).

Standard library only; deterministic (no randomness, fixed zlib level), so the output is
byte-identical on every run:

    python3 scripts/make_gltf_jade.py
"""

import base64
import json
import math
import os
import struct
import zlib

OUT = os.path.join(os.path.dirname(__file__), "..", "examples", "models", "jade.gltf")


def png(width, height, rgb):
    """An 8-bit RGB PNG from rows of (r, g, b) tuples."""
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in rgb)

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9))
            + chunk(b"IEND", b""))


def veins(width=64, height=32):
    rows = []
    for j in range(height):
        row = []
        for i in range(width):
            u, v = i / width, j / height
            # Two sinusoidal veins across the sphere: dark where |sin| is near 0.
            s = abs(math.sin(2 * math.pi * (2 * u + 0.35 * math.sin(2 * math.pi * v))))
            t = min(1.0, s / 0.25)
            green = (0.45, 0.80, 0.55)
            dark = (0.12, 0.25, 0.15)
            c = [dark[k] + (green[k] - dark[k]) * t for k in range(3)]
            # linear -> sRGB, 8-bit
            enc = [12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055 for x in c]
            row.append(tuple(int(round(255 * x)) for x in enc))
        rows.append(row)
    return rows


def sphere(stacks=16, slices=32):
    pos, nor, uv, idx = [], [], [], []
    for j in range(stacks + 1):
        th = math.pi * j / stacks
        for i in range(slices + 1):
            ph = 2 * math.pi * i / slices
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            pos.append((n[0], n[1] + 1.0, n[2]))  # resting on y = 0
            nor.append(n)
            uv.append((i / slices, j / stacks))
    for j in range(stacks):
        for i in range(slices):
            a = j * (slices + 1) + i
            b = a + slices + 1
            if j != 0:
                idx.append((a, a + 1, b))
            if j != stacks - 1:
                idx.append((a + 1, b + 1, b))
    return pos, nor, uv, idx


def quad(h=3.0):
    pos = [(-h, 0, -h), (h, 0, -h), (h, 0, h), (-h, 0, h)]
    nor = [(0, 1, 0)] * 4
    uv = [(0, 0), (1, 0), (1, 1), (0, 1)]
    idx = [(0, 2, 1), (0, 3, 2)]
    return pos, nor, uv, idx


def main():
    blob = bytearray()
    views, accessors = [], []

    def add(data, count, kind, ctype, target, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
                      **({"target": target} if target else {})})
        blob.extend(data)
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": count,
               "type": kind}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    meshes = []
    for material, (pos, nor, uv, idx) in enumerate([sphere(), quad()]):
        lo = [min(p[k] for p in pos) for k in range(3)]
        hi = [max(p[k] for p in pos) for k in range(3)]
        p = add(b"".join(struct.pack("<3f", *x) for x in pos), len(pos), "VEC3", 5126, 34962,
                (lo, hi))
        n = add(b"".join(struct.pack("<3f", *x) for x in nor), len(nor), "VEC3", 5126, 34962)
        t = add(b"".join(struct.pack("<2f", *x) for x in uv), len(uv), "VEC2", 5126, 34962)
        i = add(b"".join(struct.pack("<3I", *x) for x in idx), 3 * len(idx), "SCALAR", 5125,
                34963)
        meshes.append({"primitives": [{"attributes": {"POSITION": p, "NORMAL": n,
                                                      "TEXCOORD_0": t},
                                       "indices": i, "material": material}]})
    image = png(64, 32, veins())
    doc = {
        "asset": {"version": "2.0", "generator": "het-bssrdf scripts/make_gltf_jade.py"},
        "extensionsUsed": ["KHR_materials_volume", "KHR_materials_diffuse_transmission",
                           "KHR_materials_ior"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "name": "jade"}, {"mesh": 1, "name": "stand"}],
        "meshes": meshes,
        "materials": [
            {"name": "jade",
             "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1],
                                      "baseColorTexture": {"index": 0},
                                      "metallicFactor": 0, "roughnessFactor": 0.3},
             "extensions": {
                 "KHR_materials_volume": {"thicknessFactor": 1.0,
                                          "attenuationDistance": 0.01,
                                          "attenuationColor": [0.5, 0.8, 0.6]},
                 "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0},
                 "KHR_materials_ior": {"ior": 1.3}}},
            {"name": "stand",
             "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1],
                                      "metallicFactor": 0}},
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 33071}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(bytes(blob)).decode()}],
        "bufferViews": views,
        "accessors": accessors,
    }
    with open(OUT, "w", newline="\n") as f:
        json.dump(doc, f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    main()
