#!/usr/bin/env python3
"""Writes the hostile model files of this corpus (run from this folder). Every file must be
refused with a clear error, but those named ok_*, which must load."""
import base64, copy, json, struct

def w(name, data):
    with open(name, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

w("huge_count.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
w("list_length_huge.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n" + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<I", 0xffffffff))
w("index_out_of_range.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")
w("count_mismatch.stl", b"x" * 80 + struct.pack("<I", 0x7fffffff) + b"\0" * 50)
w("unclosed_loop.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n")
w("bad_texture_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n")
w("nan_normal_ref.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 1\nf 1//1 2//1 3//1\n")
w("only_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
w("ok_degenerate_among_good.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n")

base = {"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}

def g(name, change):
    d = copy.deepcopy(base)
    change(d)
    w(name, json.dumps(d))

def exponential(d):
    # Each node has the next one as its child twice: 2^40 instances without a cycle.
    d["nodes"] = [{"children": [i + 1, i + 1]} for i in range(40)] + [{"mesh": 0}]

g("ok_triangle.gltf", lambda d: None)
g("required_extension.gltf", lambda d: d.update({"extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"]}))
g("accessor_past_buffer.gltf", lambda d: d["accessors"][0].update({"count": 1000}))
g("view_past_buffer.gltf", lambda d: d["bufferViews"][0].update({"byteOffset": 30}))
g("cyclic_nodes.gltf", lambda d: d["nodes"][0].update({"children": [0]}))
g("missing_buffer_file.gltf", lambda d: d["buffers"][0].update({"uri": "nowhere.bin"}))
g("bad_base64.gltf", lambda d: d["buffers"][0].update({"uri": "data:application/octet-stream;base64,@@@"}))
g("huge_count_no_view.gltf", lambda d: (d["accessors"][0].pop("bufferView"), d["accessors"][0].update({"count": 4000000000})))
g("exponential_instances.gltf", exponential)
w("not_json.gltf", "{\"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [ oops ]\n}")
w("bad_glb_length.glb", b"glTF" + struct.pack("<II", 2, 0xffffff) + struct.pack("<II", 0xfffff0, 0x4E4F534A) + b"{}  ")
# Found by the million-input run: a GLB length below the header (gltf 1.4.1 subtracts unchecked).
w("glb_length_below_header.glb", b"glTF" + struct.pack("<II", 2, 3) + struct.pack("<II", 0x5e0, 0x4E4F534A) + b"{\"asset\": {\"version\": \"2.0\"}}")
# Found by fuzzing: no accessors at all, while a primitive names POSITION 0 (gltf-json 1.4.1's
# validator indexed the accessors unchecked and panicked).
g("position_accessor_missing.gltf", lambda d: d.update({"accessors": []}))
# The gltf crate's accessors unwrap what its validator does not require: raytty reads these
# from the JSON instead. A perspective camera with only an orthographic object is not used,
# and an embedded image without a MIME type is only named.
def camera_mismatch(d):
    d["cameras"] = [{"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}}]
    d["nodes"].append({"camera": 0, "translation": [0, 0, 3]})
    d["scenes"][0]["nodes"].append(1)
g("ok_camera_type_mismatch.gltf", camera_mismatch)
def image_without_mime(d):
    d["images"] = [{"bufferView": 0}]
    d["textures"] = [{"source": 0}]
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    d["meshes"][0]["primitives"][0]["material"] = 0
g("ok_image_without_mime.gltf", image_without_mime)


# Textures never fail a load: each of these loads, with a warning, in the base colour factor.
def textured(image, sampler=None, tex_coord=0):
    def change(d):
        d["images"] = [image]
        d["textures"] = [{"source": 0} if sampler is None else {"source": 0, "sampler": 0}]
        if sampler is not None:
            d["samplers"] = [sampler]
        d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": tex_coord}}}]
        d["meshes"][0]["primitives"][0]["material"] = 0
    return change

PNG_HEAD = b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR"
g("ok_texture_missing_file.gltf", textured({"uri": "no_such_texture.png"}))
g("ok_texture_not_an_image.gltf", textured({"uri": "data:image/png;base64,bm90IGFuIGltYWdl"}))
g("ok_texture_truncated_png.gltf", textured({"uri": "data:image/png;base64," + base64.b64encode(PNG_HEAD + struct.pack(">II", 2, 2)).decode()}))
g("ok_texture_huge_png.gltf", textured({"uri": "data:image/png;base64," + base64.b64encode(PNG_HEAD + struct.pack(">IIBBBBB", 100000, 100000, 8, 2, 0, 0, 0) + b"\0" * 4).decode()}))
g("ok_texture_truncated_jpeg.gltf", textured({"uri": "data:image/jpeg;base64," + base64.b64encode(b"\xff\xd8\xff\xe0\0\x10JFIF\0").decode()}))
g("ok_texture_second_texcoord.gltf", textured({"uri": "no_such_texture.png"}, tex_coord=1))
g("ok_texture_odd_sampler.gltf", textured({"uri": "data:image/png;base64,bm90IGFuIGltYWdl"}, {"wrapS": 33648, "wrapT": 33071, "magFilter": 9728}))
w("ok_colours_and_normals_nan.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float red\nproperty float green\nproperty float blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 nan 0 0 nan 2 -1\n1 0 0 0 0 0 inf 0 0\n0 1 0 0 0 1 0.5 0.5 0.5\n3 0 1 2\n")
w("ok_texture_coordinates_far_out.obj", "mtllib cube.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 5e5 -5e5\nusemtl red\nf 1/1 2/2 3/1\n")
