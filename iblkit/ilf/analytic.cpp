#include "iblkit/ilf/analytic.h"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <random>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::ilf {
namespace fs = std::filesystem;

AnalyticField AnalyticField::three_spheres() {
  AnalyticField f;
  f.spheres = {{{1.6, 0.9, 0.2}, 0.35, {30.0, 22.0, 12.0}},
               {{-1.3, 0.4, -1.1}, 0.3, {4.0, 10.0, 28.0}},
               {{0.2, 1.5, 1.4}, 0.25, {18.0, 6.0, 6.0}}};
  return f;
}

AnalyticField AnalyticField::distant(double factor) {
  AnalyticField f = three_spheres();
  for (auto& s : f.spheres) {
    s.centre *= factor;
    s.radius *= factor;
  }
  return f;
}

Vec3 AnalyticField::radiance(Vec3 x, Vec3 w) const {
  double best = 1e300;
  Vec3 out;
  for (const auto& s : spheres) {
    // |x + t w − c|² = r²  →  t² + 2 b t + cc = 0 with b = (x − c)·w, cc = |x − c|² − r².
    Vec3 oc = x - s.centre;
    double b = dot(oc, w), cc = dot(oc, oc) - s.radius * s.radius, disc = b * b - cc;
    if (disc < 0) continue;
    double t = -b - std::sqrt(disc);
    if (t > 0 && t < best) {
      best = t;
      out = s.radiance;
    }
  }
  if (best < 1e300) return out;
  if (w.y >= 0) return sky_horizon + (sky_zenith - sky_horizon) * w.y;
  return sky_horizon * 0.5;
}

Image AnalyticField::render_probe(const Sequence& seq, int width, int height, Vec3 x, int ss) const {
  sphere::Mapping m(seq.mapping, width, height, seq.dead_angle_deg);
  Image img(width, height, 3, 0.0f);
  for (int y = 0; y < height; ++y)
    for (int xx = 0; xx < width; ++xx) {
      Vec3 acc{0, 0, 0};
      int n = 0;
      for (int sy = 0; sy < ss; ++sy)
        for (int sx = 0; sx < ss; ++sx) {
          Vec3 d;
          if (!m.to_direction(xx + (sx + 0.5) / ss, y + (sy + 0.5) / ss, &d)) continue;
          acc += radiance(x, normalize(seq.rotation * d));
          ++n;
        }
      if (n) img.set_rgb(xx, y, acc / n);
    }
  return img;
}

std::vector<sh::Coeffs> AnalyticField::exact_sh(const std::vector<Vec3>& xs, int bands, const Sequence& seq, int n,
                                                int ss) const {
  int K = bands * bands;
  double cos_dead = std::cos(seq.dead_angle_deg * kPi / 180);
  bool dead = seq.mapping == sphere::MappingKind::MirrorBall && seq.dead_angle_deg > 0;
  Mat3 to_probe = seq.rotation.transposed();
  // Quadrature table: directions, weights (exact cell solid angle / ss²) and basis values.
  std::vector<Vec3> dirs;
  std::vector<double> wts, basis;
  int W = 2 * n * ss, H = n * ss;
  for (int j = 0; j < H; ++j) {
    double t0 = kPi * j / H, t1 = kPi * (j + 1) / H, th = std::acos(0.5 * (std::cos(t0) + std::cos(t1)));
    double dw = (2 * kPi / W) * (std::cos(t0) - std::cos(t1));
    for (int i = 0; i < W; ++i) {
      double u = (i + 0.5) / W;
      Vec3 d{-std::sin(th) * std::cos(2 * kPi * u), std::cos(th), -std::sin(th) * std::sin(2 * kPi * u)};
      if (dead && (to_probe * d).z < -cos_dead) continue;
      dirs.push_back(d);
      wts.push_back(dw);
      basis.resize(basis.size() + size_t(K));
      sh::eval_basis(bands, d, basis.data() + basis.size() - size_t(K));
    }
  }
  std::vector<sh::Coeffs> out(xs.size());
  parallel_for(0, int64_t(xs.size()), [&](int64_t p) {
    std::vector<double> acc(size_t(K) * 3, 0.0);
    for (size_t q = 0; q < dirs.size(); ++q) {
      Vec3 L = radiance(xs[p], dirs[q]) * wts[q];
      const double* y = basis.data() + q * size_t(K);
      for (int k = 0; k < K; ++k) {
        acc[3 * k] += L.x * y[k];
        acc[3 * k + 1] += L.y * y[k];
        acc[3 * k + 2] += L.z * y[k];
      }
    }
    out[p].bands = bands;
    for (int k = 0; k < K; ++k) out[p].c.push_back({acc[3 * k], acc[3 * k + 1], acc[3 * k + 2]});
  });
  return out;
}

std::string write_synthetic_sequence(const AnalyticField& f, const SynthDesc& d, const ProgressFn& progress) {
  if (d.probes < 1 || d.size < 8) fail(ErrorKind::Value, "synthetic sequence: need ≥ 1 probe of ≥ 8 pixels");
  ibl::make_output_folders(fs::path(fs::path(d.out_dir) / "frames").string());
  Sequence seq;
  seq.mapping = sphere::MappingKind::MirrorBall;
  seq.dead_angle_deg = d.dead_angle_deg;
  seq.volume = d.volume;
  seq.volume_given = true;
  std::mt19937_64 rng(d.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int p = 0; p < d.probes; ++p) {
    Vec3 s = d.volume.size();
    Vec3 x{d.volume.min.x + s.x * U(rng), d.volume.min.y + s.y * U(rng), d.volume.min.z + s.z * U(rng)};
    std::string name = fmt::format("frames/{:06d}.{}", p, d.half ? "exr" : "pfm");
    seq.probes.push_back({(fs::path(d.out_dir) / name).string(), x});
  }
  std::atomic<int> done{0};
  parallel_for(0, d.probes, [&](int64_t p) {
    Image img = f.render_probe(seq, d.size, d.size, seq.probes[p].position, d.supersample);
    io::WriteDesc wd;
    wd.half = d.half;
    io::write_image(seq.probes[p].image, img, wd);
    ibl::report(progress, "synth", double(++done) / d.probes);
  });
  std::string manifest = (fs::path(d.out_dir) / "sequence.json").string();
  write_sequence(manifest, seq);
  return manifest;
}

}  // namespace ibl::ilf
