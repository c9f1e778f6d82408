#!/usr/bin/env python3
"""Writes lamp.gltf and lamp.obj + lamp.mtl: one small scene in two formats (a floor, a red
back wall, a gold metal block and a ceiling panel that emits downward; no camera, no light),
the same triangles in the same order and the same materials, so that raytty must render the two
alike. Run from this folder: python3 make_lamp_twins.py (the files are committed)."""
import base64, json, struct

def quad(a, b, c, d):
    return [(a, b, c), (a, c, d)]

def box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = lambda i: (x1 if i & 4 else x0, y1 if i & 2 else y0, z1 if i & 1 else z0)
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return [t for f in faces for t in quad(*(v(i) for i in f))]

# (name, glTF material, MTL lines, triangles): counter-clockwise seen from the lit side.
PARTS = [
    ("floor", {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0, "roughnessFactor": 1}},
     "Kd 0.8 0.8 0.8", quad((-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1))),
    ("wall", {"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.2, 0.2, 1], "metallicFactor": 0, "roughnessFactor": 1}},
     "Kd 0.7 0.2 0.2", quad((-1, 0, -1), (1, 0, -1), (1, 1.5, -1), (-1, 1.5, -1))),
    ("panel", {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1},
               "emissiveFactor": [1, 0.9, 0.8], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}},
     "Kd 0 0 0\nKe 5 4.5 4", quad((-0.3, 1.5, -0.3), (0.3, 1.5, -0.3), (0.3, 1.5, 0.3), (-0.3, 1.5, 0.3))),
    ("gold", {"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.7, 0.4, 1], "metallicFactor": 1, "roughnessFactor": 0.3}},
     "Kd 0.9 0.7 0.4\nPm 1\nPr 0.3", box((-0.25, 0, -0.25), (0.25, 0.5, 0.25))),
]

verts, prims, blob = [], [], b""
with open("lamp.obj", "w") as obj, open("lamp.mtl", "w") as mtl:
    obj.write("# raytty test scene: the twin of lamp.gltf\nmtllib lamp.mtl\n")
    for name, gm, mm, tris in PARTS:
        mtl.write("newmtl %s\n%s\n\n" % (name, mm))
        obj.write("usemtl %s\n" % name)
        pos = [p for t in tris for p in t]
        for p in pos:
            obj.write("v %g %g %g\n" % p)
        base = len(verts)
        for i in range(len(tris)):
            obj.write("f %d %d %d\n" % tuple(base + 3 * i + k + 1 for k in range(3)))
        verts += pos
        pbytes = b"".join(struct.pack("<3f", *p) for p in pos)
        ibytes = b"".join(struct.pack("<I", i) for i in range(len(pos)))
        prims.append((len(pos), len(blob), len(pbytes), len(blob) + len(pbytes), len(ibytes),
                      [min(p[k] for p in pos) for k in range(3)], [max(p[k] for p in pos) for k in range(3)]))
        blob += pbytes + ibytes

views, accessors, primitives = [], [], []
for m, (n, po, pl, io, il, lo, hi) in enumerate(prims):
    views += [{"buffer": 0, "byteOffset": po, "byteLength": pl}, {"buffer": 0, "byteOffset": io, "byteLength": il}]
    accessors += [{"bufferView": 2 * m, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi},
                  {"bufferView": 2 * m + 1, "componentType": 5125, "count": n, "type": "SCALAR"}]
    primitives.append({"attributes": {"POSITION": 2 * m}, "indices": 2 * m + 1, "material": m})
gltf = {
    "asset": {"version": "2.0", "generator": "raytty tests/models/make_lamp_twins.py"},
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": primitives}],
    "materials": [dict(gm, name=name) for name, gm, _, _ in PARTS],
    "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": views, "accessors": accessors,
}
with open("lamp.gltf", "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
