# Opens one of gilt's outputs in Blender as a user would, reports what Blender holds, and renders
# the baked light so a person can look at it. Headless, CPU only:
#   blender -b --factory-startup --python scripts/blender_check.py -- MODEL OUT.png [SCALE]
# MODEL is .glb, .gltf, .ply or .obj. Prints one line per colour attribute:
#   gilt-check colour {"object": ..., "attribute": ..., "domain": ..., "type": ..., "count": N, "min": .., "mean": .., "max": ..}
# (Blender's linear values; the mean is over the attribute's elements), and per material that
# names a lightmap in its extras (glTF custom properties after import):
#   gilt-check lightmap {"material": ..., "image": ..., "uv": ..., "width": W, "height": H}
# Then every mesh is shown unlit, through an Emission shader, by its lightmap (Image Texture on
# the lightmap's UV map) where its material names one, else by its first colour attribute,
# times SCALE (default 1), and rendered with Cycles to OUT.png; the mean of the rendered
# pixels that show the model is printed as
#   gilt-check render {"covered": fraction of pixels, "mean": linear mean over them}
import json
import os
import sys

import numpy as np
np.bool = bool  # Debian 12's Blender 3.4 glTF importer still uses numpy.bool, removed in numpy 1.24
import bpy
import mathutils

args = sys.argv[sys.argv.index("--") + 1:]
model, out = args[0], args[1]
scale = float(args[2]) if len(args) > 2 else 1.0

bpy.ops.wm.read_factory_settings(use_empty=True)
ext = os.path.splitext(model)[1].lower()
if ext in (".glb", ".gltf"):
    bpy.ops.import_scene.gltf(filepath=model)
elif ext == ".ply":
    bpy.ops.import_mesh.ply(filepath=model)
    # PLY has no up axis. gilt writes y up, as glTF does and as MeshLab shows it; Blender's PLY
    # importer (unlike its glTF and OBJ importers) takes z as up and has no option to say
    # otherwise, so the model is turned +90 degrees about x, as a user would, to be seen the same.
    for o in bpy.context.selected_objects:
        o.rotation_euler = (1.5707963267948966, 0.0, 0.0)
elif ext == ".obj":
    bpy.ops.wm.obj_import(filepath=model)
else:
    sys.exit("blender_check: unknown format " + model)


def report(kind, record):
    print("gilt-check %s %s" % (kind, json.dumps(record)), flush=True)


meshes = [o for o in bpy.data.objects if o.type == "MESH"]
if not meshes:
    sys.exit("blender_check: no mesh in " + model)
first_colour = {}
for o in meshes:
    for a in o.data.color_attributes:
        values = np.zeros(len(a.data) * 4, dtype=np.float32)
        a.data.foreach_get("color", values)
        rgb = values.reshape(-1, 4)[:, :3]
        report("colour", {"object": o.name, "attribute": a.name, "domain": a.domain, "type": a.data_type,
                          "count": len(a.data), "min": float(rgb.min()) if len(rgb) else 0.0,
                          "mean": float(rgb.mean()) if len(rgb) else 0.0,
                          "max": float(rgb.max()) if len(rgb) else 0.0})
        first_colour.setdefault(o.name, a.name)


def lightmap_of(material):
    if material is None or "gilt_lightmap" not in material.keys():
        return None
    extras = material["gilt_lightmap"]
    folder = os.path.dirname(os.path.abspath(model))
    return os.path.join(folder, extras["uri"]), int(extras["texCoord"])


def emission_material(name, build_colour):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = scale
    links.new(build_colour(nodes, links), emission.inputs["Color"])
    links.new(emission.outputs["Emission"], output.inputs["Surface"])
    return mat


shown = 0
for o in meshes:
    lightmap = None
    for slot in o.material_slots:
        lightmap = lightmap or lightmap_of(slot.material)
    if lightmap is not None:
        path, tex_coord = lightmap
        if tex_coord >= len(o.data.uv_layers):
            sys.exit("blender_check: %s has no UV map %d for its lightmap" % (o.name, tex_coord))
        uv_name = o.data.uv_layers[tex_coord].name
        image = bpy.data.images.load(path, check_existing=True)
        report("lightmap", {"object": o.name, "image": os.path.basename(path), "uv": uv_name,
                            "width": image.size[0], "height": image.size[1]})

        def lightmap_colour(nodes, links, image=image, uv_name=uv_name):
            uv = nodes.new("ShaderNodeUVMap")
            uv.uv_map = uv_name
            texture = nodes.new("ShaderNodeTexImage")
            texture.image = image
            texture.interpolation = "Linear"
            links.new(uv.outputs["UV"], texture.inputs["Vector"])
            return texture.outputs["Color"]
        mat = emission_material("lightmap " + o.name, lightmap_colour)
    elif o.name in first_colour:
        def attribute_colour(nodes, links, name=first_colour[o.name]):
            colour = nodes.new("ShaderNodeVertexColor")
            colour.layer_name = name
            return colour.outputs["Color"]
        mat = emission_material("colours " + o.name, attribute_colour)
    else:
        continue
    o.data.materials.clear()
    o.data.materials.append(mat)
    shown += 1
if shown == 0:
    sys.exit("blender_check: nothing in %s holds baked light (no colour attribute, no lightmap)" % model)

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 4
scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
bpy.context.view_layer.cycles.use_denoising = False
scene.view_settings.view_transform = "Standard"
scene.render.resolution_x = scene.render.resolution_y = 256
scene.render.film_transparent = True
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
camera.data.clip_end = 1e6
scene.collection.objects.link(camera)
scene.camera = camera
bpy.context.view_layer.update()  # matrix_world after the PLY's turn
corners = [o.matrix_world @ mathutils.Vector(c) for o in meshes for c in o.bound_box]
lo = mathutils.Vector([min(c[i] for c in corners) for i in range(3)])
hi = mathutils.Vector([max(c[i] for c in corners) for i in range(3)])
target = (lo + hi) / 2
size = max((hi - lo).length, 1e-6)
camera.location = target + mathutils.Vector((0.6 * size, -1.4 * size, 0.9 * size))
camera.rotation_euler = (target - camera.location).to_track_quat("-Z", "Y").to_euler()
scene.render.image_settings.file_format = "PNG"
scene.render.filepath = out
bpy.ops.render.render(write_still=True)

rendered = bpy.data.images.load(out)
pixels = np.array(rendered.pixels[:], dtype=np.float32).reshape(-1, 4)
covered = pixels[:, 3] > 0.5
# PNG holds display values (Standard view: sRGB); the mean is taken back to linear.
srgb = pixels[covered, :3]
linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
report("render", {"covered": float(covered.mean()), "mean": float(linear.mean()) if covered.any() else 0.0})
