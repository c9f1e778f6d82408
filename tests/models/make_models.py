#!/usr/bin/env python3
"""Writes the small test models in this folder: a unit cube in every format raytty reads.
Run from this folder: python3 make_models.py (the files are committed; this regenerates them)."""
import base64, json, struct

V = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
# Faces as quads, counter-clockwise seen from outside: -x, +x, -y, +y, -z, +z.
Q = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
T = [t for a, b, c, d in Q for t in ((a, b, c), (a, c, d))]
N = [(-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), (0, 0, -1), (0, 0, 1)]

# OBJ with normals, UVs and two materials from an MTL library.
with open("cube.obj", "w") as f:
    f.write("# a unit cube: normals, UVs, two materials\nmtllib cube.mtl\n")
    for v in V:
        f.write("v %g %g %g\n" % v)
    for uv in ((0, 0), (1, 0), (1, 1), (0, 1)):
        f.write("vt %g %g\n" % uv)
    for n in N:
        f.write("vn %d %d %d\n" % n)
    for i, q in enumerate(Q):
        if i == 0:
            f.write("usemtl red\n")
        if i == 3:
            f.write("usemtl white\n")
        f.write("f " + " ".join("%d/%d/%d" % (v + 1, k + 1, i + 1) for k, v in enumerate(q)) + "\n")
with open("cube.mtl", "w") as f:
    f.write("newmtl red\nKd 0.8 0.1 0.1\nKs 0.04 0.04 0.04\nNs 50\nNi 1.5\nd 1\nillum 2\nPr 0.4\nPm 0\n\n"
            "newmtl white\nKd 0.8 0.8 0.8\nillum 1\n")

# PLY, ASCII with vertex colours, and binary little-endian.
head = ("ply\nformat %s 1.0\ncomment a unit cube\nelement vertex 8\nproperty float x\nproperty float y\n"
        "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
        "element face 6\nproperty list uchar int vertex_indices\nend_header\n")
col = lambda v: tuple(int(255 * (c + 0.5)) for c in v)
with open("cube.ply", "w") as f:
    f.write(head % "ascii")
    for v in V:
        f.write("%g %g %g %d %d %d\n" % (v + col(v)))
    for q in Q:
        f.write("4 %d %d %d %d\n" % q)
with open("cube_binary.ply", "wb") as f:
    f.write((head % "binary_little_endian").encode())
    for v in V:
        f.write(struct.pack("<3f3B", *v, *col(v)))
    for q in Q:
        f.write(struct.pack("<B4i", 4, *q))

# STL, ASCII and binary.
def normal(t):
    a, b, c = (V[i] for i in t)
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    return (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
with open("cube.stl", "w") as f:
    f.write("solid cube\n")
    for t in T:
        f.write("  facet normal %g %g %g\n    outer loop\n" % normal(t))
        for i in t:
            f.write("      vertex %g %g %g\n" % V[i])
        f.write("    endloop\n  endfacet\n")
    f.write("endsolid cube\n")
with open("cube_binary.stl", "wb") as f:
    f.write(b"binary cube".ljust(80, b" "))
    f.write(struct.pack("<I", len(T)))
    for t in T:
        f.write(struct.pack("<3f", *normal(t)))
        for i in t:
            f.write(struct.pack("<3f", *V[i]))
        f.write(b"\0\0")

# glTF: one cube mesh (indexed, COLOR_0) used by two nodes, a parent moved and turned and a
# child scaled; a .gltf with a data URI, and a .glb that adds a camera and a point light.
pos = b"".join(struct.pack("<3f", *v) for v in V)
cols = b"".join(struct.pack("<4f", *(c / 255 for c in col(v)), 1.0) for v in V)
idx = b"".join(struct.pack("<H", i) for t in T for i in t)
idx += b"\0" * (-len(idx) % 4)
data = pos + cols + idx
def doc(uri, extra_nodes=(), extra=None):
    d = {
        "asset": {"version": "2.0", "generator": "raytty tests/models/make_models.py"},
        "scene": 0,
        "scenes": [{"nodes": [0] + [2 + i for i in range(len(extra_nodes))]}],
        "nodes": [
            {"name": "parent", "mesh": 0, "translation": [0, 0.5, 0],
             "rotation": [0, 0.3826834, 0, 0.9238795], "children": [1]},
            {"name": "child", "mesh": 0, "translation": [1.5, 0, 0], "scale": [0.5, 0.5, 0.5]},
        ] + list(extra_nodes),
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2,
                                     "material": 0}]}],
        "materials": [{"name": "warm", "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 0.9, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.5}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
             "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
            {"bufferView": 1, "componentType": 5126, "count": 8, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5123, "count": 36, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(cols)},
            {"buffer": 0, "byteOffset": len(pos) + len(cols), "byteLength": 72},
        ],
        "buffers": [{"byteLength": len(data)} if uri is None else {"byteLength": len(data), "uri": uri}],
    }
    if extra:
        d.update(extra)
    return d
with open("two_nodes.gltf", "w") as f:
    json.dump(doc("data:application/octet-stream;base64," + base64.b64encode(data).decode()), f, indent=1)
glb = doc(None, [
    {"name": "camera", "camera": 0, "translation": [0.5, 1.0, 4.0]},
    {"name": "lamp", "translation": [1.0, 3.0, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
], {
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5.0}]}},
})
js = json.dumps(glb).encode()
js += b" " * (-len(js) % 4)
body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(data), 0x004E4942) + data
with open("cube.glb", "wb") as f:
    f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
