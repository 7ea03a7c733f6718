#!/usr/bin/env python3
"""Writes crypt.obj: a small vaulted room (Granier et al., Fig. 7 "Crypt", about 500 triangles).

A 6 m x 8 m room with 2.2 m walls under a semicircular barrel vault along z (apex 5.2 m), closed by
two lunette end walls, with four square pillars. Fronts face into the room (pillars: outwards).
Run: python3 examples/make_crypt.py > examples/crypt.obj
"""
import math

V, F = [], []

def quad(a, b, c, d):
    i = len(V)
    V.extend([a, b, c, d])
    F.append((i, i + 1, i + 2)); F.append((i, i + 2, i + 3))

def tri(a, b, c):
    i = len(V)
    V.extend([a, b, c])
    F.append((i, i + 1, i + 2))

W, L, H, SEG, SLICES = 3.0, 4.0, 2.2, 16, 14
quad((-W, 0, -L), (-W, 0, L), (W, 0, L), (W, 0, -L))                 # floor, facing +y
quad((-W, 0, -L), (-W, H, -L), (-W, H, L), (-W, 0, L))               # -x wall, facing +x
quad((W, 0, -L), (W, 0, L), (W, H, L), (W, H, -L))                   # +x wall, facing -x
quad((-W, 0, -L), (W, 0, -L), (W, H, -L), (-W, H, -L))               # -z wall (rectangle), facing +z
quad((-W, 0, L), (-W, H, L), (W, H, L), (W, 0, L))                   # +z wall, facing -z
arc = [(W * math.cos(math.pi * k / SEG), H + W * math.sin(math.pi * k / SEG)) for k in range(SEG + 1)]
for s in range(SLICES):                                              # vault, facing down/in
    z0, z1 = -L + 2 * L * s / SLICES, -L + 2 * L * (s + 1) / SLICES
    for k in range(SEG):
        (x0, y0), (x1, y1) = arc[k], arc[k + 1]
        quad((x0, y0, z0), (x0, y0, z1), (x1, y1, z1), (x1, y1, z0))
for k in range(SEG):                                                 # lunettes
    (x0, y0), (x1, y1) = arc[k], arc[k + 1]
    tri((0, H, -L), (x0, y0, -L), (x1, y1, -L))
    tri((0, H, L), (x1, y1, L), (x0, y0, L))
for px in (-1.3, 1.3):                                               # pillars, 0.4 m square
    for pz in (-1.6, 1.6):
        a, top = 0.2, H + 0.8
        c = [(px - a, pz - a), (px + a, pz - a), (px + a, pz + a), (px - a, pz + a)]
        for k in range(4):
            (x0, z0), (x1, z1) = c[k], c[(k + 1) % 4]
            quad((x0, 0, z0), (x1, 0, z1), (x1, top, z1), (x0, top, z0))

def fix(f):  # orient: front towards the room's centre line (walls) or away from a pillar's axis
    a, b, c = (V[i] for i in f)
    n = [(b[1]-a[1])*(c[2]-a[2])-(b[2]-a[2])*(c[1]-a[1]), (b[2]-a[2])*(c[0]-a[0])-(b[0]-a[0])*(c[2]-a[2]),
         (b[0]-a[0])*(c[1]-a[1])-(b[1]-a[1])*(c[0]-a[0])]
    m = [(a[i] + b[i] + c[i]) / 3 for i in range(3)]
    pil = [(px, pz) for px in (-1.3, 1.3) for pz in (-1.6, 1.6) if abs(m[0]-px) <= 0.21 and abs(m[2]-pz) <= 0.21]
    ref = (pil[0][0], m[1], pil[0][1]) if pil else (0, 1.5, 0)
    to = [m[i] - ref[i] for i in range(3)] if pil else [ref[i] - m[i] for i in range(3)]
    return f if sum(n[i] * to[i] for i in range(3)) > 0 else (f[0], f[2], f[1])

print("# crypt: a small vaulted room after Granier et al. (Fig. 7), written by make_crypt.py")
print(f"# {len(F)} triangles")
for v in V:
    print("v %.4f %.4f %.4f" % v)
for f in F:
    f = fix(f)
    print("f %d %d %d" % (f[0] + 1, f[1] + 1, f[2] + 1))
