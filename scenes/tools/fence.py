#!/usr/bin/env python3
"""Writes scenes/models/fence/fence.gltf: a picket fence as one quad whose
base colour texture (16x16 RGBA, ours) is cut out by alphaMode MASK, the
pickets repeated eight times by KHR_texture_transform (fence.rt shows it).
Run from scenes/: python3 tools/fence.py"""
import base64, json, struct, zlib

W = H = 16
def texel(x, y):
    # y = 0 is the top row: a picket in columns 4-11 with a pointed top
    # (rows 0-2 narrower), two rails across (rows 4-5 and 10-11); the rest
    # clear
    top = {0: (7, 8), 1: (6, 9), 2: (5, 10)}
    lo, hi = top.get(y, (4, 11))
    picket = lo <= x <= hi
    rail = y in (4, 5, 10, 11)
    shade = 205 if x in (4, 11) else 235
    return (shade, shade - 10, shade - 35, 255) if picket or rail else (0, 0, 0, 0)

def png(w, h, px):
    raw = b''.join(b'\0' + bytes(c for x in range(w) for c in px(x, y)) for y in range(h))
    def chunk(t, d):
        return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 6, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))

# the quad: x in [-4, 4], y in [0, 1], facing +z; uv (0, 1) at the bottom left
pos = [-4, 0, 0, 4, 0, 0, 4, 1, 0, -4, 1, 0]
uv = [0, 1, 1, 1, 1, 0, 0, 0]
idx = [0, 1, 2, 0, 2, 3]
buf = struct.pack('<12f', *pos) + struct.pack('<8f', *uv) + struct.pack('<6H', *idx)
g = {
    "asset": {"version": "2.0", "generator": "rtsh scenes/tools/fence.py"},
    "extensionsUsed": ["KHR_texture_transform"],
    "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "fence"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
    "materials": [{"name": "pickets", "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": True,
                   "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.8,
                                            "baseColorTexture": {"index": 0, "extensions": {
                                                "KHR_texture_transform": {"scale": [8, 1]}}}}}],
    "textures": [{"source": 0, "sampler": 0}],
    "samplers": [{"magFilter": 9729, "wrapS": 10497, "wrapT": 33071}],
    "images": [{"mimeType": "image/png",
                "uri": "data:image/png;base64," + base64.b64encode(png(W, H, texel)).decode()}],
    "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
    "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-4, 0, 0], "max": [4, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
}
with open('models/fence/fence.gltf', 'w') as f:
    json.dump(g, f, indent=1)
    f.write('\n')
