# rtsh bench: the twin of an rtsh scene in Blender's Cycles, rendered at
# several sample counts; each picture is written as a PFM (linear radiance,
# rows bottom to top, like rtsh's) and its CPU time printed.
#
#   blender -b --factory-startup -P bench/cycles_scene.py -- \
#       SCENE.rt WxH THREADS SEED OUT_PREFIX SPP [SPP...]
#
# writes OUT_PREFIX-SPP.pfm for every SPP and prints "cycles SPP SECONDS".
# The settings are the equal-quality comparison of bench/README.md: CPU, a
# 1-pixel box filter, no adaptive sampling, no denoising, no clamping, the
# scene's depth as the bounce limit.
#
# The .rt reader knows the elements the bench scenes use (C, sky, A, pl, sp,
# rc, cu, set) with Lambert, emissive and clear glass materials, and PBR ones
# (roughness= metallic= transmission= multiscatter=, as a Principled BSDF), and stops
# with file:line and the reason on anything else. rtsh's axes (y up, camera
# x to the right) become Blender's (z up): (x, y, z) -> (x, z, y).
import bmesh
import bpy
import math
import os
import struct
import sys
import time


def die(msg):
    print("cycles_scene.py: " + msg, file=sys.stderr)
    sys.exit(1)


def srgb_to_linear(c):
    c = c / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def lin3(rgb):
    return tuple(srgb_to_linear(v) for v in rgb)


def to_blender(v):
    return (v[0], v[2], v[1])


def norm(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def orient(d, twist):
    """rtsh's m4_orient: the shortest arc from +Y to d, then twist about Y
    (rows of a 3x3 matrix)."""
    c = d[1]
    if c < -1.0 + 1e-12:
        r = [[1, 0, 0], [0, -1, 0], [0, 0, -1]]
    else:
        kx, kz, f = d[2], -d[0], 1.0 / (1.0 + c)
        r = [[c + kx * kx * f, -kz, kx * kz * f], [kz, c, -kx], [kz * kx * f, kx, c + kz * kz * f]]
    if twist:
        ct, st = math.cos(twist), math.sin(twist)
        ry = [[ct, 0, st], [0, 1, 0], [-st, 0, ct]]
        r = [[sum(r[i][k] * ry[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    return r


def xform(pos, d, twist, scale):
    """The point map of rtsh's object transform T(pos) R(dir, twist) S(scale/2)."""
    r = orient(norm(d), twist)
    h = [s / 2.0 for s in scale]

    def f(p):
        q = [p[i] * h[i] for i in range(3)]
        return tuple(pos[i] + sum(r[i][k] * q[k] for k in range(3)) for i in range(3))

    return f


def tup(s, where):
    try:
        return tuple(float(x) for x in s.split(","))
    except ValueError:
        die(where + ': "%s" is not a tuple of numbers' % s)


def material(name, rgb, diffuse, emit, ior):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    col = lin3(rgb)
    if ior >= 1.0:
        s = nt.nodes.new("ShaderNodeBsdfGlass")
        s.distribution = "SHARP"
        s.inputs["IOR"].default_value = ior
        s.inputs["Color"].default_value = col + (1.0,)
    else:
        s = nt.nodes.new("ShaderNodeBsdfDiffuse")
        s.inputs["Color"].default_value = tuple(c * diffuse for c in col) + (1.0,)
        s.inputs["Roughness"].default_value = 0.0
    if emit > 0:
        e = nt.nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = col + (1.0,)
        e.inputs["Strength"].default_value = emit
        if ior < 1.0 and diffuse == 0:
            s = e
        else:
            a = nt.nodes.new("ShaderNodeAddShader")
            nt.links.new(s.outputs[0], a.inputs[0])
            nt.links.new(e.outputs[0], a.inputs[1])
            s = a
    nt.links.new(s.outputs[0], out.inputs["Surface"])
    return m


def principled(name, rgb, kv):
    """A material of rtsh's PBR family as Blender's Principled BSDF (the
    glTF metallic-roughness meaning: alpha = roughness^2 in both)."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    s = nt.nodes.new("ShaderNodeBsdfPrincipled")
    # rtsh's multiscatter=0 is single-scattering GGX; 1 (its default) gives
    # back the lost energy, as Cycles' multiple-scattering GGX does
    s.distribution = "GGX" if kv.get("multiscatter", 1.0) == 0 else "MULTI_GGX"
    s.subsurface_method = "BURLEY"
    col = lin3(rgb)
    s.inputs["Base Color"].default_value = col + (1.0,)
    s.inputs["Metallic"].default_value = kv.get("metallic", 0.0)
    s.inputs["Roughness"].default_value = kv.get("roughness", 1.0)
    s.inputs["Transmission"].default_value = kv.get("transmission", 0.0)
    s.inputs["Transmission Roughness"].default_value = 0.0
    ior = kv.get("ior", 0.0) or 1.5
    s.inputs["IOR"].default_value = ior
    # Principled's specular 0.5 is F0 0.04, ior 1.5's: F0 / 0.08
    s.inputs["Specular"].default_value = ((ior - 1) / (ior + 1)) ** 2 / 0.08
    s.inputs["Specular Tint"].default_value = 0.0
    s.inputs["Sheen"].default_value = 0.0
    s.inputs["Clearcoat"].default_value = 0.0
    s.inputs["Subsurface"].default_value = 0.0
    if kv.get("emit", 0.0) > 0:
        s.inputs["Emission"].default_value = col + (1.0,)
        s.inputs["Emission Strength"].default_value = kv["emit"]
    nt.links.new(s.outputs[0], out.inputs["Surface"])
    return m


PBR_KEYS = ("roughness", "metallic", "transmission", "multiscatter")


def mesh_object(name, verts, faces, mat, smooth=False):
    me = bpy.data.meshes.new(name)
    me.from_pydata([to_blender(v) for v in verts], [], faces)
    # normals outward on closed shapes (glass tells inside from outside);
    # the axis swap mirrors, so the faces' winding cannot be trusted
    bm = bmesh.new()
    bm.from_mesh(me)
    bmesh.ops.recalc_face_normals(bm, faces=bm.faces)
    bm.to_mesh(me)
    bm.free()
    me.update()
    if smooth:
        for p in me.polygons:
            p.use_smooth = True
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def sphere_mesh(f, seg=384, rings=192):
    """A UV sphere of unit radius through the map f, smooth-shaded."""
    verts = [(0.0, 1.0, 0.0)]
    for i in range(1, rings):
        t = math.pi * i / rings
        for j in range(seg):
            p = 2 * math.pi * j / seg
            verts.append((math.sin(t) * math.cos(p), math.cos(t), math.sin(t) * math.sin(p)))
    verts.append((0.0, -1.0, 0.0))
    faces = []
    for j in range(seg):
        faces.append((0, 1 + (j + 1) % seg, 1 + j))
    for i in range(rings - 2):
        a, b = 1 + i * seg, 1 + (i + 1) * seg
        for j in range(seg):
            k = (j + 1) % seg
            faces.append((a + j, a + k, b + k, b + j))
    last = len(verts) - 1
    a = 1 + (rings - 2) * seg
    for j in range(seg):
        faces.append((a + j, a + (j + 1) % seg, last))
    return [f(v) for v in verts], faces


def build(path, w, h):
    scene = bpy.context.scene
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    world = bpy.data.worlds.new("rtsh")
    scene.world = world
    world.use_nodes = True
    wn = world.node_tree
    wn.nodes.clear()
    bg = wn.nodes.new("ShaderNodeBackground")
    wout = wn.nodes.new("ShaderNodeOutputWorld")
    wn.links.new(bg.outputs[0], wout.inputs["Surface"])
    bg.inputs["Color"].default_value = (0, 0, 0, 1)
    depth = 5
    sky = None
    ambient = (0, 0, 0)
    cam = None
    n = 0
    with open(path) as fh:
        for lineno, line in enumerate(fh, 1):
            where = "%s:%d" % (path, lineno)
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            tok = line.split()
            kv = {}
            pos = []
            for t in tok[1:]:
                if "=" in t:
                    k, v = t.split("=", 1)
                    kv[k] = float(v)
                else:
                    pos.append(t)
            kind = tok[0]
            if kind == "set":
                if pos[0] == "depth":
                    depth = int(pos[1])
                continue
            if kind == "C":
                cam = (tup(pos[0], where), tup(pos[1], where), float(pos[2]))
                continue
            if kind == "sky":
                z, hz = lin3(tup(pos[0], where)), lin3(tup(pos[1], where))
                k = float(pos[2]) if len(pos) > 2 else 1.0
                sky = (tuple(c * k for c in z), tuple(c * k for c in hz))
                continue
            if kind == "A":
                r = float(pos[0])
                ambient = tuple(c * r for c in lin3(tup(pos[1], where)))
                continue
            if kind not in ("pl", "sp", "rc", "cu"):
                die(where + ': element "%s" has no Cycles twin; expected C sky A pl sp rc cu set' % kind)
            if len(pos) < 8:
                die(where + ": expected the extended format: POS DIR SIZES R,G,B DIFFUSE SPECULAR SHININESS REFLECTIVE")
            p, d, sz, rgb = (tup(x, where) for x in pos[:4])
            diffuse, spec, refl = float(pos[4]), float(pos[5]), float(pos[7])
            emit, ior, twist = kv.get("emit", 0.0), kv.get("ior", 0.0), math.radians(kv.get("twist", 0.0))
            for k in kv:
                if k not in ("emit", "ior", "twist") + PBR_KEYS:
                    die(where + ': "%s" has no Cycles twin; expected emit, ior, twist, roughness, metallic, '
                        "transmission or multiscatter" % k)
            pbr = any(k in kv for k in PBR_KEYS)
            if spec != 0 or refl != 0 and not pbr:
                die(where + ": only Lambert, emissive, glass and PBR materials have a Cycles twin (specular and reflective must be 0)")
            n += 1
            mat = principled("m%d" % n, rgb, kv) if pbr else material("m%d" % n, rgb, diffuse, emit, ior)
            if kind == "rc":
                f = xform(p, d, twist, sz)
                mesh_object("rc%d" % n, [f((-1, 0, -1)), f((1, 0, -1)), f((1, 0, 1)), f((-1, 0, 1))], [(0, 1, 2, 3)], mat)
            elif kind == "pl":
                f = xform(p, d, twist, (4000, 1, 4000))
                mesh_object("pl%d" % n, [f((-1, 0, -1)), f((1, 0, -1)), f((1, 0, 1)), f((-1, 0, 1))], [(0, 1, 2, 3)], mat)
            elif kind == "cu":
                f = xform(p, d, twist, sz)
                v = [f((x, y, z)) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
                faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
                mesh_object("cu%d" % n, v, faces, mat)
            else:
                if not (sz[0] == sz[1] == sz[2]):
                    die(where + ": only round spheres have a Cycles twin")
                verts, faces = sphere_mesh(xform(p, d, twist, sz))
                mesh_object("sp%d" % n, verts, faces, mat, smooth=True)
    if cam is None:
        die(path + ": no camera")
    if sky:
        # rtsh: lerp(horizon, zenith, clamp(dir.y, 0, 1)); Blender's up is z
        tc = wn.nodes.new("ShaderNodeTexCoord")
        sep = wn.nodes.new("ShaderNodeSeparateXYZ")
        clamp = wn.nodes.new("ShaderNodeClamp")
        mix = wn.nodes.new("ShaderNodeMixRGB")
        wn.links.new(tc.outputs["Generated"], sep.inputs[0])
        wn.links.new(sep.outputs["Z"], clamp.inputs["Value"])
        wn.links.new(clamp.outputs[0], mix.inputs["Fac"])
        mix.inputs[1].default_value = sky[1] + (1,)
        mix.inputs[2].default_value = sky[0] + (1,)
        wn.links.new(mix.outputs[0], bg.inputs["Color"])
    else:
        bg.inputs["Color"].default_value = ambient + (1,)
    # the camera: rtsh's right = up_ref x fwd, up = fwd x right; Blender's
    # camera looks down its -Z with +Y up
    cpos, cdir, fov = cam
    fwd = norm(cdir)
    up_ref = (0, 0, 1) if abs(fwd[1]) > 0.999999 else (0, 1, 0)
    right = norm(cross(up_ref, fwd))
    up = cross(fwd, right)
    cd = bpy.data.cameras.new("cam")
    cd.sensor_fit = "HORIZONTAL"
    cd.angle = math.radians(fov)
    co = bpy.data.objects.new("cam", cd)
    scene.collection.objects.link(co)
    from mathutils import Matrix

    X, Y, Z = to_blender(right), to_blender(up), tuple(-c for c in to_blender(fwd))
    P = to_blender(cpos)
    co.matrix_world = Matrix(((X[0], Y[0], Z[0], P[0]), (X[1], Y[1], Z[1], P[1]), (X[2], Y[2], Z[2], P[2]), (0, 0, 0, 1)))
    scene.camera = co
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = w, h, 100
    r.film_transparent = False
    c = scene.cycles
    c.device = "CPU"
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = depth
    c.diffuse_bounces = depth
    c.glossy_bounces = depth
    c.transmission_bounces = depth
    c.transparent_max_bounces = depth
    c.volume_bounces = 0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    return scene


def write_pfm(path, w, h, px):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        rgb = [px[i] for i in range(len(px)) if i % 4 != 3]
        f.write(struct.pack("<%df" % len(rgb), *rgb))
    os.replace(tmp, path)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) < 6:
        die("usage: blender -b -P cycles_scene.py -- SCENE.rt WxH THREADS SEED OUT_PREFIX SPP...")
    path, size, threads, seed, prefix = argv[0], argv[1], int(argv[2]), int(argv[3]), argv[4]
    w, h = (int(x) for x in size.split("x"))
    scene = build(path, w, h)
    r = scene.render
    r.threads_mode = "FIXED"
    r.threads = threads
    scene.cycles.seed = seed
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.exr_codec = "NONE"
    for spp in argv[5:]:
        scene.cycles.samples = int(spp)
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


main()
