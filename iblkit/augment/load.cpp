#include "iblkit/augment/load.h"

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/io/image_io.h"

namespace ibl::augment {

namespace {

constexpr double kOutsideShare = 0.5;  // a point whose rays meet back faces more often than this is outside

bool ends_with(const std::string& s, const std::string& e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

// Share of rays from x whose first proxy hit is a back face (among those that hit).
double backface_share(const geometry::TriMesh& proxy, Vec3 x) {
  geometry::RayTracer rt;
  rt.add(proxy);
  rt.commit();
  constexpr int kRays = 256;
  int hits = 0, back = 0;
  for (int i = 0; i < kRays; ++i) {  // spherical Fibonacci directions
    double z = 1 - (2 * i + 1.0) / kRays, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = i * kPi * (3 - std::sqrt(5.0));
    Vec3 d{r * std::cos(phi), z, r * std::sin(phi)};
    geometry::Hit h = rt.intersect(x, d);
    if (!h.hit) continue;
    ++hits;
    back += dot(proxy.normal(h.triangle), d) > 0;
  }
  return hits > 0 ? static_cast<double>(back) / hits : 0;
}

bool is_identity(const Mat3& r) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (r.m[i][j] != (i == j ? 1.0 : 0.0)) return false;
  return true;
}

sphere::EnvMap to_world(const sphere::EnvMap& m, const Mat3& rotation) {
  if (is_identity(rotation)) return m;
  sphere::ResampleDesc rd;
  rd.rotation = rotation;
  return sphere::EnvMap(sphere::resample(m, m.mapping, rd), m.mapping);
}

// The object's centre must lie inside the proxy (where the captured light describes the scene).
void require_inside(const geometry::TriMesh& proxy, Vec3 centre, const std::string& what) {
  double back = backface_share(proxy, centre);
  if (back > kOutsideShare)
    fail(ErrorKind::Value,
         "the object's centre ({:.3g}, {:.3g}, {:.3g}) lies outside the proxy of {} ({:.0f} % of its rays meet back "
         "faces): the "
         "captured light says nothing about it there; move it (at)",
         centre.x, centre.y, centre.z, what, 100 * back);
}

std::string probe_outside(const geometry::TriMesh& proxy, Vec3 p) {
  double back = backface_share(proxy, p);
  if (back <= kOutsideShare) return {};
  return fmt::format(
      "the probe at ({:.3g}, {:.3g}, {:.3g}) lies outside the proxy ({:.0f} % of its rays meet back "
      "faces): its light is projected onto the proxy from there all the same",
      p.x, p.y, p.z, 100 * back);
}

}  // namespace

LoadedLight load_light(const LightInput& in, Vec3 lo, Vec3 hi) {
  LoadedLight out;
  const Vec3 centre = (lo + hi) * 0.5;
  if (in.probes.empty() == in.light.empty())
    fail(ErrorKind::Value, "give the light as either a probe set or a light file (not both)");
  if (!in.probes.empty()) {
    if (!in.proxy.empty())
      fail(ErrorKind::Value, "{}: a probe set names its own proxy; leave the proxy out", in.probes);
    fusion::ProbeSet set = fusion::load_probe_set(in.probes);
    out.warnings = set.warnings;
    out.proxy = set.proxy;
    if (set.probes.size() == 1) {
      const fusion::Probe& p = set.probes[0];
      out.light.map = to_world(p.radiance, p.rotation);
      out.light.centre = p.position;
      if (p.depth_source == fusion::DepthSource::File && is_identity(p.rotation)) out.light.depth = p.depth;
      out.light.source = "probe";
      require_inside(out.proxy, centre, in.probes);  // (a set's probes outside its proxy: fusion::prepare's check)
    } else {
      fusion::PointCheck pc = fusion::check_point(set, centre);
      if (pc.backface > kOutsideShare)
        fail(ErrorKind::Value,
             "the object's centre ({:.3g}, {:.3g}, {:.3g}) lies outside the proxy of {} ({:.0f} % of its rays meet "
             "back faces)",
             centre.x, centre.y, centre.z, in.probes, 100 * pc.backface);
      out.light = light_from_probes(set, centre, in.fused_map_size);
    }
    return out;
  }
  if (in.proxy.empty()) fail(ErrorKind::Value, "{}: a light file needs a proxy mesh (the local scene)", in.light);
  out.proxy = geometry::read_mesh(in.proxy);
  if (out.proxy.triangle_count() == 0) fail(ErrorKind::Value, "{}: the proxy has no triangles", in.proxy);
  require_inside(out.proxy, centre, in.proxy);
  if (ends_with(in.light, ".shgrid")) {
    if (in.at_probe) fail(ErrorKind::Value, "{}: an SH grid has no probe position; leave at_probe out", in.light);
    ilf::SHGrid g = ilf::read_shgrid(in.light);
    const Vec3 gmin = g.grid().volume.min, gmax = g.grid().volume.max;
    constexpr double kSlack = 1e-6;  // metres: on the volume's faces is inside
    for (int a = 0; a < 3; ++a) {
      if (centre[a] < gmin[a] - kSlack || centre[a] > gmax[a] + kSlack)
        fail(ErrorKind::Value,
             "the object's centre ({:.3g}, {:.3g}, {:.3g}) lies outside the SH grid's volume ({:.3g}, {:.3g}, "
             "{:.3g})..({:.3g}, {:.3g}, {:.3g})",
             centre.x, centre.y, centre.z, gmin.x, gmin.y, gmin.z, gmax.x, gmax.y, gmax.z);
      if (lo[a] < gmin[a] - kSlack || hi[a] > gmax[a] + kSlack) {
        out.warnings.push_back("the object reaches outside the SH grid's volume; it is lit by the grid at its centre");
        break;
      }
    }
    out.light = light_from_grid(g, centre, in.grid_map_size);
    return out;
  }
  if (!in.at_probe) fail(ErrorKind::Value, "{}: a probe image needs its position (at_probe)", in.light);
  out.light.map = io::read_envmap(in.light, in.read);
  out.light.centre = *in.at_probe;
  out.light.source = "probe";
  if (!in.probe_depth.empty()) {
    Image d = io::read_image(in.probe_depth);
    if (d.width() != out.light.map.image.width() || d.height() != out.light.map.image.height())
      fail(ErrorKind::Value, "{}: depth map {}x{} and probe {}x{} differ in size", in.probe_depth, d.width(),
           d.height(), out.light.map.image.width(), out.light.map.image.height());
    Image one(d.width(), d.height(), 1);
    for (int y = 0; y < d.height(); ++y)
      for (int x = 0; x < d.width(); ++x) one.at(x, y, 0) = d.at(x, y, 0);
    out.light.depth = std::move(one);
  }
  if (auto w = probe_outside(out.proxy, *in.at_probe); !w.empty()) out.warnings.push_back(w);
  return out;
}

}  // namespace ibl::augment
