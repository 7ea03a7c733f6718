"""Side-by-side bench: iblkit's composite against Blender 3.4's Cycles shadow catcher on the same capture.

    python3 bench/composite_vs_blender.py --capture DIR [--layers DIR/layers] [--samples 64,256,512,1024] \
        [--iblkit-composite DIR/composite.jpg] [--iblkit-json composite.json] [--threads 0] \
        [--json blender.json] [--picture blender.png]

DIR is a capture folder as `iblkit lab shoot ... --backplate --out DIR` writes it (capture.json naming the backplate,
the truth photograph and its mask, and the object's albedo); the layers folder is what
`iblkit composite --capture DIR --layers L` writes: probe_matched.exr (the light in the photograph's units),
proxy.obj, object.obj, camera.json. For each sample count this script runs bench/blender_shadow_catcher.py in
Blender (a fresh `blender -b --factory-startup` each time, timed), composites its render over the backplate in linear
light and measures the composite against the truth with iblkit.measure_composite and the truth mask, as
`iblkit composite` measures its own. It prints a table (samples, render seconds, object %, shadow %), writes it as
JSON (--json) and a picture strip (--picture): backplate | iblkit composite | Blender at the highest count | truth,
each the linear image through the sRGB curve at exposure 0 (the backplate as photographed; no other tone mapping).

The backplate and the truth are JPEG/PNG codes; --response srgb (the default, as `iblkit composite`'s default for 8-bit
files) decodes them with the sRGB curve, --response linear takes codes/255 as they are.

Compositing. Sources: the Blender manual (Rendering > Cycles > Object Settings > Object > Visibility > Shadow
Catcher, render/cycles/object_settings/object_data.html; the same note stands in the 3.0 to 4.4 editions we could
read; the 3.4 English page itself was not in our stored copies): with the Shadow Catcher pass enabled "all indirect
light interactions are captured", without it a simple approximation is used. The Cycles X shadow-catcher revision
(developer.blender.org, 2021) describes the pass: "the result is calculated as combined pass divided by the pass with
shadow catcher object. This gives a pass which is to be multiplied with a backdrop", while the CG objects' matte pass
"is to be alpha-over onto the backdrop"; commit 02767cf142aa (D11632) removes the catcher from Combined before the
division. So, Backdrop x Shadow Catcher, then Alpha Over with the premultiplied Combined pass:
    composite = combined.rgb + (1 - combined.alpha) * backplate_linear * shadow_catcher
bench/blender_shadow_catcher.py --selftest checks this formula on Blender's own renders: with a plain render of the
floor as the backdrop it reproduces the plain render with the object (L1 1.5 % at 32/64 samples).

Needs numpy (Debian's /usr/bin/python3 has it; the pyenv python3 may not) and, for the measure, the iblkit Python
module from build/python (it is added to sys.path). Without the module the script falls back to its own numpy port of
augment/measure.cpp and says so (the JSON's "measure"); with it, both run and their largest difference is recorded.
"""

import argparse
import json
import os
import re
import struct
import subprocess
import sys
import time
import zlib

try:
    import numpy as np
except ImportError:
    sys.exit("composite_vs_blender.py needs numpy: run it with a python3 that has it (Debian's /usr/bin/python3)")

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(REPO, "build", "python"))
from blender_shadow_catcher import render_passes  # noqa: E402  (our EXR reader; bpy is not needed for it)

try:
    import iblkit  # noqa: E402
    if not hasattr(iblkit, "measure_composite"):  # an empty build/python/iblkit folder imports as a namespace
        raise ImportError(f"{list(iblkit.__path__)} holds no built iblkit module")
except ImportError as e:  # the lead may not have built it yet
    iblkit = None
    IBLKIT_IMPORT_ERROR = str(e)
else:
    IBLKIT_IMPORT_ERROR = ""

SCRIPT = os.path.join(HERE, "blender_shadow_catcher.py")


# ---- images ---------------------------------------------------------------------------------------------------------
def srgb_to_linear(v):
    v = np.asarray(v, np.float64)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(v):
    v = np.clip(np.asarray(v, np.float64), 0, 1)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


def read_codes(path):
    """An 8-bit photograph's codes / 255, (H, W, C) float64."""
    if iblkit is not None:
        img = np.asarray(iblkit.read_image(path), np.float64)  # 8-bit files come back sRGB-decoded: undo it
        return linear_to_srgb(img)
    try:
        from PIL import Image
    except ImportError:
        sys.exit(f"{path}: neither the iblkit module nor PIL is importable to read it")
    with Image.open(path) as im:
        a = np.asarray(im, np.float64) / (65535.0 if im.mode.startswith("I;16") else 255.0)
    return a[..., None] if a.ndim == 2 else a


def read_photo(path, response):
    """A photograph in linear light through the response (srgb or linear), RGB."""
    if iblkit is not None and response == "srgb":
        img = np.asarray(iblkit.read_image(path), np.float64)  # iblkit's own decoding, as `composite` reads it
    else:
        codes = read_codes(path)
        img = srgb_to_linear(codes) if response == "srgb" else codes
    if img.ndim == 2:
        img = img[..., None]
    if img.shape[2] == 1:
        img = np.repeat(img, 3, axis=2)
    return img[..., :3]


def read_mask(path):
    """The truth mask, one channel in [0, 1], read the way `iblkit composite` reads it (iblkit.read_image)."""
    if iblkit is not None:
        m = np.asarray(iblkit.read_image(path), np.float64)
    else:
        m = srgb_to_linear(read_codes(path))  # iblkit decodes 8-bit PNGs with the sRGB curve: same values
    return m if m.ndim == 2 else m[..., 0]


def write_png(path, rgb8):
    """An 8-bit RGB PNG (our own writer: no imaging module needed)."""
    h, w, _ = rgb8.shape
    raw = b"".join(b"\0" + rgb8[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


def display(img):
    """Linear RGB to 8-bit sRGB codes, exposure 0 (the same for every panel)."""
    return np.round(255 * linear_to_srgb(img[..., :3])).astype(np.uint8)


# ---- the measure ----------------------------------------------------------------------------------------------------
def _luminance(img):
    return 0.2125 * img[..., 0] + 0.7154 * img[..., 1] + 0.0721 * img[..., 2]


def _box_luminance(img, r=1):
    y = _luminance(img)
    h, w = y.shape
    s = np.zeros_like(y)
    n = np.zeros_like(y)
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            ys, yd = slice(max(0, dy), h + min(0, dy)), slice(max(0, -dy), h + min(0, -dy))
            xs, xd = slice(max(0, dx), w + min(0, dx)), slice(max(0, -dx), w + min(0, -dx))
            s[yd, xd] += y[ys, xs]
            n[yd, xd] += 1
    return s / n


def measure_numpy(photo, comp, truth, mask, tau=0.02):
    """A numpy port of augment::measure (iblkit/augment/measure.cpp), for when the iblkit module is absent."""
    l1 = lambda a: np.abs(a).sum(axis=-1)  # noqa: E731
    bp, bt = _box_luminance(photo), _box_luminance(truth)
    obj = mask >= 1
    rest = mask <= 0
    shadow = rest & (bp - bt > tau * bp)
    bright = rest & ~shadow & (bt - bp > tau * bp)
    same = rest & ~shadow & ~bright
    e = {}
    od, sd, ud = l1(truth)[obj].sum(), l1(photo - truth)[shadow].sum(), l1(truth)[same].sum()
    e["object"] = float(l1(comp - truth)[obj].sum() / od) if od > 0 else 0.0
    e["shadow"] = float(l1(comp - truth)[shadow].sum() / sd) if sd > 0 else 0.0
    e["unchanged"] = float(l1(comp - truth)[same].sum() / ud) if ud > 0 else 0.0
    e["object_pixels"], e["shadow_pixels"] = int(obj.sum()), int(shadow.sum())
    e["brightened_pixels"], e["unchanged_pixels"] = int(bright.sum()), int(same.sum())
    e["shadow_signal"] = float(((bp - bt)[shadow] / bp[shadow]).mean()) if shadow.any() else 0.0
    return e


def measure(photo, comp, truth, mask):
    """iblkit.measure_composite when the module is there (checked against the numpy port), else the port."""
    mine = measure_numpy(photo, comp, truth, mask)
    if iblkit is None:
        return mine, None
    f32 = lambda a: np.ascontiguousarray(a, np.float32)  # noqa: E731
    theirs = dict(iblkit.measure_composite(f32(photo), f32(comp), f32(truth), f32(mask[..., None])))
    diff = max(abs(theirs[k] - mine[k]) for k in ("object", "shadow", "unchanged"))
    return theirs, diff


def proxy_is_closed(path):
    """Whether an OBJ's faces close up: every edge shared by exactly two faces (a room box, not a floor).

    Vertices are welded by position (to 0.1 mm) first: iblkit writes each face's corners separately."""
    edges, verts = {}, []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append(tuple(round(float(t) * 1e4) for t in line.split()[1:4]))
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) for t in line.split()[1:]]
                idx = [verts[i - 1 if i > 0 else len(verts) + i] for i in idx]
                for i, j in zip(idx, idx[1:] + idx[:1]):
                    e = (min(i, j), max(i, j))
                    edges[e] = edges.get(e, 0) + 1
    return bool(edges) and all(n == 2 for n in edges.values())


# ---- Blender --------------------------------------------------------------------------------------------------------
def blender_version(blender):
    out = subprocess.run([blender, "--version"], capture_output=True, text=True).stdout
    return out.splitlines()[0].strip() if out else "unknown"


def run_blender(blender, layers, camera, object_albedo, proxy_albedo, samples, seed, threads, out, proxy_rays):
    cmd = [blender, "-b", "--factory-startup", "-noaudio", "-P", SCRIPT, "--",
           "--probe", os.path.join(layers, "probe_matched.exr"), "--proxy", os.path.join(layers, "proxy.obj"),
           "--object", os.path.join(layers, "object.obj"), "--camera", camera,
           "--object-albedo", ",".join(f"{v:.6g}" for v in object_albedo),
           "--proxy-albedo", ",".join(f"{v:.6g}" for v in proxy_albedo),
           "--samples", str(samples), "--seed", str(seed), "--threads", str(threads), "--proxy-rays", proxy_rays,
           "--out", out]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    m = re.search(r"^render_seconds ([0-9.eE+-]+)$", p.stdout, re.M)
    if p.returncode != 0 or not m or not os.path.exists(out):
        tail = "\n".join((p.stdout + "\n" + p.stderr).strip().splitlines()[-25:])
        sys.exit(f"Blender failed at {samples} samples (exit {p.returncode}):\n{tail}")
    return float(m.group(1)), wall


def blender_composite(exr, backplate):
    comb, sc = render_passes(exr)
    comb, sc = comb.astype(np.float64), sc.astype(np.float64)
    if comb.shape[:2] != backplate.shape[:2]:
        sys.exit(f"{exr}: {comb.shape[1]}x{comb.shape[0]}, the backplate is {backplate.shape[1]}x{backplate.shape[0]}")
    # Blender 3.4's shadow-catcher composite (see the docstring): alpha-over of the premultiplied Combined pass onto
    # the backdrop multiplied by the Shadow Catcher pass.
    return comb[..., :3] + (1 - comb[..., 3:4]) * backplate * sc


# ---- main -----------------------------------------------------------------------------------------------------------
def rgb(text):
    v = [float(t) for t in text.split(",")]
    if len(v) != 3 or not all(0 <= t <= 1 for t in v):
        raise argparse.ArgumentTypeError(f"{text!r}: want r,g,b in [0, 1]")
    return tuple(v)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--capture", required=True, help="the capture folder (capture.json, backplate, truth, mask)")
    ap.add_argument("--layers", help="what `iblkit composite --capture DIR --layers L` wrote (default DIR/layers)")
    ap.add_argument("--samples", default="64,256,512,1024", help="Cycles sample counts, comma-separated")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=0, help="Blender render threads (0: all cores)")
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--proxy-rays", default="auto",
                    help="blender_shadow_catcher.py's --proxy-rays: all, camera, both (each sample count twice), or "
                         "auto (the default): camera when the proxy is closed (a room would shut the distant world "
                         "out), all otherwise")
    ap.add_argument("--work", help="where the Blender renders go (default LAYERS/blender)")
    ap.add_argument("--response", choices=("srgb", "linear"), default="srgb",
                    help="how the backplate's and the truth's codes become linear light")
    ap.add_argument("--object-albedo", type=rgb, help="default: capture.json's object.albedo")
    ap.add_argument("--proxy-albedo", type=rgb,
                    help="the catcher's Diffuse colour (it matters only for light the proxy throws onto the object); "
                         "default: the median of LAYERS/albedo.exr where it is positive, else 0.5,0.5,0.5")
    ap.add_argument("--iblkit-composite", help="iblkit's composite of the same capture (default DIR/composite.jpg "
                                               "if it exists), measured the same way for the table and the picture")
    ap.add_argument("--iblkit-json", help="`iblkit --json composite ...`'s output: its seconds and errors")
    ap.add_argument("--json", help="write the table here")
    ap.add_argument("--picture", help="write the picture strip here (PNG)")
    a = ap.parse_args()

    cap_dir = a.capture
    layers = a.layers or os.path.join(cap_dir, "layers")
    for f in ("probe_matched.exr", "proxy.obj", "object.obj", "camera.json"):
        if not os.path.exists(os.path.join(layers, f)):
            sys.exit(f"{layers}: {f} is missing; run `iblkit composite --capture {cap_dir} --layers {layers}` first")
    with open(os.path.join(cap_dir, "capture.json")) as f:
        cap = json.load(f)
    if "truth" not in cap:
        sys.exit(f"{cap_dir}/capture.json has no truth photograph to measure against")
    if cap.get("response") and a.response == "srgb" and cap["response"] != "srgb":
        print(f"note: capture.json names the response {cap['response']!r}; this bench decodes with {a.response}")
    samples = [int(s) for s in a.samples.split(",") if s.strip()]
    if not samples or min(samples) < 1:
        sys.exit("--samples: want positive integers")
    object_albedo = a.object_albedo or tuple(cap.get("object", {}).get("albedo", (0.7, 0.7, 0.7)))
    proxy_albedo, proxy_albedo_source = a.proxy_albedo, "--proxy-albedo"
    if proxy_albedo is None:
        path = os.path.join(layers, "albedo.exr")
        proxy_albedo, proxy_albedo_source = (0.5, 0.5, 0.5), "default 0.5 (no albedo.exr in the layers)"
        if os.path.exists(path) and iblkit is not None:
            alb = np.asarray(iblkit.read_image(path), np.float64)[..., :3].reshape(-1, 3)
            alb = alb[alb.min(axis=1) > 0]
            if len(alb):
                proxy_albedo = tuple(float(v) for v in np.clip(np.median(alb, axis=0), 0, 1))
                proxy_albedo_source = "median of " + path

    backplate = read_photo(os.path.join(cap_dir, cap["backplate"]), a.response)
    truth = read_photo(os.path.join(cap_dir, cap["truth"]["photograph"]), a.response)
    if "mask" not in cap["truth"]:
        sys.exit(f"{cap_dir}/capture.json: the truth has no mask")
    mask = read_mask(os.path.join(cap_dir, cap["truth"]["mask"]))
    work = a.work or os.path.join(layers, "blender")
    os.makedirs(work, exist_ok=True)
    camera = os.path.join(layers, "camera.json")
    with open(camera) as f:
        cam = json.load(f)
    size = (int(backplate.shape[1]), int(backplate.shape[0]))
    if "width" not in cam or "height" not in cam:  # optional in iblkit.camera/1: the photograph's size
        cam["width"], cam["height"] = size
        camera = os.path.join(work, "camera.json")
        with open(camera, "w") as f:
            json.dump(cam, f)
    if (cam["width"], cam["height"]) != size:
        sys.exit(f"camera.json is {cam['width']}x{cam['height']}, the backplate {size[0]}x{size[1]}")
    version = blender_version(a.blender)
    rows, comps, checks = [], {}, []
    print(f"{version}, {backplate.shape[1]}x{backplate.shape[0]}, threads {a.threads or 'all'}, object albedo "
          f"{object_albedo}, proxy albedo {tuple(round(v, 4) for v in proxy_albedo)} ({proxy_albedo_source})")
    print("measure: " + ("iblkit.measure_composite (and the numpy port, compared)" if iblkit else
                         f"numpy port of augment/measure.cpp (iblkit module: {IBLKIT_IMPORT_ERROR})"))
    closed = proxy_is_closed(os.path.join(layers, "proxy.obj"))
    auto_mode = "camera" if closed else "all"
    if a.proxy_rays == "auto":
        a.proxy_rays = auto_mode
        print(f"proxy rays: {a.proxy_rays} (the proxy is {'closed' if closed else 'open'})")
    print(f"{'renderer':<22} {'samples':>7} {'render s':>9} {'process s':>9} {'object %':>9} {'shadow %':>9} "
          f"{'unchanged %':>11}")
    modes = ["all", "camera"] if a.proxy_rays == "both" else [a.proxy_rays]
    if any(m not in ("all", "camera") for m in modes):
        sys.exit(f"--proxy-rays {a.proxy_rays!r}: want all, camera or both")
    for mode in modes:
        name = "cycles" if mode == "all" else "cycles-camrays"
        for n in samples:
            out = os.path.join(work, f"{name}_{n}.exr")
            secs, wall = run_blender(a.blender, layers, camera, object_albedo, proxy_albedo, n, a.seed, a.threads,
                                     out, mode)
            comp = blender_composite(out, backplate)
            comps[(mode, n)] = comp
            e, diff = measure(backplate, comp, truth, mask)
            if diff is not None:
                checks.append(diff)
            row = {"renderer": "blender-" + name, "proxy_rays": mode, "samples": n, "render_seconds": round(secs, 3),
                   "process_seconds": round(wall, 3), "render": out}
            row.update({k: e[k] for k in ("object", "shadow", "unchanged", "object_pixels", "shadow_pixels",
                                          "brightened_pixels", "unchanged_pixels", "shadow_signal")})
            rows.append(row)
            print(f"{'blender-' + name:<22} {n:>7} {secs:>9.2f} {wall:>9.2f} {100 * e['object']:>9.2f} "
                  f"{100 * e['shadow']:>9.2f} {100 * e['unchanged']:>11.2f}", flush=True)

    ib = None
    ib_path = a.iblkit_composite or (os.path.join(cap_dir, "composite.jpg")
                                     if os.path.exists(os.path.join(cap_dir, "composite.jpg")) else None)
    if ib_path:
        ib_img = read_photo(ib_path, a.response) if not ib_path.endswith(".exr") else \
            np.asarray(iblkit.read_image(ib_path), np.float64)[..., :3]
        e, diff = measure(backplate, ib_img, truth, mask)
        if diff is not None:
            checks.append(diff)
        ib = {"renderer": "iblkit", "composite": ib_path}
        ib.update({k: e[k] for k in ("object", "shadow", "unchanged", "object_pixels", "shadow_pixels")})
        if a.iblkit_json:
            with open(a.iblkit_json) as f:
                j = json.load(f)
            ib["seconds"] = j.get("seconds")
            ib["errors_reported"] = j.get("errors")
        s = ib.get("seconds")
        s = f"{s:.2f}" if isinstance(s, (int, float)) else "-"
        print(f"{'iblkit':<22} {'-':>7} {s:>9} {'-':>9} {100 * e['object']:>9.2f} "
              f"{100 * e['shadow']:>9.2f} {100 * e['unchanged']:>11.2f}")
        comps["iblkit"] = ib_img

    panels = []
    if a.picture:
        strip = [display(backplate)]
        panels.append("backplate")
        if "iblkit" in comps:
            strip.append(display(comps["iblkit"]))
            panels.append("iblkit composite")
        top = max(samples)
        shown = auto_mode if auto_mode in modes else modes[0]
        strip.append(display(comps[(shown, top)]))
        panels.append(f"Blender Cycles shadow catcher, {top} samples, proxy rays {shown}")
        strip.append(display(truth))
        panels.append("truth")
        gap = np.full((backplate.shape[0], 4, 3), 255, np.uint8)
        pieces = []
        for k, p in enumerate(strip):
            pieces += [p] + ([gap] if k + 1 < len(strip) else [])
        write_png(a.picture, np.concatenate(pieces, axis=1))
        print(f"picture: {a.picture} ({' | '.join(panels)}; sRGB curve, exposure 0)")

    if a.json:
        doc = {"bench": "composite_vs_blender", "capture": cap_dir, "layers": layers, "blender": version,
               "size": [int(backplate.shape[1]), int(backplate.shape[0])], "threads": a.threads,
               "response": a.response, "object_albedo": list(object_albedo), "proxy_albedo": list(proxy_albedo),
               "proxy_albedo_source": proxy_albedo_source,
               "measure": "iblkit.measure_composite" if iblkit else "numpy port of augment/measure.cpp",
               "measure_port_max_difference": max(checks) if checks else None,
               "cycles": "CPU, adaptive sampling off, no denoising, clamping off, box filter 1 px, default bounces "
                         "(max 12, diffuse 4, glossy 4), film transparent, Shadow Catcher pass",
               "proxy_rays": modes, "proxy_closed": closed,
               "composite": "combined.rgb + (1 - combined.alpha) * backplate_linear * shadow_catcher",
               "render_seconds": "bpy.ops.render.render wall time (Cycles sync, BVH, render; no Blender start-up)",
               "process_seconds": "the whole blender process: start-up, scene build, render, EXR write",
               "rows": rows, "iblkit": ib, "picture": a.picture, "panels": panels}
        tmp = a.json + ".tmp"
        with open(tmp, "w") as f:
            json.dump(doc, f, indent=2)
        os.replace(tmp, a.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
