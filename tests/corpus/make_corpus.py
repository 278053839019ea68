#!/usr/bin/env python3
"""Writes the malformed-input corpus (tests/corpus/): every file must make
`bundlebake bake` print exactly one error line, exit non-zero and write no
output (tests/gl/malformed_corpus_test.cpp). Deterministic; re-run after a
change and commit the files:  python3 tests/corpus/make_corpus.py

  gltf/*.gltf|*.glb     the scene argument         (also the fuzzer's seeds)
  texture/*.gltf        the scene argument; its broken images in texture/images/
  env/*                 --env FILE with the furnace scene
  checkpoint/*.bin      copied to OUTDIR/checkpoint.bin, then --resume (furnace,
                        asset layout, resolution 16)
"""
import base64, json, os, shutil, struct, subprocess, sys, tempfile, zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def furnace():
    d = json.load(open(os.path.join(ROOT, "assets/furnace/furnace.gltf")))
    raw = open(os.path.join(ROOT, "assets/furnace/furnace.bin"), "rb").read()
    return d, raw


def data_uri(raw, mime="application/octet-stream"):
    return "data:%s;base64,%s" % (mime, base64.b64encode(raw).decode())


def embedded(d, raw):
    d = json.loads(json.dumps(d))
    d["buffers"] = [{"byteLength": len(raw), "uri": data_uri(raw)}]
    return d


def glb(d, binary, version=2, json_length=None, total=None):
    d = json.loads(json.dumps(d))
    for b in d.get("buffers", []):
        b.pop("uri", None)
    j = json.dumps(d, separators=(",", ":")).encode()
    j += b" " * ((4 - len(j) % 4) % 4)
    body = struct.pack("<I4s", len(j) if json_length is None else json_length, b"JSON") + j
    if binary is not None:
        binary += b"\0" * ((4 - len(binary) % 4) % 4)
        body += struct.pack("<I4s", len(binary), b"BIN\0") + binary
    return b"glTF" + struct.pack("<II", version, 12 + len(body) if total is None else total) + body


def triangle(positions=(0, 0, 0, 1, 0, 0, 0, 1, 0), indices=None, mode=4, extra=None):
    """A one-triangle scene with every buffer inline, a material and light-map
    UVs (TEXCOORD_1), so that it bakes unless what `extra` breaks: accessor 0
    positions, 1 TEXCOORD_1, 2 indices (when given); bufferViews alike."""
    count = len(positions) // 3
    raw = struct.pack("<%df" % len(positions), *positions)
    uv = struct.pack("<%df" % (2 * count), *[c for i in range(count) for c in (0.1 + 0.8 * (i % 2), 0.1 + 0.8 * (i // 2))])
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(raw)},
             {"buffer": 0, "byteOffset": len(raw), "byteLength": len(uv)}]
    accessors = [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": count},
                 {"bufferView": 1, "componentType": 5126, "type": "VEC2", "count": count}]
    raw += uv
    prim = {"attributes": {"POSITION": 0, "TEXCOORD_1": 1}, "mode": mode, "material": 0}
    if indices is not None:
        ib = struct.pack("<%dH" % len(indices), *indices)
        ib += b"\0" * ((4 - len(ib) % 4) % 4)
        views.append({"buffer": 0, "byteOffset": len(raw), "byteLength": 2 * len(indices)})
        accessors.append({"bufferView": 2, "componentType": 5123, "type": "SCALAR", "count": len(indices)})
        prim["indices"] = 2
        raw += ib
    d = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"name": "tri", "mesh": 0}],
         "meshes": [{"name": "tri", "primitives": [prim]}], "accessors": accessors, "bufferViews": views,
         "materials": [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}}],
         "buffers": [{"byteLength": len(raw), "uri": data_uri(raw)}]}
    if extra:
        extra(d)
    return d


def png(w, h, rgba):
    rows = b"".join(b"\0" + bytes(rgba[y * w * 4:(y + 1) * w * 4]) for y in range(h))
    def chunk(t, b):
        return struct.pack(">I", len(b)) + t + b + struct.pack(">I", zlib.crc32(t + b) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def write(rel, content):
    path = os.path.join(HERE, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if isinstance(content, (dict, list)):
        content = json.dumps(content, separators=(",", ":"))
    if isinstance(content, str):
        content = content.encode()
    with open(path, "wb") as f:
        f.write(content)


def main():
    for kind in ("gltf", "texture", "env", "checkpoint"):
        shutil.rmtree(os.path.join(HERE, kind), ignore_errors=True)
    d, raw = furnace()
    good = embedded(d, raw)
    good_text = json.dumps(good, separators=(",", ":"))

    # --- glTF text ----------------------------------------------------------
    write("gltf/empty.gltf", b"")
    write("gltf/not_json.gltf", "this is not JSON {{{\n")
    write("gltf/truncated_json.gltf", good_text[: len(good_text) // 2])
    write("gltf/json_array_root.gltf", "[1, 2, 3]")
    write("gltf/binary_garbage.gltf", bytes((i * 37 + 11) % 256 for i in range(512)))
    g = json.loads(good_text); del g["asset"]; write("gltf/missing_asset.gltf", g)
    write("gltf/gltf_1_0.gltf", {"asset": {"version": "1.0"}, "scene": "s", "scenes": {"s": {"nodes": ["n"]}},
                                 "nodes": {"n": {"meshes": ["m"]}},
                                 "meshes": {"m": {"primitives": [{"attributes": {"POSITION": "p"}, "indices": "i"}]}}})
    g = json.loads(good_text); g["asset"]["version"] = "1.0"; write("gltf/version_1_0_with_2_0_body.gltf", g)
    g = json.loads(good_text); g["asset"]["version"] = "3.0"; write("gltf/version_3_0.gltf", g)
    g = json.loads(good_text); g["asset"]["minVersion"] = "2.1"; write("gltf/min_version_2_1.gltf", g)
    write("gltf/no_scene.gltf", {"asset": {"version": "2.0"}})
    g = json.loads(good_text); g["buffers"][0]["uri"] = "missing.bin"; write("gltf/buffer_file_missing.gltf", g)
    g = json.loads(good_text); g["buffers"][0]["uri"] = "data:application/octet-stream;base64,!!!not base64!!!"
    write("gltf/buffer_bad_base64.gltf", g)
    g = json.loads(good_text); g["buffers"][0]["byteLength"] = len(raw) * 4; write("gltf/buffer_length_lies.gltf", g)
    g = json.loads(good_text); g["bufferViews"][0]["byteOffset"] = 100000; write("gltf/bufferview_out_of_range.gltf", g)
    g = json.loads(good_text); g["accessors"][0]["count"] = 100000; write("gltf/accessor_count_too_large.gltf", g)
    g = json.loads(good_text); g["accessors"][0]["count"] = 4294967295; write("gltf/accessor_count_huge.gltf", g)
    g = json.loads(good_text); g["accessors"][0]["byteOffset"] = 4294967292; write("gltf/accessor_offset_huge.gltf", g)
    g = json.loads(good_text); g["accessors"][0]["componentType"] = 1234; write("gltf/accessor_bad_component_type.gltf", g)
    g = json.loads(good_text); g["accessors"][0]["type"] = "VEC2"; write("gltf/position_vec2.gltf", g)
    g = json.loads(good_text); g["bufferViews"][0]["byteStride"] = 4; write("gltf/stride_smaller_than_element.gltf", g)
    g = json.loads(good_text); g["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99
    write("gltf/position_accessor_missing.gltf", g)
    write("gltf/index_out_of_range.gltf", triangle(indices=[0, 1, 99]))
    write("gltf/nan_position.gltf", triangle(positions=(0, 0, 0, float("nan"), 0, 0, 0, 1, 0)))
    write("gltf/inf_position.gltf", triangle(positions=(0, 0, 0, float("inf"), 0, 0, 0, 1, 0)))
    write("gltf/node_cycle.gltf", triangle(extra=lambda d: d.update(nodes=[
        {"name": "a", "mesh": 0, "children": [1]}, {"name": "b", "children": [0]}])))
    write("gltf/node_own_child.gltf", triangle(extra=lambda d: d.update(nodes=[{"name": "a", "mesh": 0, "children": [0]}])))
    write("gltf/node_mesh_missing.gltf", triangle(extra=lambda d: d["nodes"][0].update(mesh=7)))
    write("gltf/node_child_missing.gltf", triangle(extra=lambda d: d["nodes"][0].update(children=[5])))
    write("gltf/scene_index_missing.gltf", triangle(extra=lambda d: d.update(scene=3)))
    write("gltf/material_missing.gltf", triangle(extra=lambda d: d["meshes"][0]["primitives"][0].update(material=4)))
    write("gltf/draco_required.gltf", triangle(extra=lambda d: d.update(
        extensionsUsed=["KHR_draco_mesh_compression"], extensionsRequired=["KHR_draco_mesh_compression"])))
    write("gltf/only_lines.gltf", triangle(positions=(0, 0, 0, 1, 0, 0), mode=1))
    write("gltf/only_degenerate.gltf", triangle(indices=[0, 0, 1]))
    # sparse: one index, 7, into a 3-vertex accessor
    def sparse(d):
        extra_bytes = struct.pack("<I", 7) + struct.pack("<3f", 5, 5, 5)
        buf = base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1])
        d["bufferViews"] += [{"buffer": 0, "byteOffset": len(buf), "byteLength": 4},
                             {"buffer": 0, "byteOffset": len(buf) + 4, "byteLength": 12}]
        buf += extra_bytes
        d["buffers"][0] = {"byteLength": len(buf), "uri": data_uri(buf)}
        n = len(d["bufferViews"])
        d["accessors"][0]["sparse"] = {"count": 1, "indices": {"bufferView": n - 2, "componentType": 5125},
                                       "values": {"bufferView": n - 1}}
    write("gltf/sparse_index_out_of_range.gltf", triangle(extra=sparse))
    # loads with a warning (no material), then the layout refuses it (no TEXCOORD_1, and the 400
    # separate triangles' generated charts do not fit a 16^2 page): the error line alone
    scattered = [c for i in range(400) for c in (3 * (i % 20), 3 * (i // 20), 0, 3 * (i % 20) + 1, 3 * (i // 20), 0,
                                                 3 * (i % 20), 3 * (i // 20) + 1, 0)]
    write("gltf/no_uv1_warning_first.gltf", triangle(positions=scattered, extra=lambda d: (
        d["meshes"][0]["primitives"][0].pop("material"), d["meshes"][0]["primitives"][0]["attributes"].pop("TEXCOORD_1"))))
    write("gltf/uv1_accessor_too_short.gltf", triangle(extra=lambda d: d["accessors"][1].update(count=2)))
    # --- glb ----------------------------------------------------------------
    good_glb = glb(d, raw)
    write("gltf/empty.glb", b"")
    write("gltf/header_only.glb", good_glb[:12])
    write("gltf/bad_magic.glb", b"glTX" + good_glb[4:])
    write("gltf/truncated.glb", good_glb[: len(good_glb) // 2])
    write("gltf/container_version_1.glb", glb(d, raw, version=1))
    write("gltf/json_chunk_length_lies.glb", glb(d, raw, json_length=0x00ffffff))
    write("gltf/json_chunk_not_json.glb", b"glTF" + struct.pack("<II", 2, 12 + 8 + 16) +
          struct.pack("<I4s", 16, b"JSON") + b"not json at all!")
    write("gltf/missing_bin_chunk.glb", glb(d, None))
    short = glb(d, raw[:64]); write("gltf/bin_chunk_too_short.glb", short)
    write("gltf/total_length_zero.glb", glb(d, raw, total=0))

    # --- textures: a used material's image that cannot be read or decoded --------
    def textured(uri):
        t = json.loads(good_text)
        t["images"] = [{"uri": uri}]
        t["textures"] = [{"source": 0}]
        t["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
        return t
    ok_png = png(2, 2, [255] * 16)
    write("texture/images/not_an_image.png", "this is not a PNG\n")
    write("texture/images/truncated.png", ok_png[: len(ok_png) // 2])
    write("texture/images/empty.png", b"")
    write("texture/images/bad_crc_header.png", ok_png[:16] + b"\xff\xff\xff\xff\xff\xff\xff\xff" + ok_png[24:])
    for name in ("not_an_image", "truncated", "empty", "bad_crc_header"):
        write("texture/%s.gltf" % name, textured("images/%s.png" % name))
    write("texture/missing_file.gltf", textured("images/no_such_image.png"))
    write("texture/data_uri_garbage.gltf", textured(data_uri(b"GIF89a garbage garbage", "image/png")))

    # --- environment maps (--env) ----------------------------------------------
    tmp = tempfile.mkdtemp()
    try:
        exr = os.path.join(tmp, "env.exr")
        subprocess.run(["oiiotool", "--nosoftwareattrib", "--pattern", "constant:color=1,1,1", "16x8", "3", "-d", "half", "-o", exr], check=True)
        exr_bytes = open(exr, "rb").read()
        # OpenEXR stamps capDate "YYYY:MM:DD hh:mm:ss": fix it, so the corpus is the same bytes each run
        at = exr_bytes.find(b"capDate\0string\0")
        if at >= 0:
            value = at + len(b"capDate\0string\0") + 4
            exr_bytes = exr_bytes[:value] + b"2000:01:01 00:00:00" + exr_bytes[value + 19:]
    finally:
        shutil.rmtree(tmp)
    write("env/empty.exr", b"")
    write("env/not_an_image.exr", "this is not an EXR\n")
    write("env/truncated.exr", exr_bytes[: len(exr_bytes) * 2 // 3])
    write("env/header_only.exr", exr_bytes[:64])
    write("env/empty.hdr", b"")
    write("env/header_only.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n")
    write("env/huge_dimensions.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1000000 +X 1000000\n" + "\x01" * 64)
    write("env/garbage.hdr", "#?RADIANCE\n" + "garbage " * 20)

    # --- checkpoints (--resume) ---------------------------------------------
    def header(magic=b"BBCKPT05", key=0, done=1, res=16, pages=1, scale=1.0):
        return magic + struct.pack("<Qiiiid", key, done, res, pages, 0, scale)
    maps = b"\0" * (16 * 16 * 20)                   # accumulators (8) + radiance (4) + noise half (8) per texel
    stats = struct.pack("<Q", 2) + b"{}"             # the statistics block: length, JSON
    write("checkpoint/empty.bin", b"")
    write("checkpoint/garbage.bin", bytes((i * 101 + 7) % 256 for i in range(4096)))
    write("checkpoint/short_header.bin", header()[:20])
    write("checkpoint/old_magic.bin", header(magic=b"BBCKPT04") + maps)
    write("checkpoint/other_resolution.bin", header(res=999) + maps + stats)
    write("checkpoint/truncated_payload.bin", header() + b"\0" * 100)
    write("checkpoint/other_scene_key.bin", header(key=0x0123456789abcdef) + maps + stats)
    write("checkpoint/trailing_bytes.bin", header() + maps + stats + b"\0" * 1000)
    print("corpus written under", HERE)


if __name__ == "__main__":
    main()
