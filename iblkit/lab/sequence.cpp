#include "iblkit/lab/sequence.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/core/rng.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/ilf/sequence.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"

namespace ibl::lab {

namespace fs = std::filesystem;
using nlohmann::json;

// A capture holds every position (and the manifest every entry) in memory and renders each probe:
// at most kMaxProbes of them.
constexpr double kMaxProbes = 1e6;
static void require_probe_count(const std::string& what, double n, const char* hint) {
  if (n > kMaxProbes)
    fail(ErrorKind::Value,
         "{} of {:.4g} probes exceeds the {:g} a capture supports ({:.3g} GB for the positions alone); {}", what, n,
         kMaxProbes, n * sizeof(Vec3) / 1e9, hint);
}

std::vector<Vec3> grid_positions(Vec3 lo, Vec3 hi, int nx, int ny, int nz) {
  if (nx < 1 || ny < 1 || nz < 1) fail(ErrorKind::Value, "grid counts {}x{}x{} must be ≥ 1", nx, ny, nz);
  require_box("grid volume", lo, hi);
  require_probe_count(fmt::format("a grid of {}x{}x{}", nx, ny, nz), double(nx) * ny * nz,
                      "choose fewer grid points per axis");
  auto at = [](double a, double b, int i, int n) { return n == 1 ? 0.5 * (a + b) : a + (b - a) * i / (n - 1); };
  std::vector<Vec3> p;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) p.push_back({at(lo.x, hi.x, i, nx), at(lo.y, hi.y, j, ny), at(lo.z, hi.z, k, nz)});
  return p;
}

std::vector<Vec3> path_positions(const std::vector<Vec3>& pts, int count) {
  if (pts.empty()) fail(ErrorKind::Value, "a path needs at least one point");
  if (count < 1) fail(ErrorKind::Value, "path probe count {} must be ≥ 1", count);
  for (size_t i = 0; i < pts.size(); ++i) require_point(fmt::format("path point {}", i + 1), pts[i]);
  require_probe_count("a path", count, "choose a smaller probe count");
  std::vector<double> acc{0};
  for (size_t i = 1; i < pts.size(); ++i) acc.push_back(acc.back() + length(pts[i] - pts[i - 1]));
  std::vector<Vec3> out;
  for (int k = 0; k < count; ++k) {
    double s = count == 1 ? 0 : acc.back() * k / (count - 1);
    size_t i = 1;
    while (i < acc.size() && acc[i] < s) ++i;
    if (i >= acc.size()) {
      out.push_back(pts.back());
      continue;
    }
    double seg = acc[i] - acc[i - 1], t = seg > 0 ? (s - acc[i - 1]) / seg : 0;
    out.push_back(pts[i - 1] + (pts[i] - pts[i - 1]) * t);
  }
  return out;
}

std::vector<Vec3> random_positions(Vec3 lo, Vec3 hi, int count, uint64_t seed) {
  if (count < 1) fail(ErrorKind::Value, "random probe count {} must be ≥ 1", count);
  require_box("random volume", lo, hi);
  require_probe_count("a random capture", count, "choose a smaller random probe count");
  std::vector<Vec3> p;
  Rng rng(stream_key(seed, ~0ull, 0, 0));
  for (int i = 0; i < count; ++i) {
    double a = rng.uniform(), b = rng.uniform(), c = rng.uniform();
    p.push_back({lo.x + (hi.x - lo.x) * a, lo.y + (hi.y - lo.y) * b, lo.z + (hi.z - lo.z) * c});
  }
  return p;
}

std::vector<Vec3> cluster_positions(Vec3 lo, Vec3 hi, int clusters, int count, double spread, uint64_t seed) {
  if (count < 1) fail(ErrorKind::Value, "cluster probe count {} must be ≥ 1", count);
  if (clusters < 1 || clusters > count)
    fail(ErrorKind::Value, "cluster count {} must lie in [1, {}] (the probe count)", clusters, count);
  require_box("cluster volume", lo, hi);
  require_number("cluster spread (metres)", spread, 1e-9, 1e6);
  require_probe_count("a clustered capture", count, "choose a smaller probe count");
  std::vector<Vec3> centre;
  for (int c = 0; c < clusters; ++c) {
    Rng rng(stream_key(seed, ~1ull, static_cast<uint64_t>(c), 0));
    Vec3 v;
    for (int a = 0; a < 3; ++a) {
      double m = std::min(spread, 0.25 * (hi[a] - lo[a]));
      v[a] = lo[a] + m + (hi[a] - lo[a] - 2 * m) * rng.uniform();
    }
    centre.push_back(v);
  }
  std::vector<Vec3> p;
  p.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    Rng rng(stream_key(seed, ~2ull, static_cast<uint64_t>(i), 0));
    const Vec3 c = centre[static_cast<size_t>(i % clusters)];
    Vec3 v = c;
    for (int attempt = 0; attempt < 64; ++attempt) {
      for (int a = 0; a < 3; ++a) {  // Box–Muller: one normal deviate per axis
        double u1 = 1 - rng.uniform(), u2 = rng.uniform();
        v[a] = c[a] + spread * std::sqrt(-2 * std::log(u1)) * std::cos(kTwoPi * u2);
      }
      if (v.x >= lo.x && v.x <= hi.x && v.y >= lo.y && v.y <= hi.y && v.z >= lo.z && v.z <= hi.z) break;
    }
    for (int a = 0; a < 3; ++a) v[a] = std::clamp(v[a], lo[a], hi[a]);
    p.push_back(v);
  }
  return p;
}

namespace {

json vec_json(Vec3 v) { return json::array({v.x, v.y, v.z}); }

json rotation_json(const Mat3& m) {
  json r = json::array();
  for (auto& row : m.m) r.push_back({row[0], row[1], row[2]});
  return r;
}

void make_dir(const fs::path& p) { ibl::make_output_folders(p.string()); }

// Captures every probe and hands it to `sink(k, capture)` on a writer thread while the next one
// renders, so memory stays at two probes. Picks the contact-sheet probes on the way.
template <typename Sink>
std::vector<std::pair<std::string, Image>> stream(const Scene& scene, const std::vector<Vec3>& positions,
                                                  const SequenceDesc& desc, const ProgressFn& progress, Sink sink) {
  if (positions.empty()) fail(ErrorKind::Value, "no probe positions");
  size_t n = positions.size(), sheet = std::min<size_t>(desc.sheet_probes, n);
  std::vector<std::pair<std::string, Image>> pics;
  std::future<void> writing;
  for (size_t k = 0; k < n; ++k) {
    Capture cap = capture_probe(scene, positions[k], desc.capture, k);
    if (sheet && (k * sheet) / n != ((k + 1) * sheet) / n) {
      Vec3 p = positions[k];
      pics.push_back({fmt::format("#{} ({:.2f}, {:.2f}, {:.2f})", k, p.x, p.y, p.z),
                      io::resize(io::tonemap(cap.radiance), 256, 256 * cap.radiance.height() / cap.radiance.width())});
    }
    if (writing.valid()) writing.get();
    writing = std::async(std::launch::async, [&sink, k, c = std::move(cap)] { sink(k, c); });
    report(progress, "probes", static_cast<double>(k + 1) / n);
  }
  if (writing.valid()) writing.get();
  return pics;
}

std::string write_sheet(const std::vector<std::pair<std::string, Image>>& pics, const fs::path& out,
                        const std::string& title) {
  if (pics.empty()) return {};
  int cols = std::min<int>(4, static_cast<int>(pics.size()));
  Image sheet = io::contact_sheet(pics, cols, 256, pics[0].second.height(), title);
  std::string path = (out / "contact_sheet.png").string();
  io::write_image(path, sheet);
  return path;
}

std::string describe(const Scene& scene, const SequenceDesc& d) {
  return fmt::format("{}: {} {} px{}", scene.name, sphere::mapping_name(d.capture.mapping), d.capture.size,
                     d.capture.camera == Camera::MirrorBall ? ", mirror-ball camera" : "");
}

}  // namespace

SequenceResult write_sequence(const Scene& scene, const std::vector<Vec3>& positions, const SequenceDesc& desc,
                              const ProgressFn& progress) {
  for (size_t i = 0; i < positions.size(); ++i) require_point(fmt::format("probe position {}", i + 1), positions[i]);
  auto t0 = std::chrono::steady_clock::now();
  fs::path out(desc.out_dir);
  make_dir(out / "frames");
  ilf::Sequence seq;
  seq.mapping = desc.capture.mapping;
  seq.dead_angle_deg = desc.capture.dead_angle_deg;
  seq.rotation = desc.capture.rotation;
  seq.scene = scene.name;
  if (desc.capture.camera == Camera::MirrorBall && desc.capture.ball_parallax)
    seq.ball.radius = desc.capture.ball_radius;  // the orthographic ball camera's rays start on the ball
  Vec3 lo = positions.empty() ? Vec3{} : positions[0], hi = lo;
  bool inside = true;
  for (Vec3 p : positions) {
    ilf::ProbeEntry e;
    e.image = (out / fmt::format("frames/{:06d}{}", seq.probes.size(), desc.frame_ext)).string();
    e.position = p;
    if (desc.capture.depth)
      e.depth = (out / fmt::format("frames/{:06d}_depth{}", seq.probes.size(), desc.frame_ext)).string();
    seq.probes.push_back(e);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
      inside = inside && p[k] >= scene.volume_min[k] && p[k] <= scene.volume_max[k];
    }
  }
  seq.volume = inside ? ilf::Box{scene.volume_min, scene.volume_max} : ilf::Box{lo, hi};
  seq.volume_given = true;
  auto pics = stream(scene, positions, desc, progress, [&](size_t k, const Capture& c) {
    io::write_image(seq.probes[k].image, c.radiance, {desc.half});
    if (c.depth.width())
      io::write_image((out / fmt::format("frames/{:06d}_depth{}", k, desc.frame_ext)).string(), c.depth, {desc.half});
  });
  SequenceResult r;
  r.manifest = (out / "sequence.json").string();
  ilf::write_sequence(r.manifest, seq);
  r.contact_sheet = write_sheet(pics, out, describe(scene, desc));
  r.probes = positions.size();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

SequenceResult write_probe_set(const Scene& scene, const std::vector<Vec3>& positions, const SequenceDesc& desc,
                               const ProgressFn& progress) {
  for (size_t i = 0; i < positions.size(); ++i) require_point(fmt::format("probe position {}", i + 1), positions[i]);
  auto t0 = std::chrono::steady_clock::now();
  fs::path out(desc.out_dir);
  make_dir(out / "probes");
  SequenceDesc d = desc;
  d.capture.depth = true;
  geometry::write_obj((out / "proxy.obj").string(), scene.proxy_mesh(), "proxy of lab scene " + scene.name);
  json probes = json::array();
  for (size_t k = 0; k < positions.size(); ++k)
    probes.push_back({{"image", fmt::format("probes/p{}{}", k, desc.frame_ext)},
                      {"depth", fmt::format("probes/p{}_depth{}", k, desc.frame_ext)},
                      {"position", vec_json(positions[k])},
                      {"rotation", rotation_json(desc.capture.rotation)}});
  auto pics = stream(scene, positions, d, progress, [&](size_t k, const Capture& c) {
    io::write_image((out / fmt::format("probes/p{}{}", k, desc.frame_ext)).string(), c.radiance, {desc.half});
    io::write_image((out / fmt::format("probes/p{}_depth{}", k, desc.frame_ext)).string(), c.depth, {desc.half});
  });
  json m = {{"format", "iblkit.probes/1"},
            {"proxy", "proxy.obj"},
            {"mapping", sphere::mapping_name(desc.capture.mapping)},
            {"scene", scene.name},
            {"probes", probes}};
  SequenceResult r;
  r.manifest = (out / "probes.json").string();
  write_json_file(r.manifest, m);
  r.contact_sheet = write_sheet(pics, out, describe(scene, d));
  r.probes = positions.size();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace ibl::lab
