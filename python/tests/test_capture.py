"""iblkit.hdr_merge on numpy brackets (issue 29 §1): a known radiance through the sRGB curve, exact truth."""
import numpy as np
import pytest

import iblkit


def srgb_encode(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def bracket():
    h, w = 64, 128
    ramp = np.exp2(np.linspace(-8, 4, w))[None, :, None] * np.ones((h, 1, 3))
    tex = 0.6 + 0.4 * np.sin(np.arange(h) * 0.7)[:, None, None]
    L = (ramp * tex).astype(np.float64)
    ex = [2.0 ** (2 * j - 8) for j in range(5)]
    imgs = [np.round(srgb_encode(L * e) * 255).astype(np.float32) / 255 for e in ex]
    return L, imgs, ex


def test_known_curve_gives_radiance():
    L, imgs, ex = bracket()
    hdr, rep = iblkit.hdr_merge(imgs, ex, response="srgb", align=False)
    assert hdr.shape == L.shape and np.all(np.isfinite(hdr))
    X = np.stack([L * e for e in ex])
    ok = np.any((X > 0.05) & (X < 0.95), axis=0)
    # 8-bit quantisation only: well under 1 %
    assert np.median(np.abs(hdr[ok] / L[ok] - 1)) < 0.01
    assert rep["response"] == "srgb" and rep["curve"].shape == (1, 4096, 3)


def test_recovered_and_errors():
    L, imgs, ex = bracket()
    hdr, rep = iblkit.hdr_merge(imgs, ex, align=False)
    assert rep["response"] == "debevec" and len(rep["shifts"]) == 5
    with pytest.raises(ValueError, match="one exposure per image"):
        iblkit.hdr_merge(imgs, ex[:4])
    with pytest.raises(ValueError, match="one photograph"):
        iblkit.hdr_merge(imgs[:1], ex[:1])
    with pytest.raises(ValueError, match="outside"):
        iblkit.hdr_merge([i * 255 for i in imgs], ex)


def test_camera_solve_from_points_gives_the_camera_back():
    """Exact points projected through a known camera (Camera.project) give it back, in depth and on the floor."""
    truth = iblkit.Camera(eye=(0.35, 1.15, 2.3), target=(0.05, 0.25, 0.1), fov_y_deg=42, width=320, height=240)
    rng = np.random.default_rng(3)
    for floor in (False, True):
        world = rng.uniform((-1, 0, -1), (1, 0 if floor else 1.2, 1), size=(20, 3))
        pts = [(truth.project(tuple(w)), tuple(w)) for w in world]
        cam, rep = iblkit.camera_solve(points=pts, width=320, height=240, fov=42)
        assert rep["coplanar"] == floor
        assert rep["reprojection_rms_px"] < 1e-6
        assert np.allclose(cam.eye, truth.eye, atol=1e-6)
        solved, rep2 = iblkit.camera_solve(points=pts, width=320, height=240)  # the focal length too
        assert rep2["lens"] == "focal solved" and abs(solved.fov_y_deg - 42) < 1e-4
    with pytest.raises(ValueError, match="either points= or board="):
        iblkit.camera_solve(width=320, height=240)
    with pytest.raises(ValueError, match="at least 6"):
        iblkit.camera_solve(points=pts[:5], width=320, height=240, fov=42)


def test_camera_solve_from_a_charuco_board(tmp_path):
    """The lab's backplate with a ChArUco board on the floor (a pool of light across it): the camera within 5 mm."""
    from conftest import run_cli
    try:
        run_cli("lab", "shoot", "low-scene2", "--at", "0,0.15,0", "--width", 64, "--height", 64, "--samples", 1,
                "--bracket", 2, "--backplate", "--plate-samples", 2, "--plate-width", 960, "--plate-height", 720,
                "--board", "charuco:5x4:0.2:0.15", "--board-at", "-0.2,0,0.6", "--out", tmp_path / "set")
    except AssertionError as e:
        if "no aruco module" in str(e):
            pytest.skip("this build's OpenCV has no aruco module (libopencv-contrib-dev)")
        raise
    import json
    board = json.load(open(tmp_path / "set" / "capture.json"))["board"]
    photo = iblkit.read_image(str(tmp_path / "set" / "backplate.jpg"))
    cam, rep = iblkit.camera_solve(photo, board=board["spec"], board_origin=tuple(board["origin"]), fov=50)
    assert rep["points"] >= 8 and rep["reprojection_rms_px"] < 0.5, rep
    assert np.linalg.norm(np.array(cam.eye) - (0.3, 1.4, 2.2)) < 5e-3, cam.eye
    assert rep["dropped"] >= 0
    with pytest.raises(iblkit.Error, match="marker size"):
        iblkit.camera_solve(photo, board="charuco:5x4:0.2:0.3", fov=50)
