#!/usr/bin/env python3
"""Builds the seed corpora of the fuzz targets (tests/fuzz/*.cpp) into OUT/<target>/.

Usage: seeds.py SOURCE_DIR SHARED_MODELS_DIR OUT

  gltf_fuzz:  every .glb / .gltf under SHARED_MODELS_DIR and SOURCE_DIR/models; each .glb also as
              a .gltf (JSON): with its binary chunk as a base64 data URI when the file is at most
              1 MB, else the JSON alone (its buffer then has no data: an error case, still a seed);
              GLBs up to 256 KB without textures also with a tiny PNG base-colour texture added;
              three small hand-made .gltf documents (minimal_gltfs).
  image_fuzz: SOURCE_DIR/patterns/*.png, the images embedded in those glTF files (PNG and JPEG
              textures), tiny PNGs (grey 8/16-bit, grey+alpha, RGB, RGBA) and tiny BMP and TGA
              images made here.
  scene_fuzz: SOURCE_DIR/examples/*.json and SOURCE_DIR/models/*.scene.json.
Plus tests/fuzz/regressions/<target>/* (inputs that once found a bug) for each target.

Copies only; never writes into the source tree or the shared models. Files are named by the
SHA-1 of their content (as libFuzzer names its own), so running it again adds nothing twice.
"""
import base64
import glob
import hashlib
import json
import os
import struct
import sys
import zlib


def put(out, target, data):
    folder = os.path.join(out, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, hashlib.sha1(data).hexdigest()), "wb") as f:
        f.write(data)


def glb_parts(data):
    """(json dict, bin bytes or b"") of a GLB, or None when it is not one."""
    if len(data) < 20 or data[:4] != b"glTF":
        return None
    off, doc, binary = 12, None, b""
    while off + 8 <= len(data):
        length, kind = struct.unpack_from("<II", data, off)
        chunk = data[off + 8 : off + 8 + length]
        if kind == 0x4E4F534A:
            doc = json.loads(chunk.decode("utf-8"))
        elif kind == 0x004E4942:
            binary = chunk
        off += 8 + length
    return (doc, binary) if doc is not None else None


def gltf_seeds(out, paths):
    for path in paths:
        with open(path, "rb") as f:
            data = f.read()
        put(out, "gltf_fuzz", data)
        parts = glb_parts(data)
        if not parts:
            continue
        doc, binary = parts
        # Small models without a texture: also with a tiny PNG one (the decode and downscale path).
        if len(data) <= (256 << 10) and not doc.get("images") and doc.get("buffers"):
            for image in tiny_pngs()[2:]:
                put(out, "gltf_fuzz", textured_glb(doc, binary, image))
        # Embedded images: image seeds.
        for image in doc.get("images", []):
            view = image.get("bufferView")
            if view is None:
                continue
            bv = doc["bufferViews"][view]
            start = bv.get("byteOffset", 0)
            put(out, "image_fuzz", binary[start : start + bv["byteLength"]])
        # The same model as .gltf JSON.
        if doc.get("buffers") and len(data) <= (1 << 20):
            doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(
                binary
            ).decode("ascii")
        put(out, "gltf_fuzz", json.dumps(doc).encode("utf-8"))


def png(width, height, depth, colour, pixels):
    """A PNG of raw scanline bytes `pixels` (filter byte 0 added per row)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    row = len(pixels) // height
    raw = b"".join(b"\x00" + pixels[r * row : (r + 1) * row] for r in range(height))
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def tiny_pngs():
    """Small PNGs of the kinds patterns and textures come in: grey 8/16-bit, grey+alpha, RGB, RGBA."""
    n = 8
    ramp = bytes((x * 32 + y * 4) & 0xFF for y in range(n) for x in range(n))
    return [
        png(n, n, 8, 0, ramp),
        png(n, n, 16, 0, b"".join(struct.pack(">H", v * 257) for v in ramp)),
        png(n, n, 8, 4, b"".join(bytes([v, 255 - v]) for v in ramp)),
        png(n, n, 8, 2, b"".join(bytes([v, 128, 255 - v]) for v in ramp)),
        png(n, n, 8, 6, b"".join(bytes([v, 128, 255 - v, 200]) for v in ramp)),
    ]


def textured_glb(doc, binary, image):
    """`doc`/`binary` of a GLB with `image` (PNG bytes) added as the first material's base-colour
    texture (a material is added when there is none), as GLB bytes."""
    doc = json.loads(json.dumps(doc))
    pad = (-len(binary)) % 4
    offset = len(binary) + pad
    binary = binary + b"\x00" * pad + image + b"\x00" * ((-len(image)) % 4)
    doc["buffers"][0]["byteLength"] = len(binary)
    doc.setdefault("bufferViews", []).append({"buffer": 0, "byteOffset": offset, "byteLength": len(image)})
    doc["images"] = [{"bufferView": len(doc["bufferViews"]) - 1, "mimeType": "image/png"}]
    doc["textures"] = [{"source": 0}]
    if not doc.get("materials"):
        doc["materials"] = [{}]
        for mesh in doc.get("meshes", []):
            for prim in mesh.get("primitives", []):
                prim["material"] = 0
    doc["materials"][0].setdefault("pbrMetallicRoughness", {})["baseColorTexture"] = {"index": 0}
    text = json.dumps(doc).encode("utf-8")
    text += b" " * ((-len(text)) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def minimal_gltfs():
    """Small hand-made .gltf documents (fast to mutate): a triangle with its buffer as a data URI,
    the same reading gltf_fuzz's companion file "b.bin" (1 KiB of counting bytes) as indices,
    positions and a two-key animation, and a two-joint skinned triangle."""
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    base = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(pos).decode("ascii")}],
    }
    external = json.loads(json.dumps(base))
    external["buffers"] = [{"byteLength": 1024, "uri": "b.bin"}]
    external["bufferViews"] = [{"buffer": 0, "byteOffset": 0, "byteLength": 3},
                               {"buffer": 0, "byteOffset": 8, "byteLength": 36}]
    external["accessors"] = [{"bufferView": 1, "componentType": 5121, "count": 3, "type": "VEC3",
                              "normalized": True},
                             {"bufferView": 0, "componentType": 5121, "count": 3, "type": "SCALAR"},
                             {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR"},
                             {"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"}]
    external["meshes"][0]["primitives"][0] = {"attributes": {"POSITION": 0}, "indices": 1}
    external["extensionsUsed"] = ["KHR_mesh_quantization"]
    external["animations"] = [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                               "samplers": [{"input": 2, "output": 3, "interpolation": "STEP"}]}]
    skinned = json.loads(json.dumps(base))
    data = pos + struct.pack("<12B", 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0)
    data += struct.pack("<12f", 1, 0, 0, 0, 0.5, 0.5, 0, 0, 0, 1, 0, 0)
    skinned["buffers"] = [{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                           + base64.b64encode(data).decode("ascii")}]
    skinned["bufferViews"] = [{"buffer": 0, "byteLength": 36},
                              {"buffer": 0, "byteOffset": 36, "byteLength": 12},
                              {"buffer": 0, "byteOffset": 48, "byteLength": 48}]
    skinned["accessors"] += [{"bufferView": 1, "componentType": 5121, "count": 3, "type": "VEC4"},
                             {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"}]
    skinned["meshes"][0]["primitives"][0]["attributes"].update({"JOINTS_0": 1, "WEIGHTS_0": 2})
    skinned["nodes"] = [{"mesh": 0, "skin": 0}, {"children": [2], "translation": [0, 1, 0]},
                        {"rotation": [0, 0, 0.7071068, 0.7071068]}]
    skinned["scenes"] = [{"nodes": [0, 1]}]
    skinned["skins"] = [{"joints": [1, 2]}]
    return [json.dumps(d).encode("utf-8") for d in (base, external, skinned)]


def tiny_images(out):
    for image in tiny_pngs():
        put(out, "image_fuzz", image)
    # 2×2 24-bit BMP (rows padded to 4 bytes).
    rows = (b"\x00\x80\xff" * 2 + b"\x00\x00") * 2
    bmp = b"BM" + struct.pack("<IHHI", 54 + len(rows), 0, 0, 54)
    bmp += struct.pack("<IiiHHIIiiII", 40, 2, 2, 1, 24, 0, len(rows), 2835, 2835, 0, 0) + rows
    put(out, "image_fuzz", bmp)
    # 2×2 8-bit grey TGA (uncompressed) and RLE.
    head = struct.pack("<BBBHHBHHHHBB", 0, 0, 3, 0, 0, 0, 0, 0, 2, 2, 8, 0)
    put(out, "image_fuzz", head + bytes([0, 64, 128, 255]))
    rle = struct.pack("<BBBHHBHHHHBB", 0, 0, 11, 0, 0, 0, 0, 0, 2, 2, 8, 0)
    put(out, "image_fuzz", rle + bytes([0x83, 200]))


def main():
    source, shared, out = sys.argv[1:4]
    models = sorted(
        glob.glob(os.path.join(shared, "**", "*.glb"), recursive=True)
        + glob.glob(os.path.join(shared, "**", "*.gltf"), recursive=True)
        + glob.glob(os.path.join(source, "models", "*.glb"))
    )
    gltf_seeds(out, models)
    for doc in minimal_gltfs():
        put(out, "gltf_fuzz", doc)
    for png in sorted(glob.glob(os.path.join(source, "patterns", "*.png"))):
        with open(png, "rb") as f:
            put(out, "image_fuzz", f.read())
    tiny_images(out)
    scenes = glob.glob(os.path.join(source, "examples", "*.json")) + glob.glob(
        os.path.join(source, "models", "*.scene.json")
    )
    for scene in sorted(scenes):
        with open(scene, "rb") as f:
            put(out, "scene_fuzz", f.read())
    for target in ("gltf_fuzz", "image_fuzz", "scene_fuzz"):
        for path in sorted(glob.glob(os.path.join(source, "tests", "fuzz", "regressions", target, "*"))):
            with open(path, "rb") as f:
                put(out, target, f.read())
    for target in ("gltf_fuzz", "image_fuzz", "scene_fuzz"):
        n = len(os.listdir(os.path.join(out, target)))
        print(f"seeds.py: {target}: {n} inputs in {os.path.join(out, target)}")


if __name__ == "__main__":
    main()
