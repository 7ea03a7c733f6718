"""Blender 3.4 Cycles shadow-catcher render of an iblkit composite scene: the peer for bench/composite_vs_blender.py.

Runs inside Blender (bpy), from a factory-startup scene:

    blender -b --factory-startup -P bench/blender_shadow_catcher.py -- \
        --probe probe_matched.exr --proxy proxy.obj --object object.obj --camera camera.json \
        --object-albedo 0.7,0.7,0.7 --proxy-albedo 0.5,0.5,0.5 --samples 256 --seed 1 --out render.exr
    blender -b --factory-startup -P bench/blender_shadow_catcher.py -- --selftest [--keep DIR]

The scene, built from nothing:
  - world: the probe (lat-long, linear, iblkit's convention) as an Environment Texture (equirectangular, linear
    interpolation, alpha ignored) of the ray direction at strength 1; with the axis map below, Cycles' lookup is
    iblkit's texel for texel, no Mapping node needed (derivation at `world_from_probe`, proved by --selftest);
  - the proxy (an OBJ in iblkit's world: metres, +Y up): Diffuse BSDF (roughness 0) of --proxy-albedo, with
    Object.is_shadow_catcher = True, seen by every ray (--proxy-rays all, the default) or by camera rays only
    (--proxy-rays camera: it catches the object's shadow but neither blocks nor reflects the world; a closed room
    proxy would otherwise shut the distant world out altogether);
  - the object (an OBJ likewise): Diffuse BSDF (roughness 0) of --object-albedo, shaded smooth with auto smooth at
    40 degrees (--object-smooth-deg; iblkit's crease angle for mesh files; iblkit's OBJ carries no normals);
  - the camera of camera.json (iblkit.camera/1: eye, target, up, fov_y_deg, width, height, optionally intrinsics
    with square pixels; a lens with distortion is refused): sensor fit vertical, the vertical field of view as given
    (or 2 atan(H / 2 fy)), the principal point as a lens shift, 100 %.
iblkit's world (x, y, z) is Blender's (x, -z, y) (a proper rotation: +Y up becomes +Z up).

Render settings: Cycles on the CPU, --samples per pixel exactly (adaptive sampling off), --seed, no denoising,
film transparent, the Shadow Catcher pass on; light paths: the bounce limits are Cycles' defaults (max 12, diffuse 4,
glossy 4, transmission 12, volume 0, transparent 8) but clamping is off (Cycles' default clamps indirect light at 10,
which biases a bright probe) and caustics stay at their defaults; pixel filter: box, 1 px (iblkit's pixel is a box,
docs/conventions.md "Pixels"; Cycles' default is a 1.5 px Blackman-Harris). Colour management: view transform
Standard, look None, exposure 0, gamma 1 (the EXR holds scene-linear values in any case). Output: a multilayer OpenEXR,
32-bit float, ZIP, with ViewLayer.Combined.{R,G,B,A} and ViewLayer.Shadow Catcher.{R,G,B}. Prints `render_seconds N`
(the wall time of bpy.ops.render.render, which includes Cycles' scene sync and BVH build, not Blender's start-up).

--selftest proves the conventions (exit status 1 on any failure; `selftest passed` and 0 otherwise):
  1. environment orientation: a 128x64 lat-long, black except coloured caps of 6 degrees at known iblkit directions
     (red +X, blue +Z, green (0, 1, -1)/sqrt2, white (4, 1, 1)/sqrt18), written by this file's own EXR writer (so the
     test does not rest on Blender's image-row conventions). A 5-degree camera aimed along each direction must see its
     colour; aimed along the direction's images under a 180-degree turn about the vertical and under the three axis
     mirrors it must see black. A 60-degree camera along +X must show red at the centre and white right of and above
     the centre (+Z is the camera's right, +Y its up); with intrinsics whose principal point is off the centre of a
     64x48 frame, red must land on the principal point and white where iblkit's pinhole puts it.
  2. shadow and meshes: a floor (y = 0, the shadow catcher) and a sphere above it lit by one bright cap at iblkit
     direction (1, 1, 0)/sqrt2 and a dim uniform sky, seen from above with +X to the right: the Shadow Catcher pass
     must be darker left of the sphere (towards -X) than right of it, about 1 far from it, and the sphere's right side
     brighter than its left. The imported vertices must equal the OBJ's under the axis map.
  3. the compositing formula: combined + (1 - alpha) * B * shadow catcher, with B a render of the floor alone as an
     ordinary object, must give the ordinary render of floor and sphere (L1 within 10 %, the shadow within 25 %:
     Monte Carlo noise at 32 and 64 samples).
The EXR reader here (`read_exr`, no bpy needed) is also what bench/composite_vs_blender.py uses.
"""

import argparse
import json
import math
import os
import struct
import sys
import tempfile
import time
import zlib

import numpy as np

# ---- OpenEXR, single-part scan-line files (our own reader and writer; no OpenEXR module needed) --------------------
_EXR_MAGIC = 20000630
_LINES_PER_CHUNK = {0: 1, 2: 1, 3: 16}  # NONE, ZIPS, ZIP
_PIXEL_BYTES = {0: 4, 1: 2, 2: 4}  # UINT, HALF, FLOAT
_PIXEL_DTYPE = {0: "<u4", 1: "<f2", 2: "<f4"}


def read_exr(path):
    """Reads a scan-line OpenEXR (compression NONE, ZIPS or ZIP) into {channel name: float32 array (H, W)}."""
    with open(path, "rb") as f:
        data = f.read()
    magic, version = struct.unpack_from("<ii", data, 0)
    if magic != _EXR_MAGIC:
        raise ValueError(f"{path}: not an OpenEXR file")
    if version & 0x1200:  # tiled (0x200) or multi-part (0x1000)
        raise ValueError(f"{path}: tiled or multi-part OpenEXR is not supported by this reader")
    pos = 8
    attrs = {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        pos = end + 1
        end = data.index(b"\0", pos)
        kind = data[pos:end].decode()
        pos = end + 1
        (size,) = struct.unpack_from("<i", data, pos)
        pos += 4
        attrs[name] = (kind, data[pos:pos + size])
        pos += size
    pos += 1
    channels = []
    raw = attrs["channels"][1]
    q = 0
    while raw[q] != 0:
        end = raw.index(b"\0", q)
        cname = raw[q:end].decode()
        ptype, _plinear, xs, ys = struct.unpack_from("<iB3xii", raw, end + 1)
        if xs != 1 or ys != 1:
            raise ValueError(f"{path}: sub-sampled channel {cname} not supported")
        channels.append((cname, ptype))
        q = end + 1 + 16
    compression = attrs["compression"][1][0]
    if compression not in _LINES_PER_CHUNK:
        raise ValueError(f"{path}: compression {compression} not supported (NONE, ZIPS and ZIP are)")
    xmin, ymin, xmax, ymax = struct.unpack("<iiii", attrs["dataWindow"][1])
    width, height = xmax - xmin + 1, ymax - ymin + 1
    lines = _LINES_PER_CHUNK[compression]
    chunks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    row_bytes = sum(_PIXEL_BYTES[t] for _, t in channels) * width
    out = {c: np.zeros((height, width), np.float32) for c, _ in channels}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        block = data[off + 8:off + 8 + size]
        n_lines = min(lines, ymax - y + 1)
        expect = row_bytes * n_lines
        if compression != 0 and size < expect:
            t = np.frombuffer(zlib.decompress(block), np.uint8).astype(np.int64)
            t[1:] -= 128
            t = (np.cumsum(t) & 0xFF).astype(np.uint8)  # undo the predictor
            half = (len(t) + 1) // 2
            u = np.empty_like(t)
            u[0::2] = t[:half]  # undo the byte interleave
            u[1::2] = t[half:]
            block = u.tobytes()
        if len(block) != expect:
            raise ValueError(f"{path}: chunk at line {y} holds {len(block)} bytes, expected {expect}")
        p = 0
        for r in range(n_lines):
            for cname, ptype in channels:
                nb = _PIXEL_BYTES[ptype] * width
                out[cname][y - ymin + r] = np.frombuffer(block[p:p + nb], _PIXEL_DTYPE[ptype]).astype(np.float32)
                p += nb
    return out


def write_exr(path, image, names="RGB"):
    """Writes an (H, W, C) float array as an uncompressed 32-bit float OpenEXR, row 0 at the top."""
    image = np.asarray(image, np.float32)
    h, w, c = image.shape
    order = sorted(range(c), key=lambda i: names[i])
    chlist = b"".join(names[i].encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for i in order) + b"\0"

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (struct.pack("<ii", _EXR_MAGIC, 2) + attr("channels", "chlist", chlist)
              + attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box)
              + attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0")
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    row_bytes = 8 + 4 * w * c
    start = len(header) + 8 * h
    table = struct.pack(f"<{h}Q", *[start + y * row_bytes for y in range(h)])
    rows = []
    for y in range(h):
        rows.append(struct.pack("<ii", y, 4 * w * c)
                    + b"".join(image[y, :, i].astype("<f4").tobytes() for i in order))
    with open(path, "wb") as f:
        f.write(header + table + b"".join(rows))


def render_passes(path):
    """The passes of this script's multilayer EXR: (combined (H, W, 4), shadow catcher (H, W, 3))."""
    ch = read_exr(path)

    def find(pass_name, comps):
        planes = []
        for comp in comps:
            keys = [k for k in ch if k.endswith(f".{pass_name}.{comp}")]
            if len(keys) != 1:
                raise ValueError(f"{path}: no single channel '*.{pass_name}.{comp}' (channels: {sorted(ch)})")
            planes.append(ch[keys[0]])
        return np.stack(planes, axis=-1)

    return find("Combined", "RGBA"), find("Shadow Catcher", "RGB")


# ---- iblkit conventions ---------------------------------------------------------------------------------------------
def to_blender(p):
    """iblkit world (x, y, z), +Y up, to Blender's (x, -z, y), +Z up."""
    return (p[0], -p[2], p[1])


def latlong_direction(u, v):
    """iblkit's lat-long (docs/conventions.md): normalised (u, v), v from the top, to the world direction."""
    theta = math.pi * v
    return (-math.sin(theta) * math.cos(2 * math.pi * u), math.cos(theta), -math.sin(theta) * math.sin(2 * math.pi * u))


def read_obj_vertices(path):
    """The 'v' lines of an OBJ that its faces use, in file order (iblkit coordinates): Blender's importer drops
    vertices no face refers to."""
    verts, used = [], set()
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append(tuple(float(t) for t in line.split()[1:4]))
            elif line.startswith("f "):
                for t in line.split()[1:]:
                    i = int(t.split("/")[0])
                    used.add(i - 1 if i > 0 else len(verts) + i)
    return np.array([v for i, v in enumerate(verts) if i in used], np.float64).reshape(-1, 3)


def read_camera(path):
    """An iblkit.camera/1 file; refuses lenses that Blender's pinhole would not reproduce."""
    with open(path) as f:
        cam = json.load(f)
    if cam.get("format") != "iblkit.camera/1":
        raise SystemExit(f"{path}: not an iblkit.camera/1 file (format {cam.get('format')!r})")
    w, h = int(cam["width"]), int(cam["height"])
    fov = float(cam.get("fov_y_deg", 0))
    dist = cam.get("distortion")
    coeffs = dist.values() if isinstance(dist, dict) else (dist or [])
    if any(abs(float(k)) > 0 for k in coeffs):
        raise SystemExit(f"{path}: the camera has lens distortion {dist}; Blender's pinhole camera cannot reproduce it "
                         "(undistort the photograph first, or shoot the lab plate without --plate-k1)")
    cx, cy = w / 2, h / 2
    intr = cam.get("intrinsics")
    if intr:
        fx, fy, cx, cy = (float(intr[k]) for k in ("fx", "fy", "cx", "cy"))
        if abs(fx - fy) > 1e-6 * fy:
            raise SystemExit(f"{path}: intrinsics fx = {fx} != fy = {fy} (non-square pixels); this bench supports "
                             "square pixels only")
        fov = math.degrees(2 * math.atan(h / (2 * fy)))
    if not 0 < fov < 180:
        raise SystemExit(f"{path}: fov_y_deg {fov} out of range")
    return {"eye": cam["eye"], "target": cam["target"], "up": cam.get("up", [0, 1, 0]), "fov_y_deg": fov,
            "width": w, "height": h, "cx": cx, "cy": cy}


# ---- the Blender scene ----------------------------------------------------------------------------------------------
def reset_scene():
    import bpy
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.cameras, bpy.data.lights, bpy.data.images,
                 bpy.data.worlds):
        for block in list(coll):
            if getattr(block, "type", "") != "RENDER_RESULT":
                coll.remove(block)
    return bpy.context.scene


def diffuse_material(name, albedo):
    import bpy
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (albedo[0], albedo[1], albedo[2], 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def import_obj(path, name, albedo):
    """Imports an iblkit OBJ so that iblkit (x, y, z) lands at Blender (x, -z, y), and checks that it did."""
    import bpy
    before = set(bpy.data.objects)
    # Blender's OBJ importer maps the file's axes as forward = -Z, up = Y by default: file (x, y, z) -> (x, -z, y).
    bpy.ops.wm.obj_import(filepath=path, forward_axis="NEGATIVE_Z", up_axis="Y", global_scale=1.0,
                          clamp_size=0.0, validate_meshes=False)
    new = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    if len(new) != 1:
        raise SystemExit(f"{path}: the importer made {len(new)} mesh objects; expected one")
    ob = new[0]
    ob.name = name
    mw = ob.matrix_world
    got = np.array([tuple(mw @ v.co) for v in ob.data.vertices], np.float64)
    want = np.array([to_blender(p) for p in read_obj_vertices(path)], np.float64)
    if got.shape != want.shape:
        raise SystemExit(f"{path}: {len(got)} vertices after import, {len(want)} used by the file's faces")
    err = float(np.max(np.abs(got - want))) if len(got) else 0.0
    scale = max(1.0, float(np.max(np.abs(want)))) if len(want) else 1.0
    if err > 1e-5 * scale:
        raise SystemExit(f"{path}: imported vertices are off the axis map by {err:g} m")
    ob.data.materials.clear()
    ob.data.materials.append(diffuse_material(name + "_material", albedo))
    return ob, err


def world_from_probe(scene, probe_path):
    """The probe as the world, looked up the iblkit way.

    Cycles' equirectangular lookup of a direction D (Blender axes; `direction_to_equirectangular` in
    intern/cycles/kernel/camera/projection.h, range (-2pi, pi, -pi, pi/2)) is
        u_B = 1/2 - atan2(D.y, D.x) / 2pi,   v_B = 1 - acos(D.z) / pi   (v_B = 0 at the image's bottom row).
    An iblkit direction d = (x, y, z) is D = (x, -z, y), so u_B = 1/2 + atan2(z, x) / 2pi = iblkit's u, and
    v_B = 1 - acos(y) / pi: from the bottom, the row that iblkit's v = acos(y) / pi names from the top. The two agree
    texel for texel with no rotation at all: the world is the Environment Texture of the ray direction, unmapped.
    (The formula we were first given, u = atan2(D.y, -D.x) / 2pi + 1/2, is half a turn off; a Mapping node turning
    Z by pi to undo it put every selftest spot at its antipode in azimuth. --selftest proves the mapping on rendered
    pixels: each coloured cap is seen where iblkit's lat-long has it, and black at its mirror images.)
    """
    import bpy
    world = bpy.data.worlds.new("probe")
    scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    image = bpy.data.images.load(os.path.abspath(probe_path), check_existing=False)
    image.colorspace_settings.name = "Linear"
    image.alpha_mode = "NONE"  # a probe's alpha channel (weights, coverage) is not transparency
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = image
    env.projection = "EQUIRECTANGULAR"
    env.interpolation = "Linear"
    background = nt.nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = 1.0
    out = nt.nodes.new("ShaderNodeOutputWorld")
    # env's Vector input left unlinked: the world shader then looks up the ray's direction itself
    nt.links.new(env.outputs["Color"], background.inputs["Color"])
    nt.links.new(background.outputs["Background"], out.inputs["Surface"])
    return world


def add_camera(scene, cam):
    """A Blender camera with iblkit's framing: looks from eye to target, `up` upwards, vertical fov, W x H."""
    import bpy
    from mathutils import Matrix, Vector
    eye = Vector(to_blender(cam["eye"]))
    fwd = (Vector(to_blender(cam["target"])) - eye).normalized()
    right = fwd.cross(Vector(to_blender(cam["up"])))
    if right.length < 1e-9:
        raise SystemExit("camera: up is parallel to the viewing direction")
    right.normalize()
    up = right.cross(fwd)
    # Blender's camera looks along its local -Z, local +X is the image's right, +Y its up.
    rot = Matrix((right, up, -fwd)).transposed()
    data = bpy.data.cameras.new("camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.sensor_height = 24.0
    data.lens = (data.sensor_height / 2) / math.tan(math.radians(cam["fov_y_deg"]) / 2)
    # The principal point (cx, cy) (pixels from the top-left corner) off the frame's centre is a lens shift. Blender's
    # shift is in units of the fitted sensor dimension (the height here); +x moves the view window right, which
    # moves the optical axis left in the image, +y up. --selftest checks this on a 64x48 frame.
    data.shift_x = (cam["width"] / 2 - cam["cx"]) / cam["height"]
    data.shift_y = (cam["cy"] - cam["height"] / 2) / cam["height"]
    data.clip_start = 1e-4
    data.clip_end = 1e6
    ob = bpy.data.objects.new("camera", data)
    scene.collection.objects.link(ob)
    ob.matrix_world = Matrix.Translation(eye) @ rot.to_4x4()
    scene.camera = ob
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = cam["width"], cam["height"], 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    if abs(math.degrees(data.angle_y) - cam["fov_y_deg"]) > 1e-4:
        raise SystemExit(f"camera: Blender's vertical angle {math.degrees(data.angle_y)} != {cam['fov_y_deg']}")
    return ob


def render_settings(scene, samples, seed, threads, transparent=True, max_bounces=-1):
    import bpy
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.use_adaptive_sampling = False
    c.seed = seed
    c.use_animated_seed = False
    c.use_denoising = False
    c.use_preview_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0  # Cycles' default is 10; off here (see the docstring)
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    # bounces: Cycles' defaults, left alone (max_bounces 12, diffuse 4, glossy 4, transmission 12, ...), unless
    # --max-bounces asks for a limit (a truth rendered with fewer bounces than Cycles' default)
    if max_bounces >= 0:
        c.max_bounces = c.diffuse_bounces = max_bounces
    scene.render.film_transparent = transparent
    scene.render.use_persistent_data = False
    if threads > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = threads
    vl = bpy.context.view_layer
    vl.use_pass_combined = True
    vl.cycles.use_pass_shadow_catcher = True
    vl.cycles.denoising_store_passes = False
    vs = scene.view_settings
    scene.display_settings.display_device = "sRGB"
    vs.view_transform = "Standard"
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
    vs.use_curve_mapping = False
    scene.sequencer_colorspace_settings.name = "sRGB"
    im = scene.render.image_settings
    im.file_format = "OPEN_EXR_MULTILAYER"
    im.color_depth = "32"
    im.exr_codec = "ZIP"
    im.color_mode = "RGBA"
    scene.render.use_compositing = False
    scene.render.use_sequencer = False


def render(scene, out):
    import bpy
    scene.render.filepath = os.path.abspath(out)
    scene.render.use_file_extension = False
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0


def build_and_render(probe, proxy, obj, camera, object_albedo, proxy_albedo, samples, seed, out, threads=0,
                     transparent=True, proxy_rays="all", smooth_deg=40.0, max_bounces=-1):
    scene = reset_scene()
    render_settings(scene, samples, seed, threads, transparent, max_bounces)
    world_from_probe(scene, probe)
    errs = {}
    if proxy:
        ob, errs["proxy"] = import_obj(proxy, "proxy", proxy_albedo)
        ob.is_shadow_catcher = True
        if proxy_rays == "camera":
            # the proxy only receives: the object's rays, and the proxy's own, pass through it to the world
            ob.visible_diffuse = ob.visible_glossy = ob.visible_transmission = False
            ob.visible_volume_scatter = ob.visible_shadow = False
        elif proxy_rays != "all":
            raise SystemExit(f"--proxy-rays {proxy_rays!r}: want all or camera")
    if obj:
        ob, errs["object"] = import_obj(obj, "object", object_albedo)
        if smooth_deg > 0:
            # iblkit shades a mesh file with smooth normals kept apart at creases over 40 degrees
            # (geometry::with_normals, area-weighted); Blender's auto smooth is the nearest equivalent (angle-weighted).
            for poly in ob.data.polygons:
                poly.use_smooth = True
            ob.data.use_auto_smooth = True
            ob.data.auto_smooth_angle = math.radians(smooth_deg)
    add_camera(scene, read_camera(camera))
    return render(scene, out), errs


# ---- self-test ------------------------------------------------------------------------------------------------------
def _normalise(v):
    n = math.sqrt(sum(t * t for t in v))
    return tuple(t / n for t in v)


def spot_probe(path, spots, width=128, height=64, radius_deg=6.0, ambient=(0.0, 0.0, 0.0)):
    """A lat-long (iblkit convention) black but for caps of `radius_deg` around each (direction, rgb)."""
    img = np.zeros((height, width, 3), np.float32)
    img[:] = ambient
    cos_r = math.cos(math.radians(radius_deg))
    for y in range(height):
        for x in range(width):
            d = latlong_direction((x + 0.5) / width, (y + 0.5) / height)
            for s, rgb in spots:
                if sum(a * b for a, b in zip(d, s)) >= cos_r:
                    img[y, x] += rgb
    write_exr(path, img)


def write_obj(path, verts, faces):
    with open(path, "w") as f:
        for v in verts:
            f.write("v {:.9g} {:.9g} {:.9g}\n".format(*v))
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def sphere_mesh(center, radius, n_lat=16, n_lon=32):
    verts = [(center[0], center[1] + radius, center[2])]
    for i in range(1, n_lat):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            verts.append((center[0] + radius * math.sin(th) * math.cos(ph), center[1] + radius * math.cos(th),
                          center[2] + radius * math.sin(th) * math.sin(ph)))
    verts.append((center[0], center[1] - radius, center[2]))
    faces = []
    ring = lambda i, j: 1 + (i - 1) * n_lon + (j % n_lon)  # noqa: E731
    for j in range(n_lon):  # counter-clockwise seen from outside (outward normals)
        faces.append((0, ring(1, j + 1), ring(1, j)))
        faces.append((len(verts) - 1, ring(n_lat - 1, j), ring(n_lat - 1, j + 1)))
    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            faces.append((ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)))
    return verts, faces


def write_camera(path, eye, target, up, fov, w, h):
    with open(path, "w") as f:
        json.dump({"format": "iblkit.camera/1", "eye": list(eye), "target": list(target), "up": list(up),
                   "fov_y_deg": fov, "width": w, "height": h}, f)


def selftest(keep=None, threads=1):
    failures = []

    def check(ok, what):
        print(("ok    " if ok else "FAIL  ") + what)
        if not ok:
            failures.append(what)

    tmp = keep or tempfile.mkdtemp(prefix="blender_sc_selftest_")
    os.makedirs(tmp, exist_ok=True)
    red, blue, green, white = (8.0, 0, 0), (0, 0, 8.0), (0, 8.0, 0), (8.0, 8.0, 8.0)
    d_red, d_blue = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    d_green, d_white = _normalise((0, 1, -1)), _normalise((4, 1, 1))
    spots = [(d_red, red), (d_blue, blue), (d_green, green), (d_white, white)]
    probe = os.path.join(tmp, "spots.exr")
    spot_probe(probe, spots)
    # Our writer, read back by our reader, must give the iblkit texel of +X (centre column, middle rows) red.
    ch = read_exr(probe)
    check(ch["R"][31, 64] > 4 and ch["B"][31, 64] == 0, "probe file: +X at the centre column is red")

    # 1. narrow cameras along each spot's direction, and along its wrong-convention images
    def look(direction, name, fov=5.0, size=8):
        cam = os.path.join(tmp, name + ".json")
        up = (0, 0, 1) if abs(direction[1]) > 0.9 else (0, 1, 0)
        write_camera(cam, (0, 0, 0), direction, up, fov, size, size)
        out = os.path.join(tmp, name + ".exr")
        build_and_render(probe, None, None, cam, (0.5,) * 3, (0.5,) * 3, 4, 1, out, threads, transparent=False)
        return render_passes(out)[0][..., :3]

    wrong = {"turned 180 about +Y": lambda d: (-d[0], d[1], -d[2]), "mirror x": lambda d: (-d[0], d[1], d[2]),
             "mirror y": lambda d: (d[0], -d[1], d[2]), "mirror z": lambda d: (d[0], d[1], -d[2])}
    for (d, rgb), name in zip(spots, ("red", "blue", "green", "white")):
        mean = look(d, "look_" + name).reshape(-1, 3).mean(axis=0)
        want = np.array(rgb, np.float64)
        check(bool(np.all(np.abs(mean - want) < 0.1 * 8.0)),
              f"world seen along iblkit {tuple(round(t, 3) for t in d)} is {name}: mean {np.round(mean, 3)}")
        for wname, f in wrong.items():
            w = f(d)
            if max(abs(a - b) for a, b in zip(w, d)) < 1e-9:
                continue  # the mirror leaves this direction alone
            m = look(w, "look_" + name + "_" + wname.replace(" ", "_")).reshape(-1, 3).mean(axis=0)
            hit = [n for (s, c), n in zip(spots, ("red", "blue", "green", "white")) if np.dot(s, w) > 0.999]
            if hit:
                continue
            check(float(m.max()) < 0.05, f"  its image under '{wname}' {tuple(round(t, 3) for t in w)} is black: "
                                         f"max {m.max():.3g}")
    # the wide camera: red at the centre, white to the right (+Z) and above (+Y)
    img = look(d_red, "wide", fov=60.0, size=48)
    h, w = img.shape[:2]
    check(img[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1, 0].mean() > 4 and img[h // 2, w // 2, 1] < 0.5,
          "60-degree camera along +X: red at the centre")
    white_px = np.argwhere(img.min(axis=2) > 4)
    if len(white_px):
        cy, cx = white_px.mean(axis=0)
        # where iblkit's pinhole puts (4, 1, 1)/sqrt18: right = +Z, up = +Y, tan(half fov) = tan 30
        t = math.tan(math.radians(30))
        ex = w / 2 + (0.25 / t) * (h / 2)
        ey = h / 2 - (0.25 / t) * (h / 2)
        check(abs(cx + 0.5 - ex) < 2.0 and abs(cy + 0.5 - ey) < 2.0,
              f"60-degree camera: white cap centred at pixel ({cx + 0.5:.1f}, {cy + 0.5:.1f}), iblkit's pinhole puts "
              f"it "
              f"at ({ex:.1f}, {ey:.1f}) (right of and above the centre)")
    else:
        check(False, "60-degree camera: the white cap is in view")

    # an off-centre principal point on a 64 x 48 frame: red (+X, the optical axis) at (cx, cy), white where
    # iblkit's pinhole with those intrinsics puts it
    f_px = 24 / math.tan(math.radians(30))
    cam_path = os.path.join(tmp, "shifted.json")
    with open(cam_path, "w") as f:
        json.dump({"format": "iblkit.camera/1", "eye": [0, 0, 0], "target": list(d_red), "up": [0, 1, 0],
                   "width": 64, "height": 48, "intrinsics": {"fx": f_px, "fy": f_px, "cx": 42.0, "cy": 18.0}}, f)
    out = os.path.join(tmp, "shifted.exr")
    build_and_render(probe, None, None, cam_path, (0.5,) * 3, (0.5,) * 3, 4, 1, out, threads, transparent=False)
    img = render_passes(out)[0][..., :3]
    for name, sel, (ex, ey) in (("red", (img[..., 0] > 4) & (img[..., 2] < 1), (42.0, 18.0)),
                                ("white", img.min(axis=2) > 4, (42.0 + 0.25 * f_px, 18.0 - 0.25 * f_px))):
        pts = np.argwhere(sel)
        if not len(pts):
            check(False, f"shifted camera: the {name} cap is in view")
            continue
        cy_, cx_ = pts.mean(axis=0) + 0.5
        check(abs(cx_ - ex) < 1.5 and abs(cy_ - ey) < 1.5,
              f"principal point (42, 18) on 64x48: {name} cap at ({cx_:.1f}, {cy_:.1f}), iblkit's pinhole: "
              f"({ex:.1f}, {ey:.1f})")

    # 2. shadow direction, meshes, the shadow-catcher pass
    sun = _normalise((1, 1, 0))
    probe2 = os.path.join(tmp, "sun.exr")
    spot_probe(probe2, [(sun, (200.0, 200.0, 200.0))], radius_deg=6.0, ambient=(0.05, 0.05, 0.05))
    floor = os.path.join(tmp, "floor.obj")
    write_obj(floor, [(-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)], [(0, 1, 2, 3)])
    ball = os.path.join(tmp, "ball.obj")
    write_obj(ball, *sphere_mesh((0, 0.1, 0), 0.1))
    cam = os.path.join(tmp, "top.json")
    write_camera(cam, (0, 2, 0), (0, 0, 0), (0, 0, -1), 20.0, 64, 48)  # image right = +X, image up = -Z
    out = os.path.join(tmp, "shadow.exr")
    secs, errs = build_and_render(probe2, floor, ball, cam, (0.8, 0.8, 0.8), (0.5, 0.5, 0.5), 32, 1, out, threads)
    check(all(e < 1e-6 for e in errs.values()), f"imported vertices = OBJ vertices under (x, y, z) -> (x, -z, y): "
                                                f"max error {max(errs.values()):.2g} m")
    comb, sc = render_passes(out)
    h, w = sc.shape[:2]
    # pixel of iblkit point (x, 0, z) seen from (0, 2, 0): px = W/2 + x / (2 tan 10) * H/2 ... (right = +X, down = +Z)
    f_px = (h / 2) / math.tan(math.radians(10))

    def px(x, z, y=0.0):
        return int(w / 2 + x / (2 - y) * f_px), int(h / 2 + z / (2 - y) * f_px)

    def sc_at(x, z):
        i, j = px(x, z)
        return float(sc[j - 1:j + 2, i - 1:i + 2].mean())

    shadow_side, lit_side, far = sc_at(-0.16, 0), sc_at(0.16, 0), sc_at(0.3, 0.25)
    check(shadow_side < 0.5 * lit_side, f"shadow catcher: towards -X {shadow_side:.3f}, towards +X {lit_side:.3f} "
                                        "(the sun is at +X: the shadow must fall towards -X)")
    check(abs(far - 1) < 0.1, f"shadow catcher far from the sphere: {far:.3f} (1 = untouched)")
    check(float(comb[..., 3][px(0.3, 0.25)[1], px(0.3, 0.25)[0]]) < 1e-3, "combined alpha on the catcher is 0")
    i_r, j_r = px(0.07, 0, 0.15)
    i_l, j_l = px(-0.07, 0, 0.15)
    right, left = float(comb[j_r, i_r, :3].mean()), float(comb[j_l, i_l, :3].mean())
    check(right > 2 * left, f"sphere lit side: +X side {right:.3f}, -X side {left:.3f}")
    check(float(comb[px(0, 0, 0.2)[1], px(0, 0, 0.2)[0], 3]) > 0.99, "combined alpha on the sphere is 1")

    # 3. the compositing formula, on Blender's own terms: a "backplate" B (the floor alone, an ordinary diffuse
    # object) and a "truth" T (floor and sphere, both ordinary) against combined + (1 - alpha) * B * shadow catcher
    plain = os.path.join(tmp, "plate.exr")
    truth = os.path.join(tmp, "truth.exr")
    for path, objects in ((plain, False), (truth, True)):
        scene = reset_scene()
        render_settings(scene, 64, 7, threads, transparent=False)
        world_from_probe(scene, probe2)
        import_obj(floor, "floor", (0.5, 0.5, 0.5))
        if objects:
            import_obj(ball, "ball", (0.8, 0.8, 0.8))
        add_camera(scene, read_camera(cam))
        render(scene, path)
    b, t = render_passes(plain)[0][..., :3], render_passes(truth)[0][..., :3]
    comp = comb[..., :3] + (1 - comb[..., 3:4]) * b * sc
    whole = float(np.abs(comp - t).sum() / t.sum())
    i, j = px(-0.16, 0)
    dark_c, dark_t = float(comp[j - 2:j + 3, i - 2:i + 3].mean()), float(t[j - 2:j + 3, i - 2:i + 3].mean())
    check(whole < 0.1, f"combined + (1 - alpha) * plate * shadow catcher = the plain render with the sphere: "
                       f"L1 {100 * whole:.1f} % (noise of 32 and 64 samples)")
    check(abs(dark_c - dark_t) < 0.25 * dark_t, f"  in the shadow: composite {dark_c:.4f}, plain render {dark_t:.4f}")
    print(f"render_seconds {secs:.3f}")
    print("selftest " + ("passed" if not failures else f"FAILED ({len(failures)})"))
    return 0 if not failures else 1


# ---- command line ---------------------------------------------------------------------------------------------------
def rgb(text):
    v = [float(t) for t in text.split(",")]
    if len(v) != 3 or not all(0 <= t <= 1 for t in v):
        raise argparse.ArgumentTypeError(f"{text!r}: want r,g,b in [0, 1]")
    return tuple(v)


def main(argv):
    ap = argparse.ArgumentParser(prog="blender -b --factory-startup -P blender_shadow_catcher.py --",
                                 description=__doc__.split("\n")[0])
    ap.add_argument("--selftest", action="store_true", help="prove the conventions and exit (1 on failure)")
    ap.add_argument("--keep", help="selftest: keep its files in this folder")
    ap.add_argument("--probe")
    ap.add_argument("--proxy")
    ap.add_argument("--object")
    ap.add_argument("--camera")
    ap.add_argument("--object-albedo", type=rgb, default=(0.7, 0.7, 0.7))
    ap.add_argument("--proxy-albedo", type=rgb, default=(0.5, 0.5, 0.5))
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=0, help="render threads (0: Blender's automatic count)")
    ap.add_argument("--proxy-rays", choices=("all", "camera"), default="all",
                    help="all: the proxy is an ordinary object to every ray (it shades, bounces light onto the object "
                         "and shadows the world); camera: only camera rays see it (it catches the object's shadow "
                         "but neither blocks nor reflects the world: for a closed room whose light the probe "
                         "already holds)")
    ap.add_argument("--object-smooth-deg", type=float, default=40.0,
                    help="shade the object smooth with Blender's auto smooth at this angle (iblkit's crease for mesh "
                         "files); 0: flat facets, as the OBJ (which has no normals) says literally")
    ap.add_argument("--max-bounces", type=int, default=-1,
                    help="limit Cycles' total and diffuse bounces to N (default -1: Cycles' defaults, 12 and 4)")
    ap.add_argument("--out")
    a = ap.parse_args(argv)
    if a.selftest:
        return selftest(a.keep, a.threads or 1)
    missing = [n for n in ("probe", "proxy", "object", "camera", "out") if not getattr(a, n)]
    if missing:
        ap.error("missing " + ", ".join("--" + n for n in missing))
    if a.samples < 1:
        ap.error("--samples must be at least 1")
    secs, errs = build_and_render(a.probe, a.proxy, a.object, a.camera, a.object_albedo, a.proxy_albedo, a.samples,
                                  a.seed, a.out, a.threads, proxy_rays=a.proxy_rays,
                                  smooth_deg=a.object_smooth_deg, max_bounces=a.max_bounces)
    print(f"import_max_vertex_error_m {max(errs.values()):.3g}")
    print(f"render_seconds {secs:.3f}")
    return 0


if __name__ == "__main__":
    _argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        _rc = main(_argv)
    except SystemExit as e:  # argparse and our refusals: Blender would swallow a plain exception and exit 0
        if e.code not in (None, 0) and not isinstance(e.code, int):
            print(f"error: {e.code}", file=sys.stderr)
        _rc = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    except Exception:  # noqa: BLE001 - report and fail, whatever it is
        import traceback
        traceback.print_exc()
        _rc = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(_rc)  # Blender's -P would otherwise carry on and exit 0 whatever happened
