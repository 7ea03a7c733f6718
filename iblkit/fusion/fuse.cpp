#include "iblkit/fusion/fuse.h"

#include <atomic>
#include <cmath>

#include "iblkit/core/check.h"
#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"
#include "iblkit/core/fastmath.h"
#include "iblkit/core/parallel.h"

namespace ibl::fusion {

namespace {
constexpr EnumName<Blend> kBlendNames[] = {
    {Blend::Nearest, "nearest"}, {Blend::Angle, "angle"}, {Blend::Footprint, "footprint"}};
}  // namespace

std::string blend_name(Blend b) { return name_of(kBlendNames, b); }
Blend parse_blend(const std::string& s) { return parse_enum(kBlendNames, s, "blend"); }

sphere::Mapping output_mapping(sphere::MappingKind k, int size) {
  if (size < 1 || size > 8192) fail(ErrorKind::Value, "output size {} is out of range [1, 8192]", size);
  switch (k) {
    case sphere::MappingKind::LatLong:
      return {k, 2 * size, size};
    case sphere::MappingKind::CubeHCross:
      return {k, 4 * size, 3 * size};
    case sphere::MappingKind::CubeVCross:
      return {k, 3 * size, 4 * size};
    case sphere::MappingKind::CubeStrip:
      return {k, 6 * size, size};
    default:
      return {k, size, size};
  }
}

namespace {

constexpr double kFallbackSoftening2 = 0.01;  // h² in 1/(|x − x_i|² + h²): h = 0.1 m keeps weights finite at a probe
constexpr double kMaxTan = 20;                // tan α cap of the slope bias (α ≈ 87°)
constexpr double kNegligibleWeight = 1e-3;    // blend weights below this share of the total are skipped
constexpr double kMinCos = 0.05;  // cos α floor of the footprint weight (grazing views still count a little)

// Per-probe data in the form the inner loop wants.
struct Lut {
  Vec3 pos;
  Mat3 to_local;  // world -> probe frame (Rᵀ)
  bool latlong = false;
  int w = 0, h = 0;
  const float* rgbd = nullptr;   // lat-long: R, G, B, depth interleaved (Probe::rgbd)
  const float* depth = nullptr;  // other mappings: 1 channel
  const Probe* probe = nullptr;
  double delta = 0;      // texel angle √(4π/N)
  double inv_omega = 0;  // 1/(4π/N)

  // Continuous pixel coordinates of a local direction (ok = false: no data there).
  struct Px {
    float x = 0, y = 0;
    bool ok = false;
  };
  Px locate(Vec3 d) const {
    Px p;
    if (latlong) {
      constexpr float kInvTwoPi = 0.159154943091895f, kInvPi = 0.318309886183791f;
      float u = fast_atan2(static_cast<float>(d.z), static_cast<float>(d.x)) * kInvTwoPi + 0.5f;
      float r = std::sqrt(static_cast<float>(d.x * d.x + d.z * d.z));
      float v = fast_atan2(r, static_cast<float>(d.y)) * kInvPi;
      p.x = u * w;
      p.y = v * h;
      p.ok = true;
      return p;
    }
    double px, py;
    p.ok = probe->radiance.mapping.to_pixel(d, &px, &py);
    p.x = static_cast<float>(px);
    p.y = static_cast<float>(py);
    return p;
  }
  // Depth at the texel nearest the pixel position (0: none).
  float depth_at(const Px& p) const {
    if (!p.ok) return 0;
    int ix = std::clamp(static_cast<int>(p.x), 0, w - 1), iy = std::clamp(static_cast<int>(p.y), 0, h - 1);
    size_t i = static_cast<size_t>(iy) * w + ix;
    return latlong ? rgbd[4 * i + 3] : depth[i];
  }
  // Bilinear radiance towards the local direction d. With tol > 0 (a lat-long probe) only the taps whose
  // depth lies within tol of r take part: the lookup does not bleed across depth edges.
  Vec3 radiance_at(Vec3 d, const Px& p, double r = 0, double tol = 0) const {
    if (!latlong) return probe->radiance.sample_rgb(d);
    float fx = p.x - 0.5f, fy = p.y - 0.5f;
    float x0f = std::floor(fx), y0f = std::floor(fy);
    float tx = fx - x0f, ty = fy - y0f;
    int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
    int x1 = x0 + 1, y1 = y0 + 1;
    x0 = x0 < 0 ? x0 + w : (x0 >= w ? x0 - w : x0);  // |x0| ≤ w: one wrap at most
    x1 = x1 < 0 ? x1 + w : (x1 >= w ? x1 - w : x1);
    y0 = std::clamp(y0, 0, h - 1);
    y1 = std::clamp(y1, 0, h - 1);
    const float* a = rgbd + (static_cast<size_t>(y0) * w + x0) * 4;
    const float* b = rgbd + (static_cast<size_t>(y0) * w + x1) * 4;
    const float* c = rgbd + (static_cast<size_t>(y1) * w + x0) * 4;
    const float* e = rgbd + (static_cast<size_t>(y1) * w + x1) * 4;
    float w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
    if (tol > 0) {
      auto ok = [&](const float* t) { return std::abs(t[3] - r) <= tol; };
      float m00 = ok(a) ? w00 : 0, m10 = ok(b) ? w10 : 0, m01 = ok(c) ? w01 : 0, m11 = ok(e) ? w11 : 0;
      float sum = m00 + m10 + m01 + m11;
      if (sum > 0 && sum < 1) {
        w00 = m00 / sum;
        w10 = m10 / sum;
        w01 = m01 / sum;
        w11 = m11 / sum;
      }
    }
    return {w00 * a[0] + w10 * b[0] + w01 * c[0] + w11 * e[0], w00 * a[1] + w10 * b[1] + w01 * c[1] + w11 * e[1],
            w00 * a[2] + w10 * b[2] + w01 * c[2] + w11 * e[2]};
  }
};

struct RayOut {
  Vec3 L;
  double t = 0;
  PixelStatus status = PixelStatus::NoData;
  int seen = 0;
};

class Fuser {
 public:
  Fuser(const ProbeSet& set, const FuseDesc& desc) : set_(set), desc_(desc) {
    if (!set.tracer) fail(ErrorKind::Value, "fuse: the probe set is not prepared (call fusion::prepare)");
    if (desc.samples < 1 || desc.samples > 16)
      fail(ErrorKind::Value, "fuse: samples {} is out of range [1, 16]", desc.samples);
    if (!(desc.depth_bias >= 0) || !(desc.slope_bias >= 0) || !(desc.depth_tolerance >= 0))
      fail(ErrorKind::Value, "fuse: depth bias {}, slope bias {} and depth tolerance {} must be ≥ 0", desc.depth_bias,
           desc.slope_bias, desc.depth_tolerance);
    if (!(desc.angle_power >= 0)) fail(ErrorKind::Value, "fuse: angle power {} must be ≥ 0", desc.angle_power);
    if (!(desc.angle_threshold >= -1 && desc.angle_threshold <= 1))
      fail(ErrorKind::Value, "fuse: angle threshold {} must be a cosine in [−1, 1]", desc.angle_threshold);
    for (const Probe& p : set.probes) {
      Lut l;
      l.pos = p.position;
      l.to_local = p.rotation.transposed();
      l.latlong = p.radiance.mapping.kind() == sphere::MappingKind::LatLong;
      l.w = p.radiance.image.width();
      l.h = p.radiance.image.height();
      if (p.radiance.image.channels() != 3 || p.depth.width() != l.w || p.depth.height() != l.h ||
          p.depth.channels() != 1)
        fail(ErrorKind::Value,
             "fuse: probe {} is not prepared (3-channel radiance and a 1-channel depth map of its size)", p.image);
      if (l.latlong && p.rgbd.size() != p.radiance.image.pixel_count() * 4)
        fail(ErrorKind::Value, "fuse: probe {} is not prepared (call fusion::prepare)", p.image);
      l.rgbd = p.rgbd.data();
      l.depth = p.depth.data();
      l.probe = &p;
      double n = 0;
      if (l.latlong)
        n = static_cast<double>(l.w) * l.h;
      else
        for (int y = 0; y < l.h; ++y)
          for (int x = 0; x < l.w; ++x) n += p.radiance.mapping.valid(x, y);
      l.inv_omega = n / kFourPi;
      l.delta = std::sqrt(kFourPi / std::max(n, 1.0));
      luts_.push_back(l);
    }
    if (desc.angle_power == std::floor(desc.angle_power) && desc.angle_power <= 32)
      int_power_ = static_cast<int>(desc.angle_power);
    normals_.resize(set.proxy.triangle_count());
    for (size_t i = 0; i < normals_.size(); ++i) normals_[i] = set.proxy.normal(i);
  }

  RayOut shade(Vec3 x, Vec3 w) const {
    RayOut out;
    geometry::Hit h = set_.tracer->intersect(x, w);
    if (!h.hit) {
      out.status = PixelStatus::LeftProxy;
      out.L = distant(x, w, true);
      return out;
    }
    out.t = h.t;
    Vec3 p = x + w * h.t, n = normals_[h.triangle];
    double side_x = dot(n, w);
    // Pass 1: which probes see p, and their blend weights.
    struct Cand {
      int i;
      double wgt;
      Vec3 local;
      Lut::Px px;
      double r, tol;  // distance to p and the depth tolerance of its lookup taps (0: plain bilinear)
    };
    thread_local std::vector<Cand> cand;
    cand.clear();
    int best = -1;
    double best_s = -2, best_r = 0, best_tol = 0;
    Vec3 best_local;
    Lut::Px best_px;
    for (size_t i = 0; i < luts_.size(); ++i) {
      const Lut& l = luts_[i];
      Vec3 v = p - l.pos;
      double r = length(v);
      if (r <= 0) continue;
      Vec3 u = v / r, local = l.to_local * u;
      double cos_a = dot(n, u), tol = 0;
      if (desc_.visibility && cos_a * side_x <= 0) continue;  // the probe is behind p's face (x is in front of it)
      Lut::Px px = l.locate(local);
      if (desc_.visibility) {
        double d = l.depth_at(px);
        double ca = std::abs(cos_a),
               tan_a = std::min(std::sqrt(std::max(0.0, 1 - ca * ca)) / std::max(ca, 1e-9), kMaxTan);
        double rel = desc_.depth_bias + desc_.slope_bias * l.delta * tan_a;
        if (!(d > 0) || r > d * (1 + rel) + desc_.depth_tolerance) continue;
        // Taps one texel further away may see the surface at most ~2× the slope term off.
        if (desc_.edge_aware)
          tol = r * (desc_.depth_bias + 2 * desc_.slope_bias * l.delta * tan_a) + desc_.depth_tolerance;
      }
      double s = dot(w, u);
      double wgt = 0;
      switch (desc_.blend) {
        case Blend::Nearest:
          break;
        case Blend::Angle:
          wgt = s >= desc_.angle_threshold && s > 0 ? s : 0;
          break;
        case Blend::Footprint:
          wgt = power(0.5 * (1 + s)) * std::max(std::abs(cos_a), kMinCos) * l.inv_omega / (r * r);
          break;
      }
      if (s > best_s) {
        best_s = s;
        best = static_cast<int>(i);
        best_local = local;
        best_px = px;
        best_r = r;
        best_tol = tol;
      }
      if (wgt > 0) cand.push_back({static_cast<int>(i), wgt, local, px, r, tol});
      ++out.seen;
    }
    if (best < 0) {
      out.status = PixelStatus::Unseen;
      out.L = distant(x, w, false);
      return out;
    }
    out.status = PixelStatus::Fused;
    // Pass 2: radiance lookups of the probes that carry weight (the nearest alone when none does).
    if (desc_.blend == Blend::Nearest || cand.empty()) {
      out.L = luts_[best].radiance_at(best_local, best_px, best_r, best_tol);
      return out;
    }
    // Probes with less than 10⁻³ of the total weight change L by < 0.1% of their radiance: skipped.
    double wall = 0;
    for (const Cand& c : cand) wall += c.wgt;
    Vec3 sum;
    double wsum = 0;
    for (const Cand& c : cand) {
      if (c.wgt < kNegligibleWeight * wall) continue;
      sum += luts_[c.i].radiance_at(c.local, c.px, c.r, c.tol) * c.wgt;
      wsum += c.wgt;
    }
    out.L = sum / wsum;
    return out;
  }

 private:
  // Distant lookup L_i(ω) weighted by 1/(|x − x_i|² + h²); when the ray left the proxy, over the
  // probes whose own ray along ω leaves it too (when there are any).
  Vec3 distant(Vec3 x, Vec3 w, bool left) const {
    Vec3 all, out;
    double wall = 0, wout = 0;
    for (const Lut& l : luts_) {
      Vec3 local = l.to_local * w;
      Lut::Px px = l.locate(local);
      Vec3 dx = x - l.pos;
      double wgt = 1.0 / (dot(dx, dx) + kFallbackSoftening2);
      Vec3 L = l.radiance_at(local, px);
      all += L * wgt;
      wall += wgt;
      if (left && l.depth_at(px) <= 0) {
        out += L * wgt;
        wout += wgt;
      }
    }
    return wout > 0 ? out / wout : all / wall;
  }

  // q^k of the footprint weight; whole k by repeated multiplication (std::pow costs ~30 ns per call).
  double power(double q) const {
    if (int_power_ < 0) return std::pow(q, desc_.angle_power);
    double r = 1;
    for (int i = 0; i < int_power_; ++i) r *= q;
    return r;
  }

  const ProbeSet& set_;
  const FuseDesc& desc_;
  int int_power_ = -1;
  std::vector<Lut> luts_;
  std::vector<Vec3> normals_;
};

void check_x(const ProbeSet& set, Vec3 x) {
  PointCheck c = check_point(set, x);
  if (c.backface > 0.5)
    fail(
        ErrorKind::Value,
        "fuse: the point ({}, {}, {}) is inside geometry or outside the proxy ({:.0f}% of its rays reach the back of a "
        "proxy face)",
        x.x, x.y, x.z, 100 * c.backface);
}

}  // namespace

std::vector<Vec3> fuse_rays(const ProbeSet& set, Vec3 x, const std::vector<Vec3>& dirs, const FuseDesc& desc,
                            std::vector<PixelStatus>* status) {
  require_point("fuse: the point", x);
  Fuser f(set, desc);
  std::vector<Vec3> out(dirs.size());
  if (status) status->assign(dirs.size(), PixelStatus::NoData);
  parallel_for(
      0, static_cast<int64_t>(dirs.size()),
      [&](int64_t i) {
        RayOut r = f.shade(x, normalize(dirs[i]));
        out[i] = r.L;
        if (status) (*status)[i] = r.status;
      },
      256);
  return out;
}

Vec3 fuse_ray(const ProbeSet& set, Vec3 x, Vec3 omega, const FuseDesc& desc, PixelStatus* status) {
  require_point("fuse: the point", x);
  omega = require_direction("fuse: the direction", omega);
  Fuser f(set, desc);
  RayOut r = f.shade(x, omega);
  if (status) *status = r.status;
  return r.L;
}

LocalMap fuse(const ProbeSet& set, Vec3 x, const FuseDesc& desc) {
  require_point("fuse: the point", x);
  sphere::Mapping m = output_mapping(desc.mapping, desc.size);
  Fuser fuser(set, desc);
  if (desc.check_point) check_x(set, x);
  const int W = m.width(), H = m.height(), n = desc.samples;
  LocalMap out;
  out.point = x;
  Image rad(W, H, 3);
  out.depth = Image(W, H, 1);
  out.coverage = Image(W, H, 1);
  out.status.assign(static_cast<size_t>(W) * H, PixelStatus::NoData);
  std::atomic<int> rows{0};
  parallel_for(
      0, H,
      [&](int64_t yy) {
        int y = static_cast<int>(yy);
        for (int xx = 0; xx < W; ++xx) {
          Vec3 d;
          if (!m.to_direction(xx + 0.5, y + 0.5, &d)) continue;
          RayOut c = fuser.shade(x, d);
          Vec3 L = c.L;
          if (n > 1) {
            Vec3 sum;
            int used = 0;
            for (int s = 0; s < n * n; ++s) {
              Vec3 ds;
              if (!m.to_direction(xx + (s % n + 0.5) / n, y + (s / n + 0.5) / n, &ds)) continue;
              sum += fuser.shade(x, ds).L;
              ++used;
            }
            if (used) L = sum / used;
          }
          rad.set_rgb(xx, y, L);
          out.depth.at(xx, y, 0) = static_cast<float>(c.t);
          out.coverage.at(xx, y, 0) = static_cast<float>(c.status == PixelStatus::Fused ? c.seen : 0);
          out.status[static_cast<size_t>(y) * W + xx] = c.status;
        }
        report(desc.progress, "fuse", static_cast<double>(++rows) / H);
      },
      4);
  out.radiance = sphere::EnvMap(std::move(rad), m);
  double all = 0, fused = 0, left = 0, unseen = 0, probes = 0;
  for (int y = 0; y < H; ++y)
    for (int xx = 0; xx < W; ++xx) {
      PixelStatus s = out.status[static_cast<size_t>(y) * W + xx];
      if (s == PixelStatus::NoData) continue;
      double w = m.solid_angle_estimate(xx, y);
      all += w;
      if (s == PixelStatus::Fused) {
        fused += w;
        probes += w * out.coverage.at(xx, y, 0);
      }
      if (s == PixelStatus::LeftProxy) left += w;
      if (s == PixelStatus::Unseen) unseen += w;
    }
  if (all > 0) {
    out.stats.fused = fused / all;
    out.stats.left_proxy = left / all;
    out.stats.unseen = unseen / all;
    out.stats.mean_probes = fused > 0 ? probes / fused : 0;
  }
  if (out.stats.fused == 0)
    out.warnings.push_back(
        fmt::format("no direction at ({}, {}, {}) reaches a proxy point a probe sees: the whole map is the "
                    "distant fallback",
                    x.x, x.y, x.z));
  else if (out.stats.unseen > 0.01)
    out.warnings.push_back(
        fmt::format("{:.1f}% of the sphere at ({}, {}, {}) hits proxy points no probe sees (distant fallback; "
                    "see the coverage map)",
                    100 * out.stats.unseen, x.x, x.y, x.z));
  return out;
}

}  // namespace ibl::fusion
