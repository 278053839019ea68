"""Blender Cycles as a second, independent ruler for bundlebake's light maps.

Bakes L_lm = E/pi (DESIGN.md, Units) of a glTF scene with Cycles, into one float
EXR per light-map page in bundlebake's texel order, so that
`bundlebake compare CYCLES.exr REFERENCE_DIR` reads it directly.

Usage (Blender 3.4 from Debian 12: `apt-get install -y blender`):
  blender -b -noaudio --factory-startup --python bench/cycles_bake.py -- \
      SCENE.gltf OUT.exr [--resolution 64] [--samples 1024] [--sky r,g,b] \
      [--uv-layout asset] [--supersample 8] [--bounces 128] [--margin 2] [--threads 2]
  --samples is per sub-texel: a texel gets samples * S^2 paths.

What it does:
  1. imports the glTF (restoring numpy.bool first: Blender 3.4's importer still
     calls np.bool, which Debian 12's numpy 1.24 removed);
  2. rebuilds every material as a pure Lambertian: Diffuse BSDF (the importer's
     base colour graph: factor, texture, vertex colour) + Emission (emissive
     factor, texture, KHR_materials_emissive_strength). Blender 3.4's Principled
     BSDF is not Lambertian (+4.7 % in a rho 0.9 furnace). The back of a
     single-sided face (glTF doubleSided false) is opaque black, as in
     bundlebake: no reflection and no emission (Cycles' emission is two-sided,
     which would light the ceiling just above the Cornell box's light quad);
  3. sets the world to the uniform sky colour (black without --sky);
  4. bakes DIFFUSE with pass filter DIRECT + INDIRECT and no COLOR, which stores
     (diffuse light) / albedo = E/pi, on the UV map of TEXCOORD_1 ('UVMap.001' as
     the importer names it), into a float image with Non-Color (raw) colour
     space, so no colour management touches the values. All meshes are joined
     into one object first: Blender bakes selected objects one by one and dilates
     the margin after each, so a later object's margin overwrote earlier charts
     (the Cornell box's light quad over the red wall: 36 % rel_rmse before);
  5. supersampling (--supersample S, default 8): Cycles does not average a texel
     over its footprint. Blender passes half the barycentric derivative per texel
     (bake_differentials: A = 0.5 / area2), so Cycles jitters each sample over a
     box half a texel wide at the centre, mirrored back into the centre's
     triangle. bundlebake's reference stores the mean over the whole footprint
     clipped to the chart. So this bakes at R*S and averages the baked sub-texels
     (alpha 1) of each texel, then fills --margin rings of empty texels with
     their neighbours' mean. S = 1 is Cycles' own texel (with Blender's margin);
  6. writes OUT.exr (RGB float, row 0 = glTF v = 0, bundlebake's row order:
     checked with `bundlebake compare` against `bundlebake reference`), and
     OUT.json with the settings and the bake's wall time.

Cycles settings: CPU, --threads threads, --samples samples per sub-texel, no
denoising, no clamping, no caustic filter, --bounces diffuse bounces (the
furnace at rho 0.9 loses 0.9^(k+1) of its answer after k bounces: 0.1 % at 64,
1e-6 at 128; Russian roulette keeps deep paths cheap).

Layouts: only `asset` (TEXCOORD_1 as is, one page). bundlebake's `pack` and
`generate` layouts remap UVs inside bundlebake; bake those with bundlebake's own
UVs exported first (not done here).

Albedo 0: Cycles divides the diffuse light by the albedo and returns 0 where
the albedo is 0 (the open box is black), so every base colour is raised to at
least --min-albedo (1e-4): the extra light it reflects is below 1e-4 relative.
"""
import argparse
import json
import os
import sys
import time

import numpy

# Blender 3.4's glTF importer uses np.bool (removed in numpy 1.24, Debian 12).
if "bool" not in numpy.__dict__:
    try:
        numpy.bool = bool
    except Exception:
        pass

import bpy  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="cycles_bake.py", description=__doc__.split("\n")[0])
    p.add_argument("scene")
    p.add_argument("out", help="output EXR (RGB float)")
    p.add_argument("--resolution", type=int, default=64)
    p.add_argument("--samples", type=int, default=1024)
    p.add_argument("--sky", default=None, help="uniform sky radiance r,g,b (default: black)")
    p.add_argument("--uv-layout", default="asset", choices=["asset"])
    p.add_argument("--bounces", type=int, default=128, help="max diffuse (and total) bounces")
    p.add_argument("--margin", type=int, default=2,
                   help="texels of dilation around each chart (charts of the asset scenes are >= 2.24 texels apart at 64^2)")
    p.add_argument("--margin-type", default="EXTEND", choices=["EXTEND", "ADJACENT_FACES"])
    p.add_argument("--supersample", type=int, default=8,
                   help="bake at resolution x S and average the baked sub-texels of each texel (see the notes)")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--min-albedo", type=float, default=1e-4)
    p.add_argument("--no-emitter-sampling", action="store_true",
                   help="emissive materials are found by BSDF sampling only (material 'Multiple Importance' off)")
    p.add_argument("--no-backface-black", action="store_true",
                   help="keep Cycles' two-sided surfaces (for finding out what the black back faces change)")
    return p.parse_args(argv)


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.images, bpy.data.lights, bpy.data.cameras):
        for item in list(coll):
            coll.remove(item)


def relink(links, src_socket, dst_socket):
    """Move whatever feeds src_socket (a link or a default value) onto dst_socket."""
    if src_socket.is_linked:
        links.new(src_socket.links[0].from_socket, dst_socket)
    else:
        dst_socket.default_value = src_socket.default_value


def lambertian(mat, bake_image, min_albedo, backface_black):
    """Replace the importer's Principled BSDF by Diffuse + Emission; add the bake target node."""
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    out = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    pbr = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)

    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambert (Oren-Nayar off)
    emission = nodes.new("ShaderNodeEmission")
    floor = nodes.new("ShaderNodeMix")  # max(base colour, min_albedo) per channel
    floor.data_type = "RGBA"
    floor.blend_type = "LIGHTEN"
    floor.inputs["Factor"].default_value = 1.0
    floor.inputs[7].default_value = (min_albedo, min_albedo, min_albedo, 1.0)
    links.new(floor.outputs[2], diffuse.inputs["Color"])
    if pbr is not None:
        relink(links, pbr.inputs["Base Color"], floor.inputs[6])
        relink(links, pbr.inputs["Emission"], emission.inputs["Color"])
        relink(links, pbr.inputs["Emission Strength"], emission.inputs["Strength"])
        nodes.remove(pbr)
    else:  # a material the importer made without Principled (e.g. KHR_materials_unlit): white, no emission
        floor.inputs[6].default_value = (1, 1, 1, 1)
        emission.inputs["Strength"].default_value = 0.0
    add = nodes.new("ShaderNodeAddShader")
    links.new(diffuse.outputs[0], add.inputs[0])
    links.new(emission.outputs[0], add.inputs[1])
    surface = add.outputs[0]
    # the importer sets use_backface_culling = not doubleSided
    if backface_black and mat.use_backface_culling:
        geometry = nodes.new("ShaderNodeNewGeometry")
        black = nodes.new("ShaderNodeBsdfDiffuse")
        black.inputs["Color"].default_value = (0, 0, 0, 1)
        mix = nodes.new("ShaderNodeMixShader")
        links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
        links.new(surface, mix.inputs[1])
        links.new(black.outputs[0], mix.inputs[2])
        surface = mix.outputs[0]
    links.new(surface, out.inputs["Surface"])
    for sock in ("Volume", "Displacement"):
        for link in list(out.inputs[sock].links):
            links.remove(link)

    target = nodes.new("ShaderNodeTexImage")
    target.image = bake_image
    target.interpolation = "Closest"
    for n in nodes:
        n.select = False
    target.select = True
    nodes.active = target


def main():
    args = parse_args()
    t_start = time.monotonic()
    clear_scene()
    bpy.ops.import_scene.gltf(filepath=os.path.abspath(args.scene))
    scene = bpy.context.scene
    meshes = [o for o in scene.objects if o.type == "MESH"]
    if not meshes:
        raise SystemExit("cycles_bake: no meshes in " + args.scene)
    for o in meshes:
        if len(o.data.uv_layers) < 2:
            raise SystemExit("cycles_bake: mesh %s has no TEXCOORD_1" % o.name)
    # the importer's lights (KHR_lights_punctual) are left as they are; the bench scenes have none
    lights = [o.name for o in scene.objects if o.type == "LIGHT"]

    # the bake target: one float page, raw values
    res = args.resolution
    ss = args.supersample
    bake_res = res * ss
    # alpha: 1 where a texel centre lies on a triangle (baked), 0 elsewhere (cleared, no margin when ss > 1)
    image = bpy.data.images.new("lightmap_0", bake_res, bake_res, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    image.generated_color = (0, 0, 0, 0)

    mats = set()
    for o in meshes:
        for slot in o.material_slots:
            if slot.material is None:
                slot.material = bpy.data.materials.new("default")
            mats.add(slot.material)
        if not o.material_slots:
            o.data.materials.append(bpy.data.materials.new("default"))
            mats.add(o.material_slots[0].material)
    for m in mats:
        lambertian(m, image, args.min_albedo, not args.no_backface_black)
        m.cycles.sample_as_light = not args.no_emitter_sampling

    # world: uniform sky or black
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    for link in list(bg.inputs["Color"].links):
        world.node_tree.links.remove(link)
    if args.sky:
        r, g, b = (float(x) for x in args.sky.split(","))
        bg.inputs["Color"].default_value = (r, g, b, 1.0)
        bg.inputs["Strength"].default_value = 1.0
    else:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
        bg.inputs["Strength"].default_value = 0.0

    # Cycles: CPU, fixed threads, converged, unbiased
    scene.render.engine = "CYCLES"
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = args.samples
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.seed = args.seed
    cy.max_bounces = args.bounces
    cy.diffuse_bounces = args.bounces
    cy.glossy_bounces = 0
    cy.transmission_bounces = 0
    cy.volume_bounces = 0
    cy.transparent_max_bounces = 8
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.caustics_reflective = True
    cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    scene.view_settings.view_transform = "Standard"  # not used by the bake; recorded for clarity
    scene.view_settings.look = "None"
    scene.render.bake.margin = args.margin
    scene.render.bake.margin_type = args.margin_type

    # one object: Blender bakes the selected objects one after another into the image and dilates
    # after each, so one object's margin overwrites texels of charts baked before it (seen on the
    # Cornell box: the light's margin over the red wall); joined, there is one bake and one margin
    bpy.ops.object.select_all(action="DESELECT")
    for o in meshes:
        o.select_set(True)
    bpy.context.view_layer.objects.active = meshes[0]
    if len(meshes) > 1:
        bpy.ops.object.join()
    margin = args.margin if ss == 1 else 0
    t0 = time.monotonic()
    bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT", "INDIRECT"}, margin=margin,
                        margin_type=args.margin_type, use_clear=True, uv_layer="UVMap.001",
                        target="IMAGE_TEXTURES", save_mode="INTERNAL")
    bake_seconds = time.monotonic() - t0

    # pixels: Blender's row 0 is its v = 0, i.e. glTF v = 1 (the importer stores v' = 1 - v);
    # bundlebake's row 0 is glTF v = 0, so flip rows
    px = numpy.empty(bake_res * bake_res * 4, dtype=numpy.float32)
    image.pixels.foreach_get(px)
    px = px.reshape(bake_res, bake_res, 4)[::-1]
    if ss > 1:
        px = downsample(px, ss, args.margin)
    else:
        px = px[..., :3]
    out_exr = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(out_exr), exist_ok=True)
    write_exr(px, out_exr)

    info = {
        "scene": os.path.abspath(args.scene), "out": out_exr, "resolution": res, "samples": args.samples,
        "sky": args.sky, "uv_layout": args.uv_layout, "bounces": args.bounces, "margin": args.margin,
        "margin_type": args.margin_type, "threads": args.threads, "seed": args.seed,
        "min_albedo": args.min_albedo, "supersample": ss,
        "emitter_sampling": not args.no_emitter_sampling, "backface_black": not args.no_backface_black,
        "materials": sorted(m.name for m in mats), "meshes": len(meshes), "lights_ignored": lights,
        "blender": bpy.app.version_string, "seconds": {"bake": bake_seconds, "total": time.monotonic() - t_start},
        "mean": [float(px[..., c].mean()) for c in range(3)],
    }
    with open(os.path.splitext(out_exr)[0] + ".json", "w") as f:
        json.dump(info, f, indent=1)
    print("cycles_bake: %s: %dx%d, %d samples, bake %.1f s" % (out_exr, res, res, args.samples, bake_seconds))


def downsample(rgba, ss, margin):
    """Mean of the baked sub-texels (alpha 1) of each ss x ss block: the texel's footprint clipped to
    the charts, as bundlebake's reference defines a texel; then `margin` rings of empty texels get the
    mean of their filled 8-neighbours."""
    h, w = rgba.shape[0] // ss, rgba.shape[1] // ss
    a = (rgba[..., 3] > 0.5).astype(numpy.float64)
    blocks = (rgba[..., :3] * a[..., None]).reshape(h, ss, w, ss, 3).sum(axis=(1, 3))
    weight = a.reshape(h, ss, w, ss).sum(axis=(1, 3))
    rgb = numpy.zeros((h, w, 3))
    filled = weight > 0
    rgb[filled] = blocks[filled] / weight[filled][:, None]
    for _ in range(margin):
        acc = numpy.zeros_like(rgb)
        cnt = numpy.zeros((h, w))
        pad_rgb = numpy.pad(rgb, ((1, 1), (1, 1), (0, 0)))
        pad_f = numpy.pad(filled, 1).astype(numpy.float64)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                if dy or dx:
                    acc += pad_rgb[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] * pad_f[1 + dy:1 + dy + h, 1 + dx:1 + dx + w, None]
                    cnt += pad_f[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
        grow = (~filled) & (cnt > 0)
        rgb[grow] = acc[grow] / cnt[grow][:, None]
        filled = filled | grow
    return rgb.astype(numpy.float32)


def write_exr(rgb, path):
    """Write rows top to bottom as given (rgb[0] is the file's first row), RGB 32-bit float."""
    res_y, res_x = rgb.shape[:2]
    img = bpy.data.images.new("out", res_x, res_y, alpha=True, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    rgba = numpy.ones((res_y, res_x, 4), dtype=numpy.float32)
    rgba[..., :3] = rgb
    # Blender images are stored bottom row first; the file is written top row first
    img.pixels.foreach_set(rgba[::-1].ravel())
    scene = bpy.context.scene
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGB"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    img.save_render(path, scene=scene)
    bpy.data.images.remove(img)


if __name__ == "__main__":
    main()
