#include "iblkit/lab/plate.h"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/lab/view.h"

namespace ibl::lab {

namespace {

// A flat rectangle from corner `o` spanning a·u and b·v, front side u × v, with UVs (0, 0) at o and (1, 1)
// at o + a·u + b·v.
geometry::TriMesh print_quad(Vec3 o, Vec3 u, Vec3 v, double a, double b) {
  geometry::TriMesh m;
  m.positions = {o, o + u * a, o + u * a + v * b, o + v * b};
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

}  // namespace

void add_board(Scene& scene, const capture::Board& board) {
  if (scene.built()) fail(ErrorKind::Internal, "lab::add_board: add the board before Scene::build");
  const Vec3 n = normalize(cross(board.u, board.v));
  const double s = board.square;
  // The outer corner of the squares: one square before the first inner corner along u and v.
  const Vec3 outer = board.origin - (board.u + board.v) * s;
  const double a = (board.cols + 1) * s, b = (board.rows + 1) * s;
  Surface margin;
  margin.name = "board margin";
  margin.mesh = print_quad(outer - (board.u + board.v) * s + n * 0.0005, board.u, board.v, a + 2 * s, b + 2 * s);
  margin.albedo.constant = {kBoardWhite, kBoardWhite, kBoardWhite};
  margin.proxy = false;
  scene.surfaces.push_back(std::move(margin));
  Surface print;
  print.name = "board";
  print.mesh = print_quad(outer + n * 0.001, board.u, board.v, a, b);
  print.proxy = false;
  if (board.charuco) {
    // OpenCV's print, 64 pixels a square, the page's bottom at the origin's side (the texture's v runs up the page).
    const Image page = capture::draw_charuco(board, 64);
    auto tex = std::make_shared<Image>(page.width(), page.height(), 3);
    for (int y = 0; y < page.height(); ++y)
      for (int x = 0; x < page.width(); ++x) {
        const double t = page.at(x, y, 0);
        const float al = static_cast<float>(kBoardDark + t * (kBoardWhite - kBoardDark));
        tex->set_rgb(x, y, {al, al, al});
      }
    print.albedo.image = tex;
    scene.surfaces.push_back(std::move(print));
    return;
  }
  print.albedo.checker = true;
  print.albedo.tiles = {static_cast<double>(board.cols + 1), static_cast<double>(board.rows + 1)};
  // Texture::eval gives `a` where the square's indices sum to an even number: square (1, 1), between the first
  // four inner corners, is dark.
  print.albedo.a = {kBoardDark, kBoardDark, kBoardDark};
  print.albedo.b = {kBoardWhite, kBoardWhite, kBoardWhite};
  scene.surfaces.push_back(std::move(print));
}

Plate shoot_plate(const Scene& base, const PlateDesc& d, const ProgressFn& progress) {
  if (base.built()) fail(ErrorKind::Internal, "lab::shoot_plate takes a scene that is not built yet");
  geometry::require_camera(d.camera);
  if (d.samples < 1 || d.samples > 64) fail(ErrorKind::Value, "samples {} out of range [1, 64]", d.samples);
  const geometry::Camera cam = d.camera;
  auto view = [&](const Scene& scene, double done, double share) {
    ViewDesc vd;
    vd.width = cam.width;
    vd.height = cam.height;
    vd.samples = d.samples;
    vd.render = d.render;
    return photograph(
        scene,
        [&](double px, double py, Vec3* o, Vec3* dir) {
          *o = cam.eye;
          *dir = cam.ray_direction(px, py);
        },
        vd, [&](std::string_view what, double f) { report(progress, what, done + share * f); });
  };
  const bool truth = d.object.triangle_count() > 0;
  Scene plain = base;
  plain.build();
  View without = view(plain, 0, truth ? 0.5 : 1.0);
  Plate p;
  capture::SensorDesc s = d.sensor;
  if (!(s.exposure_s > 0)) {
    std::vector<double> lum;
    lum.reserve(without.radiance.pixel_count());
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) lum.push_back(luminance(without.radiance.rgb(x, y)));
    std::sort(lum.begin(), lum.end());
    const double med = lum[lum.size() / 2], hi = lum[std::min(lum.size() - 1, lum.size() * 995 / 1000)];
    if (!(med > 0)) fail(ErrorKind::Value, "the backplate is black: give its exposure");
    // Middle grey for the median, as a meter would, but the highlights kept: the 99.5th percentile at most at 80 %
    // of saturation (a lamp's pool of light stays light, not a clipped patch a shadow cannot darken).
    const double per_unit = (s.iso / 100.0) / (s.f_number * s.f_number);  // relative exposure per radiance and second
    s.exposure_s = std::min(0.18 / med, 0.8 / hi) / per_unit;
  }
  capture::validate(s);
  p.exposure_s = s.exposure_s;
  p.sensor = s;
  p.backplate_radiance = without.radiance;
  p.backplate = capture::expose(without.radiance, s);
  const float top = 1.0f - 0.5f / static_cast<float>((1 << s.bits) - 1);
  for (size_t i = 0; i < p.backplate.pixel_count(); ++i)
    p.saturated +=
        std::max({p.backplate.data()[3 * i], p.backplate.data()[3 * i + 1], p.backplate.data()[3 * i + 2]}) >= top;
  if (!truth) return p;
  Scene with = base;
  const int object = add_object(with, "object", d.object, d.albedo);
  with.build();
  View v = view(with, 0.5, 0.5);
  p.truth_radiance = v.radiance;
  p.truth = capture::expose(v.radiance, s);  // the same seed: the same noise where the light is the same
  p.truth_mask = Image(cam.width, cam.height, 1);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x)
      p.truth_mask.at(x, y, 0) = static_cast<int>(v.surface.at(x, y, 0)) == object ? 1.0f : 0.0f;
  return p;
}

}  // namespace ibl::lab
