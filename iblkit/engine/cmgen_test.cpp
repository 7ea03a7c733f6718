// Conformance with Filament's own tool: cmgen (Debian's libfilament-tools) run on the same probes
// as iblkit, its numbers and faces compared with iblkit's Filament layouts. Skips where cmgen or
// blender-data's probes are absent. The tables in bench/RESULTS.md come from these comparisons.
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "iblkit/core/parallel.h"
#include "iblkit/engine/dfg.h"
#include "iblkit/engine/diffuse.h"
#include "iblkit/engine/export.h"
#include "iblkit/engine/ggx.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/export.h"
#include "iblkit/sh/project.h"

namespace ibl::engine {
namespace {

namespace fs = std::filesystem;

const std::string kWorld = "/usr/share/blender/datafiles/studiolights/world/";
const char* kFaces[6] = {"px", "nx", "py", "ny", "pz", "nz"};

bool have_cmgen() { return std::system("cmgen --help >/dev/null 2>&1") == 0; }

// Runs a shell command; its stdout.
std::string run(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

// A fresh scratch folder for one test.
fs::path scratch(const std::string& name) {
  fs::path d = fs::temp_directory_path() / fmt::format("iblkit_cmgen_{}_{}", name, getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// blender-data's EXRs use a compression cmgen's reader lacks ("Unknown compression type"): both
// tools read the same pixels from a copy written by iblkit (io::write_image, float32), either the
// lat-long itself or a horizontal cross of face `face` resampled from it (sphere::resample).
std::string readable_copy(const std::string& name, const fs::path& dir, int face = 0) {
  const std::string path = (dir / fmt::format("{}{}.exr", name, face ? "_cross" : "")).string();
  Image im = io::read_image(kWorld + name + ".exr");
  if (face) {
    sphere::EnvMap env = io::read_envmap(kWorld + name + ".exr");
    im = sphere::resample(env, sphere::Mapping(sphere::MappingKind::CubeHCross, 4 * face, 3 * face));
  }
  io::write_image(path, im);
  return path;
}

// The 9 "( r, g, b); // L.." lines cmgen prints for --sh=3 --sh-shader.
std::vector<Vec3> parse_sh(const std::string& text) {
  std::vector<Vec3> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const size_t at = line.find('(');
    if (at == std::string::npos || line.find("L") == std::string::npos) continue;
    Vec3 v;
    if (std::sscanf(line.c_str() + at, "( %lf, %lf, %lf)", &v.x, &v.y, &v.z) == 3) out.push_back(v);
  }
  return out;
}

#define REQUIRE_PEER()                                                   \
  if (!have_cmgen()) GTEST_SKIP() << "cmgen (libfilament-tools) absent"; \
  if (!fs::exists(kWorld + "forest.exr")) GTEST_SKIP() << "blender-data probes absent"

// iblkit sh --format filament against cmgen --sh=3 --sh-shader --sh-window=no on the same file,
// as a cube map (horizontal cross) and as a lat-long: every coefficient within a tolerance of its
// channel's L00. On the cross both integrate the same texels with exact solid angles and agree
// to 1e-4; the 1 % holds there. On a lat-long cmgen first converts to a cube map by
// nearest-pixel lookups (CubemapUtils::equirectangularToCubemap: x = (atan2(x, z)/π + 1)/2 · (W − 1),
// truncated), which moves probes with small bright sources by up to a few per cent of L00;
// iblkit integrates the lat-long exactly. Measured: bench/RESULTS.md.
constexpr double kShCubeTol = 0.01;  // the 1 %
constexpr double kShLatLongTol =
    0.15;  // a frame check only: cmgen's nearest-pixel equirect → cube conversion moves
           // its SH by up to 9.7 % (interior.exr, 2026-12-01); a wrong frame misses by ≫ 50 %.
           // The layouts' equality is the cube-input case (kShCubeTol; measured 1e-5).
TEST(Cmgen, ShMatchesFilamentLayout) {
  REQUIRE_PEER();
  const fs::path dir = scratch("sh");
  for (const char* name : {"forest", "city", "interior"})
    for (int face : {256, 0}) {
      const std::string probe = readable_copy(name, dir, face);
      std::vector<Vec3> peer = parse_sh(run("cmgen --sh=3 --sh-shader --sh-window=no " + probe + " 2>/dev/null"));
      ASSERT_EQ(peer.size(), 9u) << probe;
      const sphere::EnvMap env = io::read_envmap(probe);
      sh::Coeffs ours = sh::to_filament(sh::project(env, 3), sh::filament_frame(env.mapping.kind()));
      double worst = 0;
      for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(ours.c[i][c] - peer[i][c]) / std::abs(peer[0][c]));
      std::printf("cmgen --sh=3 --sh-shader %-9s %-8s: max |Δ| / L00 = %.5f\n", name, face ? "cross" : "latlong",
                  worst);
      EXPECT_LT(worst, face ? kShCubeTol : kShLatLongTol) << probe;
    }
  fs::remove_all(dir);
}

double sq(double v) { return v * v; }

// Luminance of the six faces of one cube level, face-major (6·S·S).
struct Faces {
  int size = 0;
  std::vector<double> lum;
  double at(int f, int x, int y) const { return lum[(static_cast<size_t>(f) * size + y) * size + x]; }
};

Faces peer_faces(const fs::path& dir, int m) {
  Faces out;
  for (int f = 0; f < 6; ++f) {
    Image im = io::read_image((dir / fmt::format("m{}_{}.exr", m, kFaces[f])).string());
    out.size = im.width();
    for (int y = 0; y < im.height(); ++y)
      for (int x = 0; x < im.width(); ++x) out.lum.push_back(luminance(im.rgb(x, y)));
  }
  return out;
}

Faces our_faces(const CubeChain& c, int m) {
  Faces out;
  out.size = c.size(m);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < out.size; ++y)
      for (int x = 0; x < out.size; ++x)
        out.lum.push_back(luminance(c.levels[static_cast<size_t>(m)].rgb(f * out.size + x, y)));
  return out;
}

// Σ|a − peer| / Σ|peer| over every texel of the six faces.
double difference(const Faces& a, const Faces& peer) {
  EXPECT_EQ(a.size, peer.size);
  if (a.size != peer.size) return 1e9;
  double num = 0, den = 0;
  for (size_t i = 0; i < a.lum.size(); ++i) {
    num += std::abs(a.lum[i] - peer.lum[i]);
    den += std::abs(peer.lum[i]);
  }
  return num / den;
}

// ∫ L dω of a level (exact texel solid angles).
double power(const Faces& a) {
  const std::vector<double> om = cube_face_solid_angles(a.size);
  double sum = 0;
  for (size_t i = 0; i < a.lum.size(); ++i) sum += a.lum[i] * om[i % om.size()];
  return sum;
}

// A model of cmgen's --ibl-ld prefilter, written here from what Filament 1.9.25's sources do
// (read in libs/ibl/src/CubemapIBL.cpp roughnessFilter, Cubemap.cpp filterAt / trilinearFilterAt /
// makeSeamless, tools/cmgen/src/cmgen.cpp generateMipmaps / iblRoughnessPrefilter; not copied):
// level 0 is halved down to 1×1 by plain 2×2 means, each face carrying a one-texel border with the
// nearest texel across its edges; a level of α > 0 is Σ(n·l) L(l) / Σ(n·l) over the GGX samples
// l = 2(n·h)h − n of h from the Hammersley points (i/N, radical inverse of i), N = 1024 on level 1
// and doubled on every further level, each read trilinearly at lod = log4(Ω_s/Ω_p) + 1 with
// Ω_s = 4/(N D), Ω_p = 4π/(6 S₀²) (clamped to the chain). Within a face a level of S texels is read
// bilinearly at x = S(s + 1)/2 − `offset`: Filament's filterAt takes its weights at offset 0, which
// reads the level half a texel towards +s, +t of every face; offset ½ reads at texel centres (a GL
// sampler, iblkit). Luminance only (the comparisons are of luminance).
class CmgenModel {
 public:
  explicit CmgenModel(const Faces& level0) {
    Faces cur = level0;
    for (;;) {
      add_level(cur);
      if (cur.size == 1) break;
      Faces next;
      next.size = cur.size / 2;
      for (int f = 0; f < 6; ++f)
        for (int y = 0; y < next.size; ++y)
          for (int x = 0; x < next.size; ++x)
            next.lum.push_back(0.25 * (cur.at(f, 2 * x, 2 * y) + cur.at(f, 2 * x + 1, 2 * y) +
                                       cur.at(f, 2 * x, 2 * y + 1) + cur.at(f, 2 * x + 1, 2 * y + 1)));
      cur = std::move(next);
    }
  }

  Faces level(double alpha, int out_size, int samples, double offset) const {
    struct Sample {
      Vec3 l;
      double w;
      int l0;
      double frac;
    };
    std::vector<Sample> set;
    const int s0 = levels_[0].n, top = static_cast<int>(levels_.size()) - 1;
    const double omega_p = kFourPi / (6.0 * s0 * s0), a2 = alpha * alpha;
    double sw = 0;
    for (int i = 0; i < samples; ++i) {
      uint32_t b = static_cast<uint32_t>(i);
      double u2 = 0, scale = 0.5;
      for (; b; b >>= 1, scale *= 0.5) u2 += (b & 1) * scale;
      const double phi = kTwoPi * i / samples, c2 = (1 - u2) / (1 + (a2 - 1) * u2), ch = std::sqrt(c2),
                   sh = std::sqrt(std::max(0.0, 1 - c2)), nl = 2 * c2 - 1;
      if (nl <= 0) continue;
      const double d = (a2 - 1) * c2 + 1, D = a2 / (kPi * d * d);
      const double lod = std::clamp(std::log(4.0 / (samples * D) / omega_p) / std::log(4.0) + 1, 0.0, double(top));
      const int l0 = static_cast<int>(lod);
      set.push_back({{2 * ch * sh * std::cos(phi), 2 * ch * sh * std::sin(phi), nl}, nl, l0, lod - l0});
      sw += nl;
    }
    Faces out;
    out.size = out_size;
    out.lum.assign(6ul * out_size * out_size, 0);
    parallel_for(0, 6 * out_size, [&](int64_t row) {
      const int f = static_cast<int>(row / out_size), y = static_cast<int>(row % out_size);
      for (int x = 0; x < out_size; ++x) {
        const Frame fr = Frame::from_normal(cube_texel_direction(f, x, y, out_size));
        double acc = 0;
        for (const Sample& s : set) {
          const Vec3 l = fr.from_local(s.l);
          double v = read(levels_[static_cast<size_t>(s.l0)], l, offset);
          if (s.frac > 0 && s.l0 < top) v += s.frac * (read(levels_[static_cast<size_t>(s.l0 + 1)], l, offset) - v);
          acc += s.w * v;
        }
        out.lum[(static_cast<size_t>(f) * out_size + y) * out_size + x] = acc / sw;
      }
    });
    return out;
  }

 private:
  struct Level {
    int n;
    std::vector<double> t;  // 6 × (n + 2)², texel (x, y) at [f][y + 1][x + 1]
    double at(int f, int x, int y) const { return t[(static_cast<size_t>(f) * (n + 2) + y + 1) * (n + 2) + x + 1]; }
  };

  void add_level(const Faces& a) {
    Level lv{a.size, std::vector<double>(6ul * (a.size + 2) * (a.size + 2))};
    const int n = a.size;
    for (int f = 0; f < 6; ++f)
      for (int y = -1; y <= n; ++y)
        for (int x = -1; x <= n; ++x) {
          double s = 2.0 * (x + 0.5) / n - 1, t = 2.0 * (y + 0.5) / n - 1;
          const int g = sphere::cube_face_of(sphere::cube_face_point(f, s, t), &s, &t);
          const int ix = std::min(n - 1, static_cast<int>((s + 1) * 0.5 * n)),
                    iy = std::min(n - 1, static_cast<int>((t + 1) * 0.5 * n));
          lv.t[(static_cast<size_t>(f) * (n + 2) + y + 1) * (n + 2) + x + 1] = a.at(g, ix, iy);
        }
    levels_.push_back(std::move(lv));
  }

  static double read(const Level& lv, Vec3 d, double offset) {
    double s = 0, t = 0;
    const int f = sphere::cube_face_of(d, &s, &t);
    const double top = std::nextafter(double(lv.n), 0.0);
    const double x = std::min((s + 1) * 0.5 * lv.n, top) - offset, y = std::min((t + 1) * 0.5 * lv.n, top) - offset;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double u = x - x0, v = y - y0;
    return (1 - u) * (1 - v) * lv.at(f, x0, y0) + u * (1 - v) * lv.at(f, x0 + 1, y0) +
           (1 - u) * v * lv.at(f, x0, y0 + 1) + u * v * lv.at(f, x0 + 1, y0 + 1);
  }

  std::vector<Level> levels_;
};

// A probe with one small bright source (radiance 50 in a 6° cone towards (0, 0.3, 1), 0 elsewhere)
// as a horizontal cross of face 64: where a lookup offset shows most.
std::string spot_probe(const fs::path& dir) {
  const sphere::Mapping ll(sphere::MappingKind::LatLong, 1024, 512);
  Image im(1024, 512, 3);
  const Vec3 a = normalize(Vec3{0, 0.3, 1});
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 1024; ++x) {
      Vec3 d;
      ll.to_direction(x + 0.5, y + 0.5, &d);
      const double v = dot(d, a) > std::cos(6 * kPi / 180) ? 50.0 : 0.0;
      im.set_rgb(x, y, {v, v, v});
    }
  const std::string path = (dir / "spot_cross.exr").string();
  io::write_image(path, sphere::resample(sphere::EnvMap(std::move(im), ll),
                                         sphere::Mapping(sphere::MappingKind::CubeHCross, 256, 192)));
  return path;
}

// iblkit specular --roughness filament --frame filament against cmgen --ibl-ld, same size (64) and
// levels (3: 64², 32², 16²; ρ = 0, 0.293, 1), texel by texel on every face of every level, for
// forest as a cube map of face 64 (then level 0 is the same texels in both), forest as a lat-long
// (each resamples it its own way: cmgen by nearest pixels, iblkit area-preserving) and the spot
// probe above as a cube map.
//
// Level counts, the level → roughness rule, α = ρ², the frames, the face order and orientation agree:
// level 0 of a cube map is equal to 1e-4. On ρ > 0 the maps differ by 5–22 %, and the whole
// difference is cmgen's lookup (CmgenModel): the model with Filament's offset 0, fed iblkit's own
// level 0, reproduces cmgen to ≤ 1.3 %, and the same model with texel-centred reads reproduces
// iblkit to ≤ 5.4 % (FIS against iblkit's exact sums). cmgen's offset moves its rough levels by half
// a texel of the coarse level each sample reads — degrees — towards −s, −t of every face, and breaks
// two things every GGX prefilter keeps: ∫L̄ dω = ∫L dω (the normalised kernel is symmetric in r, l),
// and agreement with the brute-force convolution (1). iblkit keeps both and stays texel-centred;
// it does not reproduce the offset. Measured: bench/RESULTS.md ("Engine maps against Filament's cmgen").
constexpr double kCubeLevel0Tol = 0.005;    // the same texels, through half floats (measured 1e-4)
constexpr double kLatLongLevel0Tol = 0.16;  // cmgen's nearest-pixel equirect → cube against iblkit's area-preserving
                                            // resampling of a 1024×512 lat-long to 64² faces (measured 0.141)
constexpr double kModelPeerTol = 0.02;      // the model (offset 0) against cmgen: FIS noise, cmgen's random turn of its
                                            // sample set per texel, float rounding (measured ≤ 0.013)
constexpr double kModelOursTol = 0.07;  // the model (offset ½) against iblkit: FIS against iblkit's exact sums, which
                                        // read the 8² level at ρ = 1 (measured ≤ 0.054, the spot's level 2)
constexpr double kOffsetTol[3] = {0.08, 0.16, 0.25};  // iblkit against cmgen on ρ > 0, forest cross / lat-long / spot:
                                                      // cmgen's half-texel offset (measured ≤ 0.064 / 0.143 / 0.221)
constexpr double kPowerTol = 0.01;  // iblkit's ∫L̄ dω of every level against level 0's (measured ≤ 0.003)
constexpr double kBruteTol = 0.03;  // iblkit against (1) by brute force, 54 texels (measured ≤ 0.024)
TEST(Cmgen, SpecularMatchesIblLd) {
  REQUIRE_PEER();
  const fs::path dir = scratch("ld");
  const char* names[3] = {"forest cross", "forest latlong", "spot cross"};
  const std::string probes[3] = {readable_copy("forest", dir, 64), readable_copy("forest", dir, 0), spot_probe(dir)};
  for (int p = 0; p < 3; ++p) {
    const std::string& probe = probes[p];
    const bool cube = p != 1;
    const fs::path out = dir / fs::path(probe).stem();
    run(fmt::format("cmgen --quiet --size=64 --format=exr --ibl-ld={} {} 2>&1", dir.string(), probe));
    ASSERT_TRUE(fs::exists(out / "m0_px.exr")) << "cmgen wrote nothing in " << out;
    ASSERT_FALSE(fs::exists(out / "m3_px.exr"));  // 3 levels, as iblkit's default for 64
    const sphere::EnvMap env = io::read_envmap(probe);
    SpecularDesc d;
    d.size = 64;
    d.lod = LodMapping::Filament;
    d.rotation = frame_rotation(EngineFrame::Filament, env.mapping.kind());
    SpecularCube ours = prefilter_ggx(env, d);
    ASSERT_EQ(ours.cube.count(), 3);
    const Faces ours0 = our_faces(ours.cube, 0), peer0 = peer_faces(out, 0);
    const double diff0 = difference(ours0, peer0);
    std::printf("cmgen --ibl-ld %-14s level 0 (ρ 0): iblkit vs cmgen %.4f\n", names[p], diff0);
    EXPECT_LT(diff0, cube ? kCubeLevel0Tol : kLatLongLevel0Tol) << probe;
    const CmgenModel model(ours0);
    for (int m = 1; m < 3; ++m) {
      const Faces mine = our_faces(ours.cube, m), peer = peer_faces(out, m);
      const double alpha = ours.info[m].alpha;
      const int samples = 1024 << (m - 1), n = 64 >> m;
      const double diff = difference(mine, peer), shifted = difference(model.level(alpha, n, samples, 0.0), peer),
                   centred = difference(model.level(alpha, n, samples, 0.5), mine);
      const double p_ours = power(mine) / power(ours0), p_peer = power(peer) / power(peer0);
      std::printf(
          "cmgen --ibl-ld %-14s level %d (ρ %.3f, %s): iblkit vs cmgen %.4f | model offset 0 vs cmgen %.4f, "
          "offset ½ vs iblkit %.4f | ∫L̄dω / level 0: iblkit %.4f, cmgen %.4f\n",
          names[p], m, ours.info[m].roughness, level_method_name(ours.info[m].method).c_str(), diff, shifted, centred,
          p_ours, p_peer);
      EXPECT_LT(diff, kOffsetTol[p]) << probe << " level " << m;
      EXPECT_LT(shifted, kModelPeerTol) << probe << " level " << m;
      EXPECT_LT(shifted, diff / 3) << probe << " level " << m;  // the offset is what makes most of the difference
      EXPECT_LT(centred, kModelOursTol) << probe << " level " << m;
      EXPECT_NEAR(p_ours, 1.0, kPowerTol) << probe << " level " << m;
      // Which is nearer the truth: both against (1) by brute force at 3×3 texels of every face,
      // e = √(Σ (x − ref)² / Σ ref²).
      if (!cube) continue;
      double e_ours = 0, e_peer = 0, e_ref = 0;
      for (int f = 0; f < 6; ++f)
        for (int y : {n / 6, n / 2, 5 * n / 6})
          for (int x : {n / 6, n / 2, 5 * n / 6}) {
            const double ref = luminance(ggx_reference(env, cube_texel_direction(f, x, y, n), alpha, d.rotation));
            e_ours += sq(mine.at(f, x, y) - ref);
            e_peer += sq(peer.at(f, x, y) - ref);
            e_ref += sq(ref);
          }
      e_ours = std::sqrt(e_ours / e_ref);
      e_peer = std::sqrt(e_peer / e_ref);
      std::printf("cmgen --ibl-ld %-14s level %d against brute force at 54 texels: iblkit %.4f, cmgen %.4f\n", names[p],
                  m, e_ours, e_peer);
      EXPECT_LT(e_ours, kBruteTol) << probe << " level " << m;
      EXPECT_LT(e_ours, e_peer) << probe << " level " << m;
    }
    // In iblkit's own frame the maps are far off: the frame is what makes them agree.
    if (p == 0) {
      SpecularDesc plain = d;
      plain.rotation = Mat3::identity();
      const double off = difference(our_faces(prefilter_ggx(env, plain).cube, 2), peer_faces(out, 2));
      std::printf("cmgen --ibl-ld %-14s level 2 in iblkit's frame: iblkit vs cmgen %.4f\n", names[p], off);
      EXPECT_GT(off, 3 * kOffsetTol[0]);
    }
  }
  fs::remove_all(dir);
}

// The DFG table against cmgen --ibl-dfg (Filament's LUT code, 1024 Hammersley samples a texel).
// cmgen's row y holds ρ = 1 − (y − ½)/size... read from its file: we find its rows' roughness by
// matching the ρ → 0 row; see docs/engines.md. Compared at cmgen's own texel coordinates.
constexpr double kDfgTol = 0.01;  // cmgen's Monte-Carlo noise at 1024 samples and our quadrature
TEST(Cmgen, DfgMatchesFilament) {
  REQUIRE_PEER();
  const fs::path dir = scratch("dfg");
  const std::string file = (dir / "dfg.exr").string();
  run(fmt::format("cmgen --quiet --size=32 --ibl-dfg={} 2>&1", file));
  ASSERT_TRUE(fs::exists(file));
  Image peer = io::read_image(file);
  ASSERT_EQ(peer.width(), 32);
  double worst = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const double mu = (x + 0.5) / 32, rho = std::clamp((32 - y + 0.5) / 32, 0.0, 1.0);
      const Vec2 sb = dfg(mu, rho);
      worst = std::max({worst, std::abs(sb.x - peer.at(x, y, 0)), std::abs(sb.y - peer.at(x, y, 1))});
    }
  std::printf("cmgen --ibl-dfg: max |Δ| = %.4f\n", worst);
  EXPECT_LT(worst, kDfgTol);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ibl::engine
