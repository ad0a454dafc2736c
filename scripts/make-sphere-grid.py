#!/usr/bin/env python3
"""Writes the standard check of a glTF renderer: a 5x5 grid of gold spheres, metallic 0..1 from
the top row down, roughness 0..1 from left to right, one directional light (KHR_lights_punctual,
3 lux) and a camera framing the grid. One .gltf with the buffer embedded (base64).

Usage: scripts/make-sphere-grid.py OUT.gltf [--base R,G,B]
Then:  viewer render OUT.gltf --out grid.png [--environment default|none|FILE.hdr]
"""
import argparse
import base64
import json
import math
import struct


def uv_sphere(slices=48, stacks=24):
    pos, nrm, idx = [], [], []
    for j in range(stacks + 1):
        theta = math.pi * j / stacks
        for i in range(slices + 1):
            phi = 2 * math.pi * i / slices
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            pos.append(n)
            nrm.append(n)
    for j in range(stacks):
        for i in range(slices):
            a = j * (slices + 1) + i
            b = a + slices + 1
            idx += [a, a + 1, b, a + 1, b + 1, b]
    return pos, nrm, idx


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--base", default="1.0,0.766,0.336", help="base colour (linear), default gold")
    a = ap.parse_args()
    base = [float(c) for c in a.base.split(",")] + [1.0]
    pos, nrm, idx = uv_sphere()
    blob = b"".join(struct.pack("<3f", *p) for p in pos) + b"".join(struct.pack("<3f", *n) for n in nrm)
    idx_offset = len(blob)
    blob += b"".join(struct.pack("<I", i) for i in idx)
    nv = len(pos)
    gltf = {
        "asset": {"version": "2.0", "generator": "make-sphere-grid.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 3.0, "color": [1, 1, 1]}]}},
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": nv * 12, "target": 34962},
            {"buffer": 0, "byteOffset": nv * 12, "byteLength": nv * 12, "target": 34962},
            {"buffer": 0, "byteOffset": idx_offset, "byteLength": len(idx) * 4, "target": 34963},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": nv, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
        ],
        "materials": [],
        "meshes": [],
        "nodes": [],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1, "zfar": 100.0}}],
        "scenes": [{"nodes": []}],
        "scene": 0,
    }
    for row in range(5):  # metallic, top row 0
        for col in range(5):  # roughness, left column 0
            m = len(gltf["materials"])
            gltf["materials"].append({
                "name": "metallic %.2f roughness %.2f" % (row / 4, col / 4),
                "pbrMetallicRoughness": {"baseColorFactor": base, "metallicFactor": row / 4, "roughnessFactor": col / 4},
            })
            gltf["meshes"].append({"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": m}]})
            gltf["nodes"].append({"mesh": m, "translation": [(col - 2) * 2.2, (2 - row) * 2.2, 0.0], "scale": [0.95, 0.95, 0.95]})
    n = len(gltf["nodes"])
    # The sun from the upper left, behind the viewer; the camera straight on.
    gltf["nodes"].append({"extensions": {"KHR_lights_punctual": {"light": 0}},
                          "rotation": [-0.3535534, -0.3535534, -0.1464466, 0.8535534]})
    gltf["nodes"].append({"camera": 0, "translation": [0.0, 0.0, 19.0]})
    gltf["scenes"][0]["nodes"] = list(range(n + 2))
    with open(a.out, "w") as f:
        json.dump(gltf, f)


if __name__ == "__main__":
    main()
