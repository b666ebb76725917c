# rtsh bench: issue 26's glTF scene, built in Blender, exported with
# Blender's own glTF exporter and rendered by Cycles from the same .blend.
#
#   blender -b --factory-startup -P bench/gltf_scene.py -- build OUT_PREFIX
#       builds the scene and writes OUT_PREFIX.blend and OUT_PREFIX.glb
#       (bpy.ops.export_scene.gltf: the file rtsh reads, its camera and its
#       emissive lamp included)
#   blender -b --factory-startup OUT_PREFIX.blend -P bench/gltf_scene.py -- \
#       render WxH THREADS SEED DEPTH PFM_PREFIX SPP [SPP...]
#       renders the .blend with Cycles at every SPP, writes PFM_PREFIX-SPP.pfm
#       (linear radiance, rows bottom to top, as rtsh's) and prints
#       "cycles SPP SECONDS" (CPU seconds of the render)
#
# The scene (Blender's axes, z up, metres): copper metals of roughness 0.05,
# 0.2, 0.4, 0.6 and 0.8 in the back row; smooth glass, rough glass (0.3) and
# two plastics in the front row; a grey floor; a lamp that is an emissive
# mesh (Principled emission strength 4, so that the exporter writes
# KHR_materials_emissive_strength); a perspective camera. Every material is a
# Principled BSDF: GGX (single scattering) for the glass, Multiscatter GGX
# for the rest, as rtsh compensates those lobes by default.
#
# Glass: Blender's exporter writes KHR_materials_volume (a refracting solid,
# not a thin wall) only from the "glTF Material Output" node group's
# Thickness input, which Cycles ignores; the script adds that group to the
# glass materials, as Blender's manual says to.
#
# Render settings are the equal-quality comparison of bench/README.md: CPU,
# 1-pixel box filter, no adaptive sampling, no denoising, no clamping,
# DEPTH bounces.
import bpy
import math
import os
import struct
import sys
import time


def die(msg):
    print("gltf_scene.py: " + msg, file=sys.stderr)
    sys.exit(1)


COPPER = (0.955, 0.638, 0.538)  # linear F0 of copper (glTF base colour)


def principled(name, base, metallic=0.0, roughness=0.5, transmission=0.0, emit=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    s = nt.nodes.new("ShaderNodeBsdfPrincipled")
    # rtsh gives the metal and plastic GGX lobes back the energy single
    # scattering loses (Turquin, its default) and not the glass: Cycles'
    # twin of each is Multiscatter GGX and GGX (the exporter writes neither)
    s.distribution = "GGX" if transmission > 0 else "MULTI_GGX"
    s.inputs["Base Color"].default_value = tuple(base) + (1.0,)
    s.inputs["Metallic"].default_value = metallic
    s.inputs["Roughness"].default_value = roughness
    s.inputs["Transmission"].default_value = transmission
    s.inputs["Transmission Roughness"].default_value = 0.0  # the refraction roughness is Roughness
    s.inputs["IOR"].default_value = 1.5  # glTF's default: no KHR_materials_ior
    s.inputs["Specular"].default_value = 0.5  # F0 0.04, ior 1.5's: no KHR_materials_specular
    s.inputs["Specular Tint"].default_value = 0.0
    if emit > 0:
        s.inputs["Emission"].default_value = (1.0, 1.0, 1.0, 1.0)
        s.inputs["Emission Strength"].default_value = emit
    nt.links.new(s.outputs[0], out.inputs["Surface"])
    if transmission > 0:
        # the exporter's "glTF Material Output" group: Thickness > 0 makes
        # it write KHR_materials_volume (Cycles does not use the group)
        g = bpy.data.node_groups.get("glTF Material Output")
        if g is None:
            g = bpy.data.node_groups.new("glTF Material Output", "ShaderNodeTree")
            g.inputs.new("NodeSocketFloat", "Thickness")
        n = nt.nodes.new("ShaderNodeGroup")
        n.node_tree = g
        n.inputs["Thickness"].default_value = 0.9
    return m


def add(ob, mat):
    ob.data.materials.clear()
    ob.data.materials.append(mat)
    return ob


def sphere(name, x, y, r, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=r, location=(x, y, r))
    ob = bpy.context.active_object
    ob.name = name
    bpy.ops.object.shade_smooth()
    return add(ob, mat)


def build(prefix):
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    scene = bpy.context.scene
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world

    # the floor: rough grey metal. Cycles 3.4's Principled dielectric is not
    # glTF's (Disney diffuse, not dimmed by the specular layer): a plastic
    # floor is 12% brighter in Cycles, and the glass, which shows the floor,
    # follows it (bench/README.md)
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 2, 0))
    add(bpy.context.active_object, principled("floor", (0.3, 0.3, 0.3), metallic=1, roughness=0.5)).name = "floor"
    # the lamp: a 3 x 1.6 m rectangle 4 m up, its face down
    bpy.ops.mesh.primitive_plane_add(size=1, location=(0, 0.6, 4), rotation=(math.pi, 0, 0))
    lamp = bpy.context.active_object
    lamp.scale = (3.0, 1.6, 1.0)
    add(lamp, principled("lamp", (0, 0, 0), roughness=1.0, emit=4.0)).name = "lamp"

    for i, r in enumerate((0.05, 0.2, 0.4, 0.6, 0.8)):
        sphere("copper%d" % i, -2.2 + 1.1 * i, 1.4, 0.45, principled("copper r=%.2f" % r, COPPER, metallic=1, roughness=r))
    sphere("glass", -1.65, 0, 0.45, principled("glass", (1, 1, 1), roughness=0.0, transmission=1))
    sphere("rough glass", -0.55, 0, 0.45, principled("rough glass", (1, 1, 1), roughness=0.3, transmission=1))
    sphere("red plastic", 0.55, 0, 0.45, principled("red plastic", (0.58, 0.02, 0.02), roughness=0.3))
    sphere("blue plastic", 1.65, 0, 0.45, principled("blue plastic", (0.02, 0.08, 0.58), roughness=0.6))

    cd = bpy.data.cameras.new("camera")
    cd.sensor_fit = "HORIZONTAL"
    cd.angle = math.radians(48)
    cam = bpy.data.objects.new("camera", cd)
    scene.collection.objects.link(cam)
    cam.location = (0, -5.2, 1.6)
    cam.rotation_euler = (math.radians(90 - 12.4), 0, 0)  # looking along +y, 12.4 degrees down
    scene.camera = cam
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 192, 108, 100
    for f in (prefix + ".blend", prefix + ".glb"):
        if os.path.exists(f):
            os.remove(f)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(prefix + ".blend"))
    bpy.ops.export_scene.gltf(filepath=os.path.abspath(prefix + ".glb"), export_format="GLB",
                              export_cameras=True, export_lights=True, export_apply=True)


def write_pfm(path, w, h, px):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        rgb = [px[i] for i in range(len(px)) if i % 4 != 3]
        f.write(struct.pack("<%df" % len(rgb), *rgb))
    os.replace(tmp, path)


def render(argv):
    if len(argv) < 6:
        die("usage: blender -b FILE.blend -P gltf_scene.py -- render WxH THREADS SEED DEPTH PFM_PREFIX SPP...")
    size, threads, seed, depth, prefix = argv[0], int(argv[1]), int(argv[2]), int(argv[3]), argv[4]
    w, h = (int(x) for x in size.split("x"))
    scene = bpy.context.scene
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = w, h, 100
    r.film_transparent = False
    r.threads_mode = "FIXED"
    r.threads = threads
    c = scene.cycles
    c.device = "CPU"
    c.seed = seed
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = depth
    c.transmission_bounces = c.transparent_max_bounces = depth
    c.volume_bounces = 0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.exr_codec = "NONE"
    for spp in argv[5:]:
        c.samples = int(spp)
        t0 = time.process_time()
        bpy.ops.render.render(write_still=False)
        t = time.process_time() - t0
        exr = prefix + "-%s.exr" % spp
        bpy.data.images["Render Result"].save_render(exr)
        img = bpy.data.images.load(exr)
        write_pfm(prefix + "-%s.pfm" % spp, w, h, img.pixels[:])
        bpy.data.images.remove(img)
        os.remove(exr)
        print("cycles %s %.4f" % (spp, t), flush=True)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if argv[:1] == ["build"] and len(argv) == 2:
        build(argv[1])
    elif argv[:1] == ["render"]:
        render(argv[1:])
    else:
        die("usage: -- build OUT_PREFIX | -- render WxH THREADS SEED DEPTH PFM_PREFIX SPP...")


main()
