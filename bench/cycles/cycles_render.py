# Renders a gilt JSON wrapper (glTF meshes, a directional light, a uniform environment, a camera)
# with Blender Cycles, for comparison with gilt's path tracer.
#
#   blender -b --factory-startup -P cycles_render.py -- WRAPPER.json OUT.exr SPP WIDTH HEIGHT \
#       [--threads N] [--seed S] [--distribution import|GGX|MULTI_GGX] [--bounces B]
#
# The same wrapper file drives both renderers, so geometry, lights and camera cannot drift apart:
#   meshes[].file        glTF files, imported with Blender's own importer (Principled BSDFs); a
#                        material with metallic 0 and KHR_materials_specular's specularFactor 0, which
#                        gilt reads as exactly Lambertian, gets a Diffuse BSDF (roughness 0) instead.
#                        Glass (KHR_materials_transmission): the Principled BSDF's Transmission; its
#                        Roughness is checked against the glTF roughnessFactor (and set if the importer
#                        did not), and the Volume Absorption of density 0 the importer attaches for
#                        KHR_materials_volume without attenuation is removed (it absorbs nothing; in
#                        Cycles a closed mesh with a refracting BSDF is a solid either way)
#   lights[] directional a delta sun: angle 0, strength = irradiance (W/m^2), shining along `direction`
#   lights[] environment the world: Background colour = radiance, strength 1
#   camera               look_from / look_at / up / vfov (vertical, degrees)
# glTF is +Y up and the importer turns a point (x, y, z) into Blender's (x, -z, y); every point and
# direction taken from the wrapper goes through the same map.
#
# Cycles is set up as an unbiased reference: CPU, no denoising, no clamping, light threshold 0, no
# adaptive sampling, no glossy filter, many bounces, linear float output (Standard view, no look).
# The pixel filter is gilt's default: a Gaussian of sigma = 0.5 px (gilt: truncated at 1.5 px; Cycles'
# "Gaussian" of width w has sigma = w / 4, so w = 2). The film is transparent: RGB of pixels that see
# the background is 0 and alpha is the geometry's coverage; the comparison adds the background back.
# Prints MATERIAL lines (what the importer made) and RENDER_SECONDS.
import json
import math
import os
import sys
import time

import numpy as np
if not hasattr(np, "bool"):   # Blender 3.4's glTF importer still uses np.bool (gone since numpy 1.24)
    np.bool = bool
import bpy
import mathutils

args = sys.argv[sys.argv.index("--") + 1:]
wrapper_path, out_path = os.path.abspath(args[0]), os.path.abspath(args[1])
spp, width, height = int(args[2]), int(args[3]), int(args[4])
opts = {"--threads": "2", "--seed": "0", "--distribution": "import", "--bounces": "128"}
rest = args[5:]
while rest:
    key, value, rest = rest[0], rest[1], rest[2:]
    if key not in opts:
        sys.exit("cycles_render.py: unknown option " + key)
    opts[key] = value

wrapper = json.load(open(wrapper_path))
folder = os.path.dirname(wrapper_path)


def to_blender(v):
    """glTF (+Y up) point or direction to Blender (+Z up), as the glTF importer maps them."""
    return mathutils.Vector((v[0], -v[2], v[1]))


bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

# Geometry and materials: Blender's glTF importer, nothing changed but (optionally) the
# Principled BSDF's microfacet distribution, the Lambertian ground and the glass's checks (above).
lambertian = set()   # names of the glTF materials gilt makes diffuse
glass = {}           # name of a glTF material with transmission > 0.5 (gilt's dielectric): its roughness
for mesh in wrapper["meshes"]:
    if set(mesh) != {"file"}:
        sys.exit("cycles_render.py: only plain {\"file\": ...} meshes are supported")
    path = os.path.join(folder, mesh["file"])
    if path.endswith(".gltf"):
        for gm in json.load(open(path)).get("materials", []):
            pbr = gm.get("pbrMetallicRoughness", {})
            spec = gm.get("extensions", {}).get("KHR_materials_specular", {}).get("specularFactor", 1.0)
            if pbr.get("metallicFactor", 1.0) == 0 and spec == 0 and "name" in gm:
                lambertian.add(gm["name"])
            transmission = gm.get("extensions", {}).get("KHR_materials_transmission", {})
            if transmission.get("transmissionFactor", 0.0) > 0.5 and "name" in gm:
                glass[gm["name"]] = pbr.get("roughnessFactor", 1.0)
    bpy.ops.import_scene.gltf(filepath=path)
for mat in bpy.data.materials:
    if not mat.use_nodes:
        continue
    if mat.name in lambertian:
        nodes = mat.node_tree.nodes
        p = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
        out = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
        d = nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Roughness"].default_value = 0.0
        if p.inputs["Base Color"].is_linked:
            mat.node_tree.links.new(p.inputs["Base Color"].links[0].from_socket, d.inputs["Color"])
        else:
            d.inputs["Color"].default_value = p.inputs["Base Color"].default_value
        mat.node_tree.links.new(d.outputs["BSDF"], out.inputs["Surface"])
        nodes.remove(p)
        print("MATERIAL %s: Lambertian Diffuse BSDF (glTF specularFactor 0), base %.3f,%.3f,%.3f" %
              ((mat.name,) + tuple(d.inputs["Color"].default_value[:3])))
        continue
    for node in mat.node_tree.nodes:
        if node.type == "TEX_IMAGE" and node.image:
            print("TEXTURE %s: %s, colour space %s, interpolation %s, extension %s" %
                  (mat.name, node.image.name, node.image.colorspace_settings.name, node.interpolation, node.extension))
        if node.type != "BSDF_PRINCIPLED":
            continue
        imported = node.distribution
        if opts["--distribution"] != "import":
            node.distribution = opts["--distribution"]
        inp = node.inputs
        if mat.name in glass:
            r = glass[mat.name]
            if abs(inp["Roughness"].default_value - r) > 1e-6 and not inp["Roughness"].is_linked:
                print("MATERIAL %s: the importer gave roughness %.3f for the glTF's %.3f; set to %.3f" %
                      (mat.name, inp["Roughness"].default_value, r, r))
                inp["Roughness"].default_value = r
            out = next(n for n in mat.node_tree.nodes if n.type == "OUTPUT_MATERIAL")
            for link in list(out.inputs["Volume"].links):
                v = link.from_node
                if v.type == "VOLUME_ABSORPTION" and v.inputs["Density"].default_value == 0 and \
                        not v.inputs["Density"].is_linked:
                    mat.node_tree.nodes.remove(v)
                    print("MATERIAL %s: removed the importer's Volume Absorption of density 0 (absorbs nothing)" %
                          mat.name)
            print("MATERIAL %s: transmission %.3f, transmission_roughness %.3f, volume %s" %
                  (mat.name, inp["Transmission"].default_value, inp["Transmission Roughness"].default_value,
                   "linked" if out.inputs["Volume"].is_linked else "none"))
        base = "texture" if inp["Base Color"].is_linked else "%.3f,%.3f,%.3f" % tuple(inp["Base Color"].default_value[:3])
        print("MATERIAL %s: distribution %s (imported %s), base %s, metallic %.3f, roughness %.3f, specular %.3f, "
              "specular_tint %.3f, sheen %.3f, clearcoat %.3f, ior %.3f" %
              (mat.name, node.distribution, imported, base, inp["Metallic"].default_value,
               inp["Roughness"].default_value, inp["Specular"].default_value, inp["Specular Tint"].default_value,
               inp["Sheen"].default_value, inp["Clearcoat"].default_value, inp["IOR"].default_value))

# Lights.
for light in wrapper.get("lights", []):
    if light["type"] == "directional":
        e = light["irradiance"]
        if isinstance(e, list):
            sys.exit("cycles_render.py: give a directional light's irradiance as one number")
        sun = bpy.data.lights.new("sun", "SUN")
        sun.energy, sun.angle = float(e), 0.0
        sun_obj = bpy.data.objects.new("sun", sun)
        scene.collection.objects.link(sun_obj)
        # A sun shines down its local -Z: point -Z along the direction the light travels.
        sun_obj.rotation_euler = to_blender(light["direction"]).normalized().to_track_quat("-Z", "Y").to_euler()
    elif light["type"] == "environment":
        L = light["radiance"]
        L = [L] * 3 if not isinstance(L, list) else L
        world = bpy.data.worlds.new("world")
        world.use_nodes = True
        bg = world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (*L, 1.0)
        bg.inputs["Strength"].default_value = 1.0
        scene.world = world
    else:
        sys.exit("cycles_render.py: unsupported light type " + light["type"])
if scene.world is None:   # a black world
    scene.world = bpy.data.worlds.new("world")
    scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0

# Camera: an explicit rotation from the view frame (Blender cameras look down -Z with +Y up).
cam = wrapper["camera"]
eye, target = to_blender(cam["look_from"]), to_blender(cam["look_at"])
up = to_blender(cam.get("up", [0, 1, 0]))
forward = (target - eye).normalized()
right = forward.cross(up).normalized()
true_up = right.cross(forward)
rot = mathutils.Matrix((right, true_up, -forward)).transposed()   # columns: camera X, Y, Z
cam_data = bpy.data.cameras.new("camera")
cam_data.type = "PERSP"
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(cam.get("vfov", 40.0))
cam_data.clip_start, cam_data.clip_end = 1e-3, 1e4
cam_obj = bpy.data.objects.new("camera", cam_data)
cam_obj.matrix_world = mathutils.Matrix.Translation(eye) @ rot.to_4x4()
scene.collection.objects.link(cam_obj)
scene.camera = cam_obj

# Cycles: unbiased settings.
r, c = scene.render, scene.cycles
r.engine = "CYCLES"
c.device = "CPU"
c.samples = spp
c.seed = int(opts["--seed"])
c.use_denoising = False
c.use_adaptive_sampling = False
c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
c.light_threshold = 0.0
c.blur_glossy = 0.0
c.caustics_reflective = c.caustics_refractive = True
bounces = int(opts["--bounces"])
c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
c.volume_bounces = c.transparent_max_bounces = bounces
c.min_light_bounces = c.min_transparent_bounces = 0
c.pixel_filter_type = "GAUSSIAN"
c.filter_width = 2.0                     # sigma = 0.5 px, as gilt's default Gaussian
r.film_transparent = True
r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
r.pixel_aspect_x = r.pixel_aspect_y = 1.0
r.threads_mode = "FIXED"
r.threads = int(opts["--threads"])
r.use_persistent_data = False
vs = scene.view_settings
vs.view_transform, vs.look, vs.exposure, vs.gamma = "Standard", "None", 0.0, 1.0
scene.display_settings.display_device = "sRGB"
img = r.image_settings
img.file_format, img.color_mode, img.color_depth, img.exr_codec = "OPEN_EXR", "RGBA", "32", "ZIP"
r.filepath = out_path
r.use_file_extension = False

t0 = time.time()
bpy.ops.render.render(write_still=True)
print("RENDER_SECONDS %.3f spp %d seed %s threads %s distribution %s" %
      (time.time() - t0, spp, opts["--seed"], opts["--threads"], opts["--distribution"]))
