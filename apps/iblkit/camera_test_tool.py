#!/usr/bin/python3
"""Test helper of cli_test_camera.sh: a peer's view of a camera (OpenCV's projectPoints, undistortPoints and
remap), independent of iblkit's own Camera.

  camera_test_tool.py points CAM.json OUT.json {depth|floor} [SHIFT_PX]  world points projected through CAM
  camera_test_tool.py board CAM.json OUT.png COLS ROWS SQUARE ORIGIN U V  a chessboard photographed by CAM
  camera_test_tool.py compare TRUTH.json SOLVED.json [EYE_M DEG FX_PX]   differences; exit 1 beyond them
  camera_test_tool.py overlap A.exr B.exr MIN MAX                         masks' intersection over union in [MIN, MAX]

CAM is an iblkit.camera/1 file (fov_y_deg, or intrinsics and distortion). Pixels are iblkit's continuous
coordinates (OpenCV's + 0.5). The board follows docs/camera.md: COLS x ROWS inner corners, the first at
ORIGIN, columns along U, rows along V (comma lists), the square between the first four corners dark.
"""
import json
import os
import sys

os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")  # the masks are EXR files
import cv2  # noqa: E402
import numpy as np


def load(path):
    c = json.load(open(path))
    eye, target, up = (np.array(c[k], float) for k in ("eye", "target", "up"))
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    R = np.array([r, -u, f])
    w, h = c["width"], c["height"]
    if "intrinsics" in c:
        k = c["intrinsics"]
        K = np.array([[k["fx"], 0, k["cx"] - 0.5], [0, k["fy"], k["cy"] - 0.5], [0, 0, 1]])
    else:
        fl = h / (2 * np.tan(np.radians(c["fov_y_deg"]) / 2))
        K = np.array([[fl, 0, w / 2 - 0.5], [0, fl, h / 2 - 0.5], [0, 0, 1]])
    D = np.array(c.get("distortion", [0, 0, 0, 0, 0]), float)
    return dict(eye=eye, R=R, K=K, D=D, w=w, h=h, f=f, json=c)


def project(cam, world):
    rvec, _ = cv2.Rodrigues(cam["R"])
    tvec = -cam["R"] @ cam["eye"]
    px, _ = cv2.projectPoints(np.asarray(world, float).reshape(-1, 1, 3), rvec, tvec, cam["K"], cam["D"])
    return px.reshape(-1, 2) + 0.5


def points(cam_path, out, kind, shift="0"):
    cam = load(cam_path)
    world = []
    for i in range(5):
        for j in range(4):
            y = 0.0 if kind == "floor" else 0.12 * ((i * 3 + j) % 4)
            world.append([-0.5 + 0.25 * i, y, -0.45 + 0.3 * j])
    px = project(cam, world)
    px[0, 0] += float(shift)
    pts = [{"pixel": [float(p[0]), float(p[1])], "world": w} for p, w in zip(px, world)]
    json.dump({"format": "iblkit.points/1", "points": pts}, open(out, "w"), indent=1)


def board(cam_path, out, cols, rows, square, origin, u, v):
    cam = load(cam_path)
    cols, rows, square = int(cols), int(rows), float(square)
    origin, u, v = (np.array([float(x) for x in s.split(",")]) for s in (origin, u, v))
    u /= np.linalg.norm(u)
    v /= np.linalg.norm(v)
    n = np.cross(u, v)
    # The board's texture in corner units a in [-1.6, cols + 0.6], b in [-1.6, rows + 0.6], ppu texels a unit.
    ppu = 40
    tw, th = int((cols + 2.2) * ppu), int((rows + 2.2) * ppu)
    X, Y = np.meshgrid(np.arange(tw), np.arange(th))
    a, b = (X + 0.5) / ppu - 1.6, (Y + 0.5) / ppu - 1.6
    tex = np.full((th, tw), 0.8, np.float32)
    inside = (a > -1) & (a < cols) & (b > -1) & (b < rows)
    dark = ((np.floor(a).astype(int) + 1 + np.floor(b).astype(int) + 1) % 2) == 0
    tex[inside & dark] = 0.05
    # Every output pixel, 3x3 sub-samples: undistorted (OpenCV), its ray onto the board's plane, the texel.
    w, h = cam["w"], cam["h"]
    acc = np.zeros((h, w), np.float32)
    for sy in range(3):
        for sx in range(3):
            gx, gy = np.meshgrid(np.arange(w) + (sx + 0.5) / 3 - 0.5, np.arange(h) + (sy + 0.5) / 3 - 0.5)
            pix = np.stack([gx.ravel(), gy.ravel()], 1).reshape(-1, 1, 2)
            crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-12)
            norm = cv2.undistortPointsIter(pix, cam["K"], cam["D"], None, None, crit).reshape(-1, 2)
            d = np.stack([norm[:, 0], norm[:, 1], np.ones(len(norm))], 1) @ cam["R"]  # R^T (x, y, 1)
            t = ((origin - cam["eye"]) @ n) / (d @ n)
            p = cam["eye"] + d * t[:, None] - origin
            ta, tb = (p @ u) / square, (p @ v) / square
            mx = ((ta + 1.6) * ppu - 0.5).reshape(h, w).astype(np.float32)
            my = ((tb + 1.6) * ppu - 0.5).reshape(h, w).astype(np.float32)
            bad = (t <= 0).reshape(h, w)
            mx[bad] = -1e4
            s = cv2.remap(tex, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0.3)
            acc += s
    img = acc / 9
    srgb = np.where(img <= 0.0031308, 12.92 * img, 1.055 * np.power(img, 1 / 2.4) - 0.055)
    cv2.imwrite(out, np.clip(np.round(srgb * 255), 0, 255).astype(np.uint8))


def compare(truth_path, solved_path, eye_tol="inf", deg_tol="inf", fx_tol="inf"):
    t, s = load(truth_path), load(solved_path)
    de = np.linalg.norm(t["eye"] - s["eye"])
    ang = np.degrees(np.arccos(np.clip(t["R"][2] @ s["R"][2], -1, 1)))
    roll = np.degrees(np.arccos(np.clip(t["R"][1] @ s["R"][1], -1, 1)))
    fx = s["K"][0, 0] - t["K"][0, 0]
    cx, cy = s["K"][0, 2] - t["K"][0, 2], s["K"][1, 2] - t["K"][1, 2]
    k1 = s["D"][0] - t["D"][0]
    print(f"eye {de:.3e} m, view {ang:.3e} deg, roll {roll:.3e} deg, fx {fx:+.3e} px, "
          f"principal point {cx:+.3e},{cy:+.3e} px, k1 {k1:+.3e}")
    if not (de <= float(eye_tol) and max(ang, roll) <= float(deg_tol) and abs(fx) <= float(fx_tol)):
        print(f"beyond the tolerances: eye {eye_tol} m, angles {deg_tol} deg, fx {fx_tol} px")
        sys.exit(1)


def overlap(a_path, b_path, lo, hi):
    a, b = (cv2.imread(p, cv2.IMREAD_UNCHANGED) for p in (a_path, b_path))
    a, b = ((m if m.ndim == 2 else m[..., 0]) > 0.5 for m in (a, b))
    iou = (a & b).sum() / max(1, (a | b).sum())
    print(f"mask overlap {iou:.4f} ({(a ^ b).sum()} of {a.sum()} pixels differ)")
    sys.exit(0 if float(lo) <= iou <= float(hi) else 1)


if __name__ == "__main__":
    {"points": points, "board": board, "compare": compare, "overlap": overlap}[sys.argv[1]](*sys.argv[2:])
