#!/usr/bin/env python3
"""Writes the textured test models: a square (two triangles in the z = 0 plane, facing +z, from
(-1, -1) to (1, 1)) with a 2x2 checker texture, red and green in its top row, blue and white in
its bottom row, in three forms:
  checker.png                  the texture (written here with zlib, no imaging library)
  checker.gltf                 glTF, texture coordinates and the PNG by file name
  checker.obj + checker.mtl    the same triangles with `vt` and `map_Kd checker.png`
  checker_jpeg.gltf            glTF with the texture as a 16x16 JPEG inside its buffer (a
                               buffer view), written only where Pillow is installed
  checker.glb                  GLB with the PNG in its binary chunk, vertex normals and colours
                               (white) too: a seed of the fuzz test
so that raytty must draw the texture's colours in the square's four quarters, the same in each
form. Run from this folder: python3 make_texture_twins.py (the files are committed)."""
import base64, io, json, struct, zlib

RED, GREEN, BLUE, WHITE = (255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 255)
ROWS = [[RED, GREEN], [BLUE, WHITE]]  # top row first


def png(rows):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    h, w = len(rows), len(rows[0])
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


with open("checker.png", "wb") as f:
    f.write(png(ROWS))

# Corners counter-clockwise seen from +z; glTF's texture coordinates run down from the image's
# top, OBJ's up from its bottom.
P = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
UV = [(0, 1), (1, 1), (1, 0), (0, 0)]
T = [(0, 1, 2), (0, 2, 3)]

with open("checker.mtl", "w") as f:
    f.write("# raytty test material: the twin of checker.gltf's\nnewmtl checker\nKd 1 1 1\nmap_Kd checker.png\n")
with open("checker.obj", "w") as f:
    f.write("# raytty test model: the twin of checker.gltf\nmtllib checker.mtl\nusemtl checker\n")
    for p in P:
        f.write("v %g %g %g\n" % p)
    for u, v in UV:
        f.write("vt %g %g\n" % (u, 1 - v))
    for t in T:
        f.write("f %s\n" % " ".join("%d/%d" % (i + 1, i + 1) for i in t))


def gltf(image, image_bytes=b""):
    blob = b"".join(struct.pack("<3f", *p) for p in P)
    blob += b"".join(struct.pack("<2f", *t) for t in UV)
    blob += b"".join(struct.pack("<3H", *t) for t in T) + b"\0\0"
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
             {"buffer": 0, "byteOffset": 48, "byteLength": 32},
             {"buffer": 0, "byteOffset": 80, "byteLength": 12}]
    if image_bytes:
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(image_bytes)})
        blob += image_bytes
    return {
        "asset": {"version": "2.0", "generator": "raytty tests/models/make_texture_twins.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"name": "checker", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "baseColorTexture": {"index": 0},
            "metallicFactor": 0, "roughnessFactor": 1}}],
        "textures": [{"source": 0}],
        "images": [image],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    }


def write(name, doc):
    with open(name, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


write("checker.gltf", gltf({"uri": "checker.png"}))
try:
    from PIL import Image
    img = Image.new("RGB", (16, 16))
    for y in range(16):
        for x in range(16):
            img.putpixel((x, y), ROWS[y // 8][x // 8])
    out = io.BytesIO()
    img.save(out, "JPEG", quality=100, subsampling=0)
    write("checker_jpeg.gltf", gltf({"bufferView": 3, "mimeType": "image/jpeg"}, out.getvalue()))
except ImportError:
    print("Pillow is not installed: checker_jpeg.gltf left as it is")


# The GLB: the PNG in the binary chunk, and NORMAL and COLOR_0 accessors.
doc = gltf({"bufferView": 3, "mimeType": "image/png"}, png(ROWS))
blob = base64.b64decode(doc["buffers"][0].pop("uri").split(",", 1)[1])
while len(blob) % 4:
    blob += b"\0"
for kind, value in (("NORMAL", (0, 0, 1)), ("COLOR_0", (1, 1, 1))):
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": 48})
    doc["accessors"].append({"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126, "count": 4, "type": "VEC3"})
    doc["meshes"][0]["primitives"][0]["attributes"][kind] = len(doc["accessors"]) - 1
    blob += struct.pack("<3f", *value) * 4
doc["buffers"][0]["byteLength"] = len(blob)
text = json.dumps(doc).encode()
text += b" " * (-len(text) % 4)
with open("checker.glb", "wb") as f:
    f.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(blob)))
    f.write(struct.pack("<I4s", len(text), b"JSON") + text)
    f.write(struct.pack("<I4s", len(blob), b"BIN\0") + blob)
