"""Chrome-ball probes from numpy photographs (capture/ball.h): the binding against closed forms."""
import numpy as np
import pytest

import iblkit


def ball_photo(size=160, r=70.0, value=2.0, backdrop=0.05):
    """An orthographic photograph of a chrome ball of reflectance 1 under a uniform sky of radiance `value`."""
    y, x = np.mgrid[0:size, 0:size] + 0.5
    inside = (x - size / 2) ** 2 + (y - size / 2) ** 2 < r * r
    img = np.full((size, size, 3), backdrop, np.float32)
    img[inside] = value
    return img


def test_find_ball():
    fit = iblkit.find_ball(ball_photo())
    cx, cy, r = fit["ball"]
    assert abs(cx - 80) < 0.5 and abs(cy - 80) < 0.5 and abs(r - 70) < 0.75
    assert fit["coverage"] > 0.9
    with pytest.raises(iblkit.InvalidValue, match=r"balls="):
        iblkit.find_ball(np.full((64, 64, 3), 0.5, np.float32))


def test_uniform_sky_comes_back():
    probe, weights = iblkit.probe_from_ball([ball_photo()], balls=[(80, 80, 70)], distance=0, fresnel="none",
                                            reflectance=[1.0], size=32)
    assert probe.shape == (32, 64, 4) and weights.shape == (32, 64)
    seen = probe[..., 3] > 0.999
    assert seen.mean() > 0.9
    # Bilinear samples next to the rim mix in the backdrop: the sky is 2.0 everywhere else.
    assert np.median(probe[seen][:, :3]) == pytest.approx(2.0, rel=1e-6)
    # Chrome's Fresnel rise: the photograph divided by R(θ) ≤ 1/F(0) = 1.81, R(0) = F(0) = 0.552.
    chrome, _ = iblkit.probe_from_ball([ball_photo()], balls=[(80, 80, 70)], distance=8, size=32)
    centre = chrome[16, 48, :3]  # +Z, towards the camera: normal incidence
    assert centre[0] == pytest.approx(2.0 / 0.5518, rel=0.01)


def test_bad_input():
    with pytest.raises(iblkit.InvalidValue):
        iblkit.probe_from_ball([], distance=5)
    with pytest.raises(iblkit.InvalidValue, match="partly outside"):
        iblkit.probe_from_ball([ball_photo()], balls=[(150, 80, 70)], distance=5)


def test_calibrate_ball_from_a_known_light():
    """A light of radiance 10 seen in an orthographic ball of reflectance 0.6 (no rise) and directly: r0 = 0.6."""
    img = ball_photo(value=0.05)
    img[40:60, 90:110] = 6.0  # the light's reflection, inside the disc
    direct = np.full((32, 32, 3), 0.1, np.float32)
    direct[8:24, 8:24] = 10.0
    fit = iblkit.calibrate_ball(img, (85, 35, 30, 30), direct, (4, 4, 24, 24), ball=(80, 80, 70), fresnel="none")
    assert fit["reflectance"] == pytest.approx((0.6, 0.6, 0.6), rel=1e-6)
    assert fit["ball_pixels"] == 400 and fit["direct_pixels"] == 256
    with pytest.raises(iblkit.InvalidValue, match="leaves its"):
        iblkit.calibrate_ball(img, (150, 35, 30, 30), direct, (4, 4, 24, 24), ball=(80, 80, 70))
    with pytest.raises(iblkit.InvalidValue, match=r"\(x, y, w, h\)"):
        iblkit.calibrate_ball(img, (85, 35, 30), direct, (4, 4, 24, 24), ball=(80, 80, 70))
