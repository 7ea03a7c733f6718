#include "iblkit/fusion/evaluate.h"

#include <cmath>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::fusion {

double image_rmse(const sphere::EnvMap& est, const sphere::EnvMap& truth) {
  const auto& m = truth.mapping;
  if (est.mapping.kind() != m.kind() || est.mapping.width() != m.width() || est.mapping.height() != m.height())
    fail(ErrorKind::Value, "image error: a {}x{} map against a {}x{} truth in another mapping or size",
         est.mapping.width(), est.mapping.height(), m.width(), m.height());
  double s2 = 0, sy = 0, sw = 0;
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      double w = m.solid_angle_estimate(x, y);
      double yt = luminance(truth.image.rgb(x, y)), ye = luminance(est.image.rgb(x, y));
      s2 += w * (ye - yt) * (ye - yt);
      sy += w * yt;
      sw += w;
    }
  return sy > 0 ? std::sqrt(s2 / sw) / (sy / sw) : 0;
}

geometry::Camera view_camera(Vec3 x, Vec3 forward) {
  require_point("view position", x);
  const Vec3 f = require_direction("view direction", forward);
  geometry::Camera c;
  c.eye = x;
  c.target = x + f;
  c.up = std::abs(f.y) > 0.99 ? Vec3{0, 0, 1} : Vec3{0, 1, 0};
  c.width = 320;
  c.height = 200;
  c.fov_y_deg = 2 * std::atan(1.0 * c.height / c.width) * 180 / kPi;  // tan(45°)·h/w vertically
  return c;
}

std::vector<Vec3> pixel_directions(const geometry::Camera& c) {
  std::vector<Vec3> d;
  d.reserve(static_cast<size_t>(c.width) * c.height);
  for (int j = 0; j < c.height; ++j)
    for (int i = 0; i < c.width; ++i) d.push_back(c.pixel_direction(i, j));
  return d;
}

Image view_image(const geometry::Camera& c, const std::vector<Vec3>& L) {
  if (L.size() != static_cast<size_t>(c.width) * c.height)
    fail(ErrorKind::Value, "view image: {} radiances for {}x{} pixels", L.size(), c.width, c.height);
  Image img(c.width, c.height, 3);
  for (int j = 0; j < c.height; ++j)
    for (int i = 0; i < c.width; ++i) img.set_rgb(i, j, L[static_cast<size_t>(j) * c.width + i]);
  return img;
}

PointEval evaluate_point(const ProbeSet& set, Vec3 x, const Reference& ref, const EvalDesc& desc) {
  if (!ref.radiance_map) fail(ErrorKind::Value, "fusion evaluation: the reference has no radiance map");
  if (desc.view && !ref.radiance_along)
    fail(ErrorKind::Value, "fusion evaluation: a view needs the reference's radiance along rays");
  require_point("evaluation point", x);
  static const std::vector<Vec3> normals = sphere::icosphere_face_centres(5);  // 20480 (Madsen & Laursen)
  PointEval pe;
  pe.truth = ref.radiance_map(x, desc.fuse.size);
  const auto e_truth = lights::irradiance_ground_truth(pe.truth, normals);
  for (Blend b : {Blend::Nearest, Blend::Angle, Blend::Footprint})
    for (bool vis : {false, true}) {
      FuseDesc fd = desc.fuse;
      fd.mapping = sphere::MappingKind::LatLong;
      fd.blend = b;
      fd.visibility = vis;
      LocalMap m = fuse(set, x, fd);
      const auto st = lights::compare_irradiance(lights::irradiance_ground_truth(m.radiance, normals), e_truth);
      pe.rows.push_back({x, b, vis, image_rmse(m.radiance, pe.truth), st.mean_rel, st.max_rel, m.stats});
      pe.maps.push_back(std::move(m));
    }
  if (desc.view) {
    pe.camera = view_camera(x, *desc.view);
    const auto dirs = pixel_directions(pe.camera);
    pe.view_truth = view_image(pe.camera, ref.radiance_along(x, dirs));
    for (bool vis : {false, true})
      for (Blend b : {Blend::Angle, Blend::Footprint}) {
        FuseDesc fd = desc.fuse;
        fd.blend = b;
        fd.visibility = vis;
        pe.views.push_back({b, vis, view_image(pe.camera, fuse_rays(set, x, dirs, fd))});
      }
  }
  return pe;
}

}  // namespace ibl::fusion
