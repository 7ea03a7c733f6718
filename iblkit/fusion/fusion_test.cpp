// Fusion: depth tracing, back-projection and blending against closed forms on "painted"
// proxies (every proxy point has a known view-independent radiance, so the exact local map anywhere is
// known), the visibility test, bad input, localised lights and the path tracker.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numeric>
#include <random>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/testing.h"
#include "iblkit/fusion/fuse.h"
#include "iblkit/fusion/local_lights.h"
#include "iblkit/fusion/path.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/lights/evaluate.h"

using ibl::test_util::expect_error;

namespace ibl::fusion {
namespace {

namespace fs = std::filesystem;
using Paint = std::function<Vec3(Vec3 p, Vec3 n)>;

// Radiance a painted proxy sends from point p with front normal n (view-independent).
Vec3 smooth_paint(Vec3 p, Vec3) {
  return {1.0 + 0.3 * std::sin(2 * p.x) + 0.2 * std::cos(3 * p.z), 0.5 + 0.2 * p.y, 1.0 + 0.1 * p.x * p.z};
}
// Each face direction its own colour; the occluder of room_with_occluder() red, its two sides different.
Vec3 normal_paint(Vec3 p, Vec3 n) {
  if (std::abs(p.x) < 0.31 && p.y < 2.21 && std::abs(p.z) < 1.21) return Vec3{4.0, 0.4, 0.4} * (1 + 0.3 * n.x);
  return {0.6 + 0.5 * n.x, 0.6 + 0.5 * n.y, 0.6 + 0.5 * n.z};
}

// A lat-long probe of height h of the painted proxy seen from `pos` (pixel-centre rays), rotated by `rot`.
Probe paint_probe(const geometry::RayTracer& rt, const geometry::TriMesh& mesh, Vec3 pos, const Mat3& rot, int h,
                  const Paint& paint) {
  Probe p;
  p.position = pos;
  p.rotation = rot;
  sphere::Mapping m(sphere::MappingKind::LatLong, 2 * h, h);
  Image img(2 * h, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 2 * h; ++x) {
      Vec3 d;
      m.to_direction(x + 0.5, y + 0.5, &d);
      geometry::Hit hit = rt.intersect(pos, rot * d);
      if (hit.hit) img.set_rgb(x, y, paint(pos + rot * d * hit.t, mesh.normal(hit.triangle)));
    }
  p.radiance = sphere::EnvMap(img, m);
  return p;
}

ProbeSet painted_set(const geometry::TriMesh& mesh, const std::vector<Vec3>& positions, const std::vector<Mat3>& rots,
                     int h, const Paint& paint) {
  geometry::RayTracer rt;
  rt.add(mesh);
  rt.commit();
  ProbeSet set;
  set.proxy = mesh;
  for (size_t i = 0; i < positions.size(); ++i)
    set.probes.push_back(paint_probe(rt, mesh, positions[i], i < rots.size() ? rots[i] : Mat3(), h, paint));
  prepare(set);
  return set;
}

// The exact local map: the paint of the first proxy point along each pixel-centre ray.
Image exact_map(const ProbeSet& set, Vec3 x, const sphere::Mapping& m, const Paint& paint) {
  Image img(m.width(), m.height(), 3);
  for (int y = 0; y < m.height(); ++y)
    for (int i = 0; i < m.width(); ++i) {
      Vec3 d;
      if (!m.to_direction(i + 0.5, y + 0.5, &d)) continue;
      geometry::Hit h = set.tracer->intersect(x, d);
      if (h.hit) img.set_rgb(i, y, paint(x + d * h.t, set.proxy.normal(h.triangle)));
    }
  return img;
}

struct Diff {
  double mean_rel = 0, max_rel = 0, bad_share = 0;  // bad: luminance off by > 5%
};
Diff compare(const Image& a, const Image& b, const sphere::Mapping& m) {
  Diff d;
  double n = 0;
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      if (!m.valid(x, y)) continue;
      double ya = luminance(a.rgb(x, y)), yb = luminance(b.rgb(x, y));
      double r = std::abs(ya - yb) / std::max(yb, 1e-6);
      d.mean_rel += r;
      d.max_rel = std::max(d.max_rel, r);
      d.bad_share += r > 0.05;
      ++n;
    }
  d.mean_rel /= n;
  d.bad_share /= n;
  return d;
}

geometry::TriMesh box_room() { return geometry::make_box({-2, 0, -3}, {2, 3, 3}, true); }

// A room with a closed box standing between two probes.
geometry::TriMesh room_with_occluder() {
  geometry::TriMesh m = geometry::make_box({-4, 0, -2}, {4, 3, 2}, true);
  m.append(geometry::make_box({-0.3, 0, -1.2}, {0.3, 2.2, 1.2}));
  return m;
}

TEST(FusionProbeSet, TracedDepthIsTheRayBoxDistance) {
  constexpr double kFloatTol = 1e-5;  // relative: depth is stored as float (2^-24 ≈ 6e-8), Embree hits within 1e-6
  ProbeSet set;
  set.proxy = box_room();
  Probe p;
  p.position = {0.5, 1.2, -1};
  p.rotation = Mat3::rotation({0.3, 1, 0.2}, 0.7);
  p.radiance = sphere::EnvMap(Image(64, 32, 3, 1.0f), sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  set.probes.push_back(p);
  prepare(set);
  const Probe& q = set.probes[0];
  EXPECT_EQ(q.depth_source, DepthSource::Computed);
  EXPECT_EQ(q.escape_fraction, 0.0);
  EXPECT_TRUE(set.warnings.empty());
  const Vec3 lo{-2, 0, -3}, hi{2, 3, 3};
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      Vec3 d;
      q.radiance.mapping.to_direction(x + 0.5, y + 0.5, &d);
      Vec3 w = q.rotation * d;
      double t = 1e30;
      for (int k = 0; k < 3; ++k)
        if (std::abs(w[k]) > 1e-12) t = std::min(t, ((w[k] > 0 ? hi[k] : lo[k]) - q.position[k]) / w[k]);
      EXPECT_NEAR(q.depth.at(x, y, 0), t, kFloatTol * t) << x << "," << y;
    }
}

TEST(FusionFuse, AtAProbeEveryBlendGivesItsImageBack) {
  constexpr double kLookupTol = 2e-3;  // relative: fast_atan2 (1e-5 rad) moves bilinear lookups ~1e-4 px off centre
  auto mesh = box_room();
  auto set = painted_set(mesh, {{0, 1.5, -1}, {1, 1, 1.5}}, {}, 32, smooth_paint);
  for (Blend b : {Blend::Nearest, Blend::Angle, Blend::Footprint}) {
    FuseDesc fd;
    fd.blend = b;
    fd.size = 32;
    LocalMap lm = fuse(set, set.probes[0].position, fd);
    Diff d = compare(lm.radiance.image, set.probes[0].radiance.image, lm.radiance.mapping);
    if (b == Blend::Footprint) {
      // Footprint weights prefer the nearer, sharper probe, but probe 1 still carries some weight:
      // only the agreement of both with the paint is exact, not the pixel values.
      EXPECT_LT(d.mean_rel, 0.01) << blend_name(b);
    } else if (b == Blend::Nearest) {
      EXPECT_LT(d.max_rel, kLookupTol);
    } else {
      EXPECT_LT(d.mean_rel, 0.01) << "angle: both probes weigh in; they agree up to interpolation";
    }
    EXPECT_DOUBLE_EQ(lm.stats.fused, 1.0);
  }
}

TEST(FusionFuse, PaintedBoxOffTheProbesMatchesTheClosedForm) {
  // Probes with different rotations; the exact map at x is the paint along each ray. Errors come only
  // from bilinear interpolation of 64-row probes (≈(texel footprint)²/8·|f''| ≈ 0.2% on the smooth paint).
  constexpr double kMeanTol = 0.005;  // mean relative error: interpolation, plus corners seen at grazing angles
  auto mesh = box_room();
  std::vector<Mat3> rots = {Mat3(), Mat3::rotation({0, 1, 0}, 2.0), Mat3::rotation({1, 0.2, 0}, 0.9)};
  auto set = painted_set(mesh, {{-1, 1.5, -2}, {1, 1.2, 0}, {0, 2, 2}}, rots, 64, smooth_paint);
  Vec3 x{0.3, 1.0, -0.7};
  for (Blend b : {Blend::Nearest, Blend::Angle, Blend::Footprint}) {
    FuseDesc fd;
    fd.blend = b;
    fd.size = 48;
    LocalMap lm = fuse(set, x, fd);
    Image exact = exact_map(set, x, lm.radiance.mapping, smooth_paint);
    Diff d = compare(lm.radiance.image, exact, lm.radiance.mapping);
    EXPECT_LT(d.mean_rel, kMeanTol) << blend_name(b);
    EXPECT_DOUBLE_EQ(lm.stats.fused, 1.0) << "a convex room: every probe sees every point";
    EXPECT_NEAR(lm.stats.mean_probes, 3.0, 1e-9) << "the bias must not reject any probe in a convex room";
    // Depth channel: the distance to the box.
    Vec3 d0;
    lm.radiance.mapping.to_direction(10.5, 20.5, &d0);
    EXPECT_NEAR(lm.depth.at(10, 20, 0), set.tracer->intersect(x, d0).t, 1e-5);
  }
}

TEST(FusionVisibility, TheOccludedProbeIsLeftOutOnlyWithVisibility) {
  auto mesh = room_with_occluder();
  // Probe 0 on the −x side, probe 1 on the +x side of the occluder; x on the −x side, beside it.
  auto set = painted_set(mesh, {{-2, 1.5, 0.5}, {2, 1.5, 0}}, {}, 64, normal_paint);
  Vec3 x{-3, 1.0, -1.8};
  FuseDesc fd;
  fd.size = 48;
  fd.blend = Blend::Angle;
  Image exact;
  Diff on, off;
  for (bool vis : {true, false}) {
    fd.visibility = vis;
    LocalMap lm = fuse(set, x, fd);
    if (exact.empty()) exact = exact_map(set, x, lm.radiance.mapping, normal_paint);
    (vis ? on : off) = compare(lm.radiance.image, exact, lm.radiance.mapping);
    // Along +x x sees the +x wall past the occluder; probe 0 looks at that point from nearly the same
    // direction (ω·ω'_0 ≈ 0.93) but sees the occluder's −x face instead.
    Vec3 L = fuse_ray(set, x, {1, 0, 0}, fd);
    Vec3 want = normal_paint({4, 1, -1.8}, {-1, 0, 0});
    if (vis)
      EXPECT_NEAR(luminance(L), luminance(want), 1e-3);
    else
      EXPECT_GT(std::abs(luminance(L) - luminance(want)), 0.1)
          << "without visibility probe 1's view of the +x face leaks in";
  }
  // With visibility only pixels along the edges where the paint jumps are off (bilinear lookups blend
  // the two faces there: ~5% of a 96×48 map with 24 box edges); without, a large part of the map.
  constexpr double kEdgeShare = 0.10;  // measured 8.2%
  EXPECT_LT(on.bad_share, kEdgeShare) << "on " << on.bad_share << " off " << off.bad_share;
  EXPECT_GT(off.bad_share, 2 * on.bad_share) << "on " << on.bad_share << " off " << off.bad_share;
  EXPECT_LT(on.mean_rel, off.mean_rel / 2) << "on " << on.mean_rel << " off " << off.mean_rel;
}

TEST(FusionVisibility, PointsNoProbeSeesAreReportedAndFallBack) {
  auto mesh = room_with_occluder();
  auto set = painted_set(mesh, {{-2, 1.5, 0}}, {}, 32, normal_paint);
  // From (1.5, 1, 0) the occluder's +x face is hidden from the only probe.
  LocalMap lm = fuse(set, {1.5, 1, 0}, FuseDesc{});
  EXPECT_GT(lm.stats.unseen, 0.05);
  EXPECT_NEAR(lm.stats.fused + lm.stats.unseen + lm.stats.left_proxy, 1.0, 1e-9);
  PixelStatus s;
  Vec3 L = fuse_ray(set, {1.5, 1, 0}, {-1, 0, 0}, FuseDesc{}, &s);
  EXPECT_EQ(s, PixelStatus::Unseen);
  EXPECT_GT(luminance(L), 0) << "the fallback is the probe's distant lookup, never black";
  EXPECT_FALSE(lm.warnings.empty());
}

// ---- files and bad input ----------------------------------------------------------------------

fs::path temp_dir(const std::string& name) {
  auto d = fs::temp_directory_path() / fmt::format("iblkit_fusion_{}_{}", name, ::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Writes a painted probe set to disk: proxy.obj, pK.exr and probes.json (no depth maps).
std::string write_set(const fs::path& dir, const geometry::TriMesh& mesh, const std::vector<Vec3>& pos, int h = 16,
                      const geometry::TriMesh* proxy_file = nullptr) {
  geometry::RayTracer rt;
  rt.add(mesh);
  rt.commit();
  geometry::write_obj((dir / "proxy.obj").string(), proxy_file ? *proxy_file : mesh);
  nlohmann::json probes = nlohmann::json::array();
  for (size_t k = 0; k < pos.size(); ++k) {
    Probe p = paint_probe(rt, mesh, pos[k], Mat3(), h, smooth_paint);
    io::write_image((dir / fmt::format("p{}.exr", k)).string(), p.radiance.image);
    probes.push_back({{"image", fmt::format("p{}.exr", k)}, {"position", {pos[k].x, pos[k].y, pos[k].z}}});
  }
  nlohmann::json j = {{"format", "iblkit.probes/1"}, {"proxy", "proxy.obj"}, {"probes", probes}};
  std::ofstream((dir / "probes.json").string()) << j.dump(1);
  return (dir / "probes.json").string();
}

TEST(FusionProbeSet, DepthIsTracedOnceAndCachedBesideTheProbe) {
  auto dir = temp_dir("cache");
  auto manifest = write_set(dir, box_room(), {{0, 1.5, 0}, {1, 1, 1}});
  ProbeSet a = load_probe_set(manifest);
  EXPECT_EQ(a.probes[0].depth_source, DepthSource::Computed);
  EXPECT_TRUE(fs::exists(dir / "p0_proxydepth.exr"));
  ProbeSet b = load_probe_set(manifest);
  EXPECT_EQ(b.probes[1].depth_source, DepthSource::Cache);
  EXPECT_EQ(b.probes[1].depth.at(5, 7, 0), a.probes[1].depth.at(5, 7, 0));
  LoadDesc force;
  force.force_depth = true;
  EXPECT_EQ(load_probe_set(manifest, force).probes[0].depth_source, DepthSource::Computed);
  fs::remove_all(dir);
}

TEST(FusionBadInput, ClearErrorsAndWarnings) {
  auto dir = temp_dir("bad");
  // A probe outside the proxy (behind the +x wall).
  auto m1 = write_set(dir, box_room(), {{0, 1.5, 0}, {3, 1.5, 0}});
  expect_error([&] { load_probe_set(m1); }, "probe 1");
  expect_error([&] { load_probe_set(m1); }, "outside the proxy");
  // Depth and probe sizes that disagree.
  auto m2 = write_set(dir, box_room(), {{0, 1.5, 0}});
  io::write_image((dir / "d.exr").string(), Image(8, 4, 1, 1.0f));
  auto j = nlohmann::json::parse(std::ifstream(m2));
  j["probes"][0]["depth"] = "d.exr";
  std::ofstream(m2) << j.dump();
  expect_error([&] { load_probe_set(m2); }, "8×4 but the probe is 32×16");
  // Bad manifests name the field.
  std::ofstream((dir / "x.json").string()) << R"({"format":"iblkit.probes/1","probes":[]})";
  expect_error([&] { load_probe_set((dir / "x.json").string()); }, "\"proxy\"");
  std::ofstream((dir / "y.json").string())
      << R"({"format":"iblkit.probes/1","proxy":"proxy.obj","probes":[{"image":"p0.exr"}]})";
  expect_error([&] { load_probe_set((dir / "y.json").string()); }, "\"position\"");
  // A point inside geometry (inside the occluder) or behind a wall.
  auto set = painted_set(room_with_occluder(), {{-2, 1.5, 0}}, {}, 16, smooth_paint);
  expect_error([&] { fuse(set, {0, 1, 0}, FuseDesc{}); }, "inside geometry");
  expect_error([&] { fuse(set, {5, 1, 0}, FuseDesc{}); }, "inside geometry or outside the proxy");
  // Settings out of range.
  FuseDesc bad;
  bad.samples = 0;
  expect_error([&] { fuse(set, {-2, 1, 0}, bad); }, "samples");
  expect_error([&] { parse_blend("median"); }, "unknown blend");
  fs::remove_all(dir);
}

TEST(FusionBadInput, OpenProxyWarnsAndFallsBackInsteadOfBlack) {
  geometry::RoomDesc rd;
  rd.lo = {-2, 0, -3};
  rd.hi = {2, 3, 3};
  rd.omit[3] = true;  // no ceiling: open sky
  geometry::TriMesh open = geometry::make_room(rd);
  auto set = painted_set(open, {{0, 1.5, 0}}, {}, 32, smooth_paint);
  // Give the sky a radiance in the probe (the paint only covers the proxy).
  Probe& p = set.probes[0];
  for (int y = 0; y < p.radiance.image.height(); ++y)
    for (int x = 0; x < p.radiance.image.width(); ++x)
      if (p.depth.at(x, y, 0) == 0) p.radiance.image.set_rgb(x, y, {0.2, 0.4, 2.0});
  set.warnings.clear();
  prepare(set);  // images changed: prepare again (it interleaves radiance and depth for the lookups)
  ASSERT_FALSE(set.warnings.empty());
  EXPECT_NE(set.warnings[0].find("not closed"), std::string::npos) << set.warnings[0];
  EXPECT_GT(p.escape_fraction, 0.1);
  LocalMap lm = fuse(set, {0.5, 1, 0.5}, FuseDesc{});
  EXPECT_GT(lm.stats.left_proxy, 0.1);
  Vec3 up = fuse_ray(set, {0.5, 1, 0.5}, {0, 1, 0});
  EXPECT_NEAR(up.z, 2.0, 1e-3) << "straight up the distant lookup reads the probe's sky";
  // An inside-out proxy is flipped with a warning.
  geometry::TriMesh inverted = box_room();
  inverted.flip();
  auto set2 = painted_set(inverted, {{0, 1.5, 0}}, {}, 16, smooth_paint);
  ASSERT_FALSE(set2.warnings.empty());
  EXPECT_NE(set2.warnings[0].find("flipped"), std::string::npos);
}

// ---- lights and paths -------------------------------------------------------------------------

TEST(FusionLights, TheBrightPatchBecomesALightAtItsPosition) {
  constexpr double kPositionTol = 0.1;  // metres: one texel of the 64-row fused map at 1.9 m (0.049 rad × 1.9 m)
  const Vec3 patch{1.0, 3.0, -1.5};
  auto paint = [&](Vec3 p, Vec3) {
    bool in = std::abs(p.y - 3) < 1e-6 && std::abs(p.x - patch.x) < 0.2 && std::abs(p.z - patch.z) < 0.2;
    return in ? Vec3{200, 190, 180} : Vec3{0.05, 0.05, 0.05};
  };
  auto set = painted_set(box_room(), {{0, 1.5, 0}, {1, 1.0, -1}}, {}, 128, paint);
  Vec3 x{0.5, 1.2, -0.5};
  FuseDesc fd;
  fd.size = 64;
  LocalMap lm = fuse(set, x, fd);
  auto ls = localize_lights(lm, {8});
  ASSERT_TRUE(ls.origin);
  EXPECT_NEAR(length(*ls.origin - x), 0, 1e-12);
  // Median cut splits the patch (≈93% of the energy) into several small lights: each sits on the patch
  // (within its half-diagonal 0.28 m plus the tolerance), and their energy-weighted mean is its centre.
  // The remaining large regions (the dim room) are not checked.
  Vec3 mean;
  double wsum = 0;
  for (const auto& l : ls.lights) {
    ASSERT_TRUE(l.position) << "a closed room: every light has a position";
    if (l.solid_angle > 1.0) continue;
    double y = luminance(l.irradiance);
    EXPECT_LT(length(*l.position - patch), 0.28 + kPositionTol);
    mean += *l.position * y;
    wsum += y;
  }
  EXPECT_LT(length(mean / wsum - patch), kPositionTol);
  // The lights carry the map's ∫L dω.
  auto integ = lm.radiance.integral();
  EXPECT_NEAR(luminance(lights::total_irradiance(ls)), luminance(Vec3{integ[0], integ[1], integ[2]}),
              1e-6 * luminance(Vec3{integ[0], integ[1], integ[2]}));
  // Round trip through iblkit.lights/1.
  auto back = lights::from_json(lights::to_json(ls));
  ASSERT_TRUE(back.lights[0].position);
  EXPECT_NEAR(back.lights[0].position->x, ls.lights[0].position->x, 1e-12);
}

TEST(FusionTrack, AssignmentMatchesBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (auto [r, c] : std::vector<std::pair<int, int>>{{5, 5}, {4, 6}, {6, 4}, {1, 3}}) {
    std::vector<double> cost(r * c);
    for (auto& v : cost) v = u(rng);
    auto a = assign_min_cost(cost, r, c);
    double got = 0;
    for (int i = 0; i < r; ++i)
      if (a[i] >= 0) got += cost[i * c + a[i]];
    // Brute force over injective maps of the smaller side.
    int small = std::min(r, c), big = std::max(r, c);
    std::vector<int> perm(big);
    std::iota(perm.begin(), perm.end(), 0);
    double best = 1e30;
    do {
      double s = 0;
      for (int i = 0; i < small; ++i) s += r <= c ? cost[i * c + perm[i]] : cost[perm[i] * c + i];
      best = std::min(best, s);
    } while (std::next_permutation(perm.begin(), perm.end()));
    EXPECT_NEAR(got, best, 1e-12) << r << "x" << c;
  }
}

TEST(FusionTrack, IdentitiesSurviveShufflingAndTheFilterCutsFlicker) {
  // Four lights with fixed true directions; each frame lists them in a random order with a random
  // direction jitter and power noise (median cut on a moving map does both).
  std::vector<Vec3> dirs = {normalize(Vec3{1, 1, 0}), normalize(Vec3{-1, 0.5, 0.2}), normalize(Vec3{0, 1, 1}),
                            normalize(Vec3{0.2, -1, -1})};
  std::mt19937 rng(3);
  std::normal_distribution<double> jit(0, 0.05);
  LightTracker raw_tr({false, 1.0}), filt_tr({true, 3.0});
  std::vector<lights::LightSet> raw_frames, filt_frames;
  std::map<int, int> true_of_id;
  for (int k = 0; k < 40; ++k) {
    std::vector<int> order = {0, 1, 2, 3};
    std::shuffle(order.begin(), order.end(), rng);
    lights::LightSet s;
    s.origin = Vec3{};
    for (int o : order) {
      lights::Light l;
      l.direction = normalize(dirs[o] + Vec3{jit(rng), jit(rng), jit(rng)});
      double e = (1 + o) * (1 + 2 * jit(rng));
      l.irradiance = {e, e, e};
      l.solid_angle = 0.1;
      s.lights.push_back(l);
    }
    raw_frames.push_back(raw_tr.update(s, 1.0));
    filt_frames.push_back(filt_tr.update(s, 1.0));
    // Track ids follow the true light: the track of the light listed j-th stands for order[j].
    if (k == 0)
      for (int j = 0; j < 4; ++j) true_of_id[filt_tr.ids()[j]] = order[j];
    for (int j = 0; j < 4; ++j) EXPECT_EQ(true_of_id.at(filt_tr.ids()[j]), order[j]) << "frame " << k;
    // The filter keeps the frame's total power.
    EXPECT_NEAR(luminance(lights::total_irradiance(filt_frames.back())), luminance(lights::total_irradiance(s)), 1e-9);
  }
  FlickerStats fr = light_flicker(raw_frames), ff = light_flicker(filt_frames);
  EXPECT_LT(ff.mean, 0.5 * fr.mean) << "raw " << fr.mean << " filtered " << ff.mean;
}

TEST(FusionPath, PathFilesWithAndWithoutTimes) {
  auto dir = temp_dir("path");
  std::ofstream((dir / "a.json").string()) << "[[0,1,2],[0,1,3]]";
  auto a = read_path((dir / "a.json").string());
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[1].time, 1.0);
  std::ofstream((dir / "b.json").string())
      << R"({"format":"iblkit.path/1","points":[{"position":[0,1,2],"time":0.5},{"position":[0,1,3],"time":0.75}]})";
  EXPECT_EQ(read_path((dir / "b.json").string())[1].time, 0.75);
  std::ofstream((dir / "c.json").string())
      << R"({"format":"iblkit.path/1","points":[{"position":[0,1,2],"time":1},{"position":[0,1,3],"time":1}]})";
  expect_error([&] { read_path((dir / "c.json").string()); }, "times must increase");
  std::ofstream((dir / "d.json").string()) << R"([[0,1]])";
  expect_error([&] { read_path((dir / "d.json").string()); }, "points[0]");
  fs::remove_all(dir);
}

TEST(FusionPath, FusePathHandsOutEveryFrameAndMeasuresThem) {
  // A bright patch on the ceiling of the box room; six timed points pass under it.
  auto paint = [](Vec3 p, Vec3) {
    bool in = std::abs(p.y - 3) < 1e-6 && std::abs(p.x - 0.5) < 0.3 && std::abs(p.z + 1) < 0.3;
    return in ? Vec3{100, 95, 90} : Vec3{0.1, 0.12, 0.1};
  };
  auto set = painted_set(box_room(), {{0, 1.5, 0}, {1, 1.0, -1}}, {}, 64, paint);
  std::vector<PathPoint> path;
  for (int k = 0; k < 6; ++k) path.push_back({{-0.5 + 0.25 * k, 1.2, -0.5}, 0.5 * k});
  PathDesc pd;
  pd.fuse.size = 32;
  pd.lights = 6;
  pd.track.time_constant = 1.0;
  std::vector<lights::LightSet> raw, filt;
  std::vector<std::vector<int>> raw_ids, filt_ids;
  std::vector<sphere::EnvMap> maps;
  size_t calls = 0;
  auto r = fuse_path(set, path, pd, [&](const PathFrame& f) {
    EXPECT_EQ(f.index, calls++);
    EXPECT_EQ(f.point.time, path[f.index].time);
    // The frame's map is fuse() at the point, its lights the localised cut of that map, tracked.
    LocalMap m = fuse(set, path[f.index].position, pd.fuse);
    ASSERT_EQ(f.map.radiance.image.size(), m.radiance.image.size());
    EXPECT_TRUE(std::equal(m.radiance.image.data(), m.radiance.image.data() + m.radiance.image.size(),
                           f.map.radiance.image.data()));
    auto cut = localize_lights(m, {pd.lights});
    ASSERT_EQ(f.cut.lights.size(), cut.lights.size());
    EXPECT_EQ(f.cut.regions.label, cut.regions.label);
    ASSERT_EQ(f.raw.lights.size(), cut.lights.size());
    ASSERT_EQ(f.filtered.lights.size(), cut.lights.size());
    EXPECT_EQ(f.raw_ids.size(), cut.lights.size());
    EXPECT_EQ(f.filtered_ids.size(), cut.lights.size());
    for (size_t i = 0; i < cut.lights.size(); ++i)  // the raw tracker only names the lights
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.raw.lights[i].irradiance[c], cut.lights[i].irradiance[c], 1e-12);
    // The filter keeps the frame's total power.
    double y = luminance(lights::total_irradiance(cut));
    EXPECT_NEAR(luminance(lights::total_irradiance(f.filtered)), y, 1e-9 * y);
    raw.push_back(f.raw);
    filt.push_back(f.filtered);
    raw_ids.push_back(f.raw_ids);
    filt_ids.push_back(f.filtered_ids);
    maps.push_back(f.map.radiance);
  });
  EXPECT_EQ(calls, path.size());
  EXPECT_EQ(r.frames, path.size());
  EXPECT_GE(r.seconds, 0);
  // The measures are local_lights.h's of the frames it handed out.
  EXPECT_EQ(r.map_flicker.mean, map_flicker(maps).mean);
  EXPECT_EQ(r.raw_flicker.mean, light_flicker(raw).mean);
  EXPECT_EQ(r.filtered_flicker.max, light_flicker(filt).max);
  EXPECT_EQ(r.raw_excess, excess_flicker(raw, maps));
  EXPECT_EQ(r.filtered_excess, excess_flicker(filt, maps));
  EXPECT_EQ(r.raw_jitter, shadow_light_jitter(raw, raw_ids, pd.shadow_lights));
  EXPECT_EQ(r.filtered_jitter, shadow_light_jitter(filt, filt_ids, pd.shadow_lights));
  EXPECT_EQ(r.raw_vs_maps, lights_vs_maps(raw, maps));
  EXPECT_EQ(r.filtered_vs_maps, lights_vs_maps(filt, maps));
  EXPECT_GT(r.map_flicker.mean, 0);  // the points move: the maps change
  // Without the filter the two trackers are the same.
  pd.track.filter = false;
  auto same = fuse_path(set, path, pd);
  EXPECT_EQ(same.raw_flicker.mean, same.filtered_flicker.mean);
  EXPECT_EQ(same.raw_vs_maps, same.filtered_vs_maps);
  // Bad settings are named.
  pd.fuse.mapping = sphere::MappingKind::CubeHCross;
  expect_error([&] { fuse_path(set, path, pd); }, "lat-long");
  pd.fuse.mapping = sphere::MappingKind::LatLong;
  pd.lights = 0;
  expect_error([&] { fuse_path(set, path, pd); }, "lights = 0");
  pd.lights = 4;
  expect_error([&] { fuse_path(set, {}, pd); }, "no points");
}

}  // namespace
}  // namespace ibl::fusion
