#include "iblkit/engine/ggx.h"

#include <atomic>
#include <chrono>
#include <cmath>

#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::engine {

namespace {
constexpr EnumName<LodMapping> kLodNames[] = {{LodMapping::Linear, "linear"}, {LodMapping::Filament, "filament"}};
constexpr EnumName<LevelMethod> kMethodNames[] = {
    {LevelMethod::Resample, "resample"}, {LevelMethod::Exact, "exact"}, {LevelMethod::Importance, "importance"}};

bool is_pow2(int n) { return n > 0 && (n & (n - 1)) == 0; }
int log2i(int n) {
  int l = 0;
  while ((1 << (l + 1)) <= n) ++l;
  return l;
}

// Van der Corput radical inverse in base 2: the second coordinate of the Hammersley set.
double radical_inverse(uint32_t i) {
  i = (i << 16u) | (i >> 16u);
  i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
  i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
  i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
  i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
  return double(i) * 2.3283064365386963e-10;  // 2⁻³²
}

struct Sample {
  Vec3 l;  // in the frame of r (r = +z)
  double weight, lod;
};

// The FIS sample set of one level (shared by every texel).
std::vector<Sample> fis_samples(double alpha, int count, int base_size, int chain_levels) {
  std::vector<Sample> out;
  const double omega_p = kFourPi / (6.0 * base_size * base_size), a2 = alpha * alpha;
  double sw = 0;
  for (int i = 0; i < count; ++i) {
    const double u1 = (i + 0.5) / count, u2 = radical_inverse(static_cast<uint32_t>(i));
    const double phi = kTwoPi * u1;
    const double cos2 = (1 - u2) / (1 + (a2 - 1) * u2), cos_h = std::sqrt(cos2),
                 sin_h = std::sqrt(std::max(0.0, 1 - cos2));
    const Vec3 h{sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h};
    const double nl = 2 * cos2 - 1;
    if (nl <= 0) continue;
    const Vec3 l{2 * cos_h * h.x, 2 * cos_h * h.y, nl};
    const double d = (a2 - 1) * cos2 + 1, D = a2 / (kPi * d * d);
    const double omega_s = 4.0 / (count * D);  // 1 / (N · pdf_l), pdf_l = D/4 for n = v
    const double lod = std::clamp(0.5 * std::log2(omega_s / omega_p) + 1.0, 0.0, double(chain_levels - 1));
    out.push_back({l, nl, lod});
    sw += nl;
  }
  for (Sample& s : out) s.weight /= sw;
  return out;
}

Image importance_level(const CubeChain& chain, double alpha, int out_size, int samples, const ProgressFn& progress) {
  const std::vector<Sample> set = fis_samples(alpha, samples, chain.size(0), chain.count());
  Image out(6 * out_size, out_size, 3);
  std::atomic<int> rows{0};
  parallel_for(0, 6 * out_size, [&](int64_t row) {
    const int f = static_cast<int>(row / out_size), y = static_cast<int>(row % out_size);
    for (int x = 0; x < out_size; ++x) {
      const Vec3 r = cube_texel_direction(f, x, y, out_size);
      const Frame fr = Frame::from_normal(r);
      Vec3 acc;
      for (const Sample& s : set) acc += chain.sample(fr.from_local(s.l), s.lod) * s.weight;
      out.set_rgb(f * out_size + x, y, acc);
    }
    int done = ++rows;
    if (progress && done % 8 == 0) progress("importance sampling", double(done) / (6 * out_size));
  });
  return out;
}

}  // namespace

std::string lod_mapping_name(LodMapping m) { return name_of(kLodNames, m); }
LodMapping parse_lod_mapping(const std::string& name) { return parse_enum(kLodNames, name, "roughness mapping"); }
std::string level_method_name(LevelMethod m) { return name_of(kMethodNames, m); }

double level_roughness(int m, int n, LodMapping mapping) {
  if (n <= 1) return 0;
  const double t = double(m) / (n - 1);
  return mapping == LodMapping::Linear ? t : 1 - std::sqrt(std::max(0.0, 1 - t));
}

int specular_level_count(const SpecularDesc& d) {
  if (!is_pow2(d.size) || d.size < 8 || d.size > 4096)
    fail(ErrorKind::Value, "specular size {} must be a power of two in 8..4096", d.size);
  const int most = log2i(d.size) + 1;
  if (d.levels < 0 || d.levels > most)
    fail(ErrorKind::Value, "specular levels {} outside 1..{} for size {} (0: the default {})", d.levels, most, d.size,
         std::max(1, log2i(d.size) - 3));
  if (d.samples < 16 || d.samples > 65536) fail(ErrorKind::Value, "specular samples {} outside 16..65536", d.samples);
  if (!(d.exact_budget >= 0)) fail(ErrorKind::Value, "exact_budget must be ≥ 0");
  return d.levels > 0 ? d.levels : std::max(1, log2i(d.size) - 3);
}

SpecularCube prefilter_ggx(const sphere::EnvMap& probe, const SpecularDesc& desc, const ProgressFn& progress) {
  const int n = specular_level_count(desc);
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  SpecularCube out;
  const CubeChain chain = build_cube_chain(probe, desc.size, desc.rotation);
  const double chain_seconds = std::chrono::duration<double>(clock::now() - t0).count();
  for (int m = 0; m < n; ++m) {
    auto tl = clock::now();
    SpecularLevel lv;
    lv.roughness = level_roughness(m, n, desc.lod);
    lv.alpha = lv.roughness * lv.roughness;
    const int s = std::max(1, desc.size >> m);
    auto sub = [&](std::string_view, double f) { report(progress, "specular", (m + f) / n); };
    if (lv.alpha <= 0) {
      lv.method = LevelMethod::Resample;
      lv.source_size = desc.size;
      out.cube.levels.push_back(chain.levels[0]);  // only level 0 has ρ = 0
    } else {
      int src = 8;
      while (src < desc.size && src * lv.alpha < 4) src *= 2;
      src = std::min(src, desc.size);
      const double cost = 36.0 * s * s * double(src) * src;
      if (cost <= desc.exact_budget) {
        lv.method = LevelMethod::Exact;
        lv.source_size = src;
        const Image& source = chain.levels[static_cast<size_t>(log2i(desc.size / src))];
        const double a = lv.alpha;
        out.cube.levels.push_back(convolve_cube(
            source, s, [a](double c) { return ggx_kernel(c, a); }, sub));
      } else {
        lv.method = LevelMethod::Importance;
        lv.source_size = desc.size;
        out.cube.levels.push_back(importance_level(chain, lv.alpha, s, desc.samples, sub));
      }
    }
    lv.seconds = std::chrono::duration<double>(clock::now() - tl).count() + (m == 0 ? chain_seconds : 0.0);
    out.info.push_back(lv);
    report(progress, "specular", double(m + 1) / n);
  }
  return out;
}

Vec3 ggx_reference(const sphere::EnvMap& probe, Vec3 r, double alpha, const Mat3& rotation, int sub) {
  const Vec3 rp = rotation.transposed() * normalize(r);  // r in the probe's own frame
  const sphere::Mapping& m = probe.mapping;
  const int w = m.width(), h = m.height(), nc = probe.image.channels();
  struct Acc {
    Vec3 sum;
    double weight = 0;
  };
  Acc total = parallel_reduce_fixed(
      0, h, 4, Acc{},
      [&](int64_t y0, int64_t y1) {
        Acc a;
        for (int y = static_cast<int>(y0); y < y1; ++y)
          for (int x = 0; x < w; ++x) {
            const double om = m.solid_angle(x, y);
            if (om <= 0) continue;
            const float* p = probe.image.pixel(x, y);
            const Vec3 L{p[0], nc > 1 ? p[1] : p[0], nc > 2 ? p[2] : p[0]};
            for (int j = 0; j < sub; ++j)
              for (int i = 0; i < sub; ++i) {
                Vec3 d;
                if (!m.to_direction(x + (i + 0.5) / sub, y + (j + 0.5) / sub, &d)) continue;
                const double k = ggx_kernel(dot(rp, d), alpha) * om / (sub * sub);
                a.sum += L * k;
                a.weight += k;
              }
          }
        return a;
      },
      [](Acc a, const Acc& b) {
        a.sum += b.sum;
        a.weight += b.weight;
        return a;
      });
  return total.weight > 0 ? total.sum / total.weight : Vec3{};
}

}  // namespace ibl::engine
