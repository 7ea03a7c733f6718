#include "iblkit/lights/cut.h"

#include <cmath>
#include <functional>
#include <queue>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::lights {

namespace {

// Summed-area table of T over a W×H grid (Crow 1984; Pedersen 2008 §6.1): s(x, y) = Σ over pixels
// [0,x)×[0,y); the sum over [x0,x1)×[y0,y1) is s(x1,y1) − s(x0,y1) − s(x1,y0) + s(x0,y0).
template <typename T>
struct Sat {
  int w = 0, h = 0;
  std::vector<T> s;
  T at(int x, int y) const { return s[static_cast<size_t>(y) * (w + 1) + x]; }
  T sum(int x0, int y0, int x1, int y1) const { return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0); }

  // value(x, y) gives the pixel's entry. Rows are prefixed in parallel, then accumulated down.
  template <typename F>
  void build(int width, int height, F&& value) {
    w = width;
    h = height;
    s.assign(static_cast<size_t>(w + 1) * (h + 1), T{});
    parallel_for(
        0, h,
        [&](int64_t y) {
          T* row = &s[static_cast<size_t>(y + 1) * (w + 1)];
          T acc{};
          for (int x = 0; x < w; ++x) {
            acc = acc + value(x, static_cast<int>(y));
            row[x + 1] = acc;
          }
        },
        8);
    for (int y = 1; y <= h; ++y) {
      T* row = &s[static_cast<size_t>(y) * (w + 1)];
      const T* prev = row - (w + 1);
      for (int x = 1; x <= w; ++x) row[x] = row[x] + prev[x];
    }
  }
};

// Energy-weighted first moment: W = Σ E, S = Σ E·ω.
struct Moment {
  double w = 0, sx = 0, sy = 0, sz = 0;
  Moment operator+(const Moment& o) const { return {w + o.w, sx + o.sx, sy + o.sy, sz + o.sz}; }
  Moment operator-(const Moment& o) const { return {w - o.w, sx - o.sx, sy - o.sy, sz - o.sz}; }
  // V = W − ‖S‖²/W (cut.h); 0 for an empty region.
  double variance() const { return w > 0 ? std::max(0.0, w - (sx * sx + sy * sy + sz * sz) / w) : 0.0; }
};

struct Region {
  int x0, y0, x1, y1;      // half-open pixel rectangle
  double key = 0;          // priority: energy (median cut) or variance removed by the best split
  int axis = -1, pos = 0;  // variance cut: the best split (axis −1: none)
};

// The any-N cut: split the region with the highest key next until there are n regions or none can
// be split. split(r, &a, &b) returns false for a region that must stay whole.
template <typename Split>
std::vector<Region> cut_highest_first(const Region& all, int n, Split&& split) {
  std::vector<Region> out;
  auto less = [](const Region& a, const Region& b) { return a.key < b.key; };
  std::priority_queue<Region, std::vector<Region>, decltype(less)> pq(less);
  pq.push(all);
  while (!pq.empty() && static_cast<int>(out.size() + pq.size()) < n) {
    Region r = pq.top();
    pq.pop();
    Region a, b;
    if (split(r, &a, &b)) {
      pq.push(a);
      pq.push(b);
    } else {
      out.push_back(r);
    }
  }
  for (; !pq.empty(); pq.pop()) out.push_back(pq.top());
  return out;
}

// Per-pixel directions of the grid in separable form: ω = (−sinθ cosφ, cosθ, −sinθ sinφ).
struct Trig {
  std::vector<double> sin_t, cos_t, cos_p, sin_p;
  explicit Trig(const LatLongGrid& g) : sin_t(g.height), cos_t(g.height), cos_p(g.width), sin_p(g.width) {
    for (int y = 0; y < g.height; ++y) {
      sin_t[y] = std::sin(kPi * (y + 0.5) / g.height);
      cos_t[y] = std::cos(kPi * (y + 0.5) / g.height);
    }
    for (int x = 0; x < g.width; ++x) {
      cos_p[x] = std::cos(kTwoPi * (x + 0.5) / g.width);
      sin_p[x] = std::sin(kTwoPi * (x + 0.5) / g.width);
    }
  }
  Vec3 dir(int x, int y) const { return {-sin_t[y] * cos_p[x], cos_t[y], -sin_t[y] * sin_p[x]}; }
};

double energy(const LatLongGrid& g, int x, int y) {
  return luminance(g.rgb[static_cast<size_t>(y) * g.width + x]) * g.row_solid_angle[y];
}

// Lit-pixel counts: exact emptiness tests that summed doubles cannot give.
Sat<int> lit_counts(const LatLongGrid& g) {
  Sat<int> c;
  c.build(g.width, g.height,
          [&](int x, int y) { return luminance(g.rgb[static_cast<size_t>(y) * g.width + x]) > 0 ? 1 : 0; });
  return c;
}

// One light per region: centroid normalize(Σ E ω), irradiance Σ L dω, solid angle Σ dω.
LightSet lights_from_regions(const LatLongGrid& g, const std::vector<Region>& regions, const Trig& trig,
                             const std::string& method) {
  LightSet set;
  set.method = method;
  set.lights.resize(regions.size());
  set.regions.width = g.width;
  set.regions.height = g.height;
  set.regions.label.assign(static_cast<size_t>(g.width) * g.height, -1);
  parallel_for(0, static_cast<int64_t>(regions.size()), [&](int64_t i) {
    const Region& r = regions[i];
    Vec3 s, irr;
    double omega = 0;
    for (int y = r.y0; y < r.y1; ++y) {
      double dw = g.row_solid_angle[y];
      Vec3 row_rgb, row_s;
      for (int x = r.x0; x < r.x1; ++x) {
        const Vec3& L = g.rgb[static_cast<size_t>(y) * g.width + x];
        set.regions.label[static_cast<size_t>(y) * g.width + x] = static_cast<int32_t>(i);
        row_rgb += L;
        row_s += trig.dir(x, y) * luminance(L);
      }
      irr += row_rgb * dw;
      s += row_s * dw;
      omega += dw * (r.x1 - r.x0);
    }
    Light& l = set.lights[i];
    // A region without energy (only in the degenerate 1-pixel case) points at its middle.
    l.direction = length(s) > 0 ? normalize(s) : g.direction(0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1));
    l.irradiance = irr;
    l.solid_angle = omega;
  });
  return set;
}

// Runs `cut(n)` (regions for n lights) and, with a minimum separation, merges close lights and cuts
// further until N lights remain or the cut cannot give more.
LightSet finish(const LatLongGrid& g, const CutDesc& desc, const std::string& method,
                const std::function<std::vector<Region>(int)>& cut) {
  Trig trig(g);
  int target = desc.count;
  LightSet set;
  for (int round = 0; round < 16; ++round) {
    auto regions = cut(target);
    set = lights_from_regions(g, regions, trig, method);
    if (desc.min_separation_deg <= 0) break;
    merge_close_lights(set, desc.min_separation_deg * kPi / 180.0);
    if (static_cast<int>(set.lights.size()) >= desc.count || static_cast<int>(regions.size()) < target ||
        desc.power_of_two)
      break;
    target += desc.count - static_cast<int>(set.lights.size());
  }
  rank_for_shadows(set);
  report(desc.progress, method, 1.0);
  return set;
}

void check_count(const LatLongGrid& g, const CutDesc& desc) {
  if (desc.count < 1) fail(ErrorKind::Value, "light count must be at least 1 (got {})", desc.count);
  if (!(desc.min_separation_deg >= 0 && desc.min_separation_deg < 180))
    fail(ErrorKind::Value, "minimum separation must be in [0, 180) degrees (got {})", desc.min_separation_deg);
  if (g.width < 1 || g.height < 1) fail(ErrorKind::Value, "the probe is empty");
}

}  // namespace

// ---- median cut ---------------------------------------------------------------------------------

LightSet median_cut(const LatLongGrid& g, const CutDesc& desc) {
  check_count(g, desc);
  if (desc.power_of_two && (desc.count & (desc.count - 1)) != 0)
    fail(ErrorKind::Value, "the classic (2^K) median cut needs a power-of-two count (got {})", desc.count);
  Sat<double> e;
  e.build(g.width, g.height, [&](int x, int y) { return energy(g, x, y); });
  Sat<int> lit = lit_counts(g);
  if (lit.at(g.width, g.height) == 0) fail(ErrorKind::Value, "the probe is all black: there is no light to extract");

  // Splits r along `axis` at the energy median, kept where both halves have a lit pixel.
  auto split_axis = [&](const Region& r, int axis, Region* a, Region* b) {
    int lo = axis == 0 ? r.x0 : r.y0, hi = axis == 0 ? r.x1 : r.y1;
    if (hi - lo < 2) return false;
    auto E = [&](int s) { return axis == 0 ? e.sum(r.x0, r.y0, s, r.y1) : e.sum(r.x0, r.y0, r.x1, s); };
    auto C = [&](int s) { return axis == 0 ? lit.sum(r.x0, r.y0, s, r.y1) : lit.sum(r.x0, r.y0, r.x1, s); };
    int total = C(hi);
    // First split index with a lit pixel on the left; last with one on the right.
    int a0 = lo + 1, a1 = hi - 1;
    while (a0 < a1) {
      int m = (a0 + a1) / 2;
      if (C(m) >= 1)
        a1 = m;
      else
        a0 = m + 1;
    }
    int s_lo = a0;
    a0 = lo + 1;
    a1 = hi - 1;
    while (a0 < a1) {
      int m = (a0 + a1 + 1) / 2;
      if (C(m) <= total - 1)
        a0 = m;
      else
        a1 = m - 1;
    }
    int s_hi = a0;
    if (C(s_lo) < 1 || C(s_hi) > total - 1 || s_lo > s_hi) return false;
    double half = 0.5 * E(hi);
    a0 = s_lo;
    a1 = s_hi;
    while (a0 < a1) {
      int m = (a0 + a1) / 2;
      if (E(m) >= half)
        a1 = m;
      else
        a0 = m + 1;
    }
    int s = a0;
    if (s - 1 >= s_lo && std::abs(E(s - 1) - half) <= std::abs(E(s) - half)) --s;
    *a = r;
    *b = r;
    if (axis == 0) {
      a->x1 = s;
      b->x0 = s;
    } else {
      a->y1 = s;
      b->y0 = s;
    }
    a->key = e.sum(a->x0, a->y0, a->x1, a->y1);
    b->key = e.sum(b->x0, b->y0, b->x1, b->y1);
    return true;
  };
  // Longest side on the sphere first: width (2π/W)·sinθ(middle row), height π/H per pixel.
  auto split = [&](const Region& r, Region* a, Region* b) {
    double wlen = (r.x1 - r.x0) * kTwoPi / g.width * std::sin(kPi * 0.5 * (r.y0 + r.y1) / g.height);
    double hlen = (r.y1 - r.y0) * kPi / g.height;
    int first = wlen >= hlen ? 0 : 1;
    return split_axis(r, first, a, b) || split_axis(r, 1 - first, a, b);
  };
  Region all{0, 0, g.width, g.height, e.sum(0, 0, g.width, g.height)};

  auto cut = [&](int n) {
    std::vector<Region> out;
    if (desc.power_of_two) {
      out.push_back(all);
      for (int k = 1; k < n; k *= 2) {
        std::vector<Region> next;
        for (const auto& r : out) {
          Region a, b;
          if (split(r, &a, &b)) {
            next.push_back(a);
            next.push_back(b);
          } else
            next.push_back(r);
        }
        out.swap(next);
      }
      return out;
    }
    return cut_highest_first(all, n, split);
  };
  return finish(g, desc, "median-cut", cut);
}

LightSet median_cut(const sphere::EnvMap& env, const CutDesc& desc) {
  validate_probe(env, desc.count);
  return median_cut(to_latlong_grid(env), desc);
}

// ---- variance-minimisation cut -------------------------------------------------------------------

LightSet variance_cut(const LatLongGrid& g, const CutDesc& desc) {
  check_count(g, desc);
  Trig trig(g);
  Sat<Moment> m;
  m.build(g.width, g.height, [&](int x, int y) {
    double en = energy(g, x, y);
    Vec3 d = trig.dir(x, y);
    return Moment{en, en * d.x, en * d.y, en * d.z};
  });
  Sat<int> lit = lit_counts(g);
  if (lit.at(g.width, g.height) == 0) fail(ErrorKind::Value, "the probe is all black: there is no light to extract");

  // Finds the split of r (either axis, halves with a lit pixel each) with the least V(A) + V(B).
  auto best_split = [&](Region& r) {
    Moment whole = m.sum(r.x0, r.y0, r.x1, r.y1);
    int total = lit.sum(r.x0, r.y0, r.x1, r.y1);
    double best = whole.variance();
    r.axis = -1;
    for (int axis = 0; axis < 2; ++axis) {
      int lo = axis == 0 ? r.x0 : r.y0, hi = axis == 0 ? r.x1 : r.y1;
      for (int s = lo + 1; s < hi; ++s) {
        Moment a = axis == 0 ? m.sum(r.x0, r.y0, s, r.y1) : m.sum(r.x0, r.y0, r.x1, s);
        int ca = axis == 0 ? lit.sum(r.x0, r.y0, s, r.y1) : lit.sum(r.x0, r.y0, r.x1, s);
        if (ca == 0 || ca == total) continue;
        double v = a.variance() + (whole - a).variance();
        if (v < best || r.axis < 0) {
          best = v;
          r.axis = axis;
          r.pos = s;
        }
      }
    }
    r.key = r.axis < 0 ? -1.0 : whole.variance() - best;
  };
  Region all{0, 0, g.width, g.height};
  best_split(all);

  auto cut = [&](int n) {
    return cut_highest_first(all, n, [&](const Region& r, Region* a, Region* b) {
      if (r.axis < 0) return false;
      *a = r;
      *b = r;
      if (r.axis == 0) {
        a->x1 = r.pos;
        b->x0 = r.pos;
      } else {
        a->y1 = r.pos;
        b->y0 = r.pos;
      }
      best_split(*a);
      best_split(*b);
      return true;
    });
  };
  return finish(g, desc, "variance-cut", cut);
}

LightSet variance_cut(const sphere::EnvMap& env, const CutDesc& desc) {
  validate_probe(env, desc.count);
  return variance_cut(to_latlong_grid(env), desc);
}

}  // namespace ibl::lights
