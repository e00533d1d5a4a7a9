#!/usr/bin/env python3
"""Builds the seed corpora of the fuzz targets (tests/fuzz/*.cpp) into OUT/<target>/.

Usage: seeds.py SOURCE_DIR SHARED_MODELS_DIR OUT

  gltf_fuzz:  every .glb / .gltf under SHARED_MODELS_DIR and SOURCE_DIR/models; each .glb also as
              a .gltf (JSON): with its binary chunk as a base64 data URI when the file is at most
              1 MB, else the JSON alone (its buffer then has no data: an error case, still a seed).
  image_fuzz: SOURCE_DIR/patterns/*.png, the images embedded in those glTF files (PNG and JPEG
              textures), and tiny hand-made BMP and TGA images.
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


def tiny_images(out):
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
