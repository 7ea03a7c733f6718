#include "render_truth.h"
#ifdef IBLKIT_HAVE_GEOMETRY
#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/view.h"

namespace iblcli {

using namespace ibl;

LabPhotograph photograph_frame(const std::string& scene_path, const render::FrameDesc& d, int samples, int bounces,
                               const ProgressFn& progress) {
  geometry::require_camera(d.camera);
  lab::Scene scene = lab::load_scene(scene_path, false);
  LabPhotograph p;
  for (size_t i = 0; i < d.objects.size(); ++i)
    p.objects.push_back(
        lab::add_object(scene, "object " + std::to_string(i), *d.objects[i].mesh, d.objects[i].material.albedo));
  scene.build();
  lab::ViewDesc vd;
  vd.width = d.camera.width;
  vd.height = d.camera.height;
  vd.samples = samples;
  vd.render = scene.render;
  vd.render.bounces = bounces;
  const geometry::Camera cam = d.camera;
  lab::View v = lab::photograph(
      scene,
      [&](double px, double py, Vec3* o, Vec3* dir) {
        *o = cam.eye;
        *dir = cam.ray_direction(px, py);
      },
      vd, progress);
  p.radiance = std::move(v.radiance);
  p.surface = std::move(v.surface);
  std::vector<double> lum;
  for (int y = 0; y < vd.height; ++y)
    for (int x = 0; x < vd.width; ++x)
      if (std::find(p.objects.begin(), p.objects.end(), static_cast<int>(p.surface.at(x, y, 0))) != p.objects.end())
        lum.push_back(luminance(p.radiance.rgb(x, y)));
  if (lum.empty())
    fail(ErrorKind::Value, "no pixel of the frame sees the objects in {}: check --at, --eye and --target", scene_path);
  std::nth_element(lum.begin(), lum.begin() + lum.size() / 2, lum.end());
  p.median = lum[lum.size() / 2];
  return p;
}

TruthComparison compare(const LabPhotograph& photo, const render::RenderResult& rendered) {
  const int W = photo.radiance.width(), H = photo.radiance.height();
  if (rendered.color.width() != W || rendered.color.height() != H)
    fail(ErrorKind::Value, "frame {}x{} and photograph {}x{} differ in size", rendered.color.width(),
         rendered.color.height(), W, H);
  TruthComparison c;
  c.error = Image(W, H, 1, -1.0f);
  double sum_abs = 0, sum_ref = 0, first_abs = 0, first_ref = 0, first_render = 0;
  std::vector<double> rel;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      int s = static_cast<int>(photo.surface.at(x, y, 0));
      auto it = std::find(photo.objects.begin(), photo.objects.end(), s);
      if (it == photo.objects.end() || rendered.coverage.at(x, y, 0) <= 0) continue;
      double a = luminance(rendered.color.rgb(x, y)), b = luminance(photo.radiance.rgb(x, y));
      sum_abs += std::abs(a - b);
      sum_ref += b;
      ++c.pixels;
      double e = std::abs(a - b) / std::max(b, 1e-6);
      c.error.at(x, y, 0) = static_cast<float>(e);
      if (it == photo.objects.begin()) {
        first_abs += std::abs(a - b);
        first_ref += b;
        first_render += a;
        rel.push_back(e);
        ++c.first_pixels;
      }
    }
  if (c.pixels == 0) fail(ErrorKind::Value, "the frame and the photograph share no object pixel");
  c.rel_l1 = sum_ref > 0 ? sum_abs / sum_ref : 0;
  c.rel_l1_first = first_ref > 0 ? first_abs / first_ref : 0;
  if (!rel.empty()) {
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    c.median_rel = rel[rel.size() / 2];
    c.mean_render = first_render / c.first_pixels;
    c.mean_truth = first_ref / c.first_pixels;
  }
  return c;
}

}  // namespace iblcli
#endif
