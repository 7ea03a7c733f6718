#include "lights_pictures.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "iblkit/io/draw.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lights/evaluate.h"

namespace iblcli {

namespace {

using ibl::Image;
using ibl::Vec3;

const Vec3 kPalette[] = {
    {0.95, 0.45, 0.15}, {0.25, 0.65, 0.95}, {0.35, 0.85, 0.35}, {0.9, 0.3, 0.8}, {0.95, 0.85, 0.2}};

void dashed_line(Image& img, double x0, double y0, double x1, double y1, Vec3 c, double dash = 6) {
  double len = std::hypot(x1 - x0, y1 - y0);
  int n = std::max(1, static_cast<int>(len / dash));
  for (int i = 0; i < n; i += 2) {
    double a = static_cast<double>(i) / n, b = std::min(1.0, static_cast<double>(i + 1) / n);
    ibl::io::draw_line(img, x0 + a * (x1 - x0), y0 + a * (y1 - y0), x0 + b * (x1 - x0), y0 + b * (y1 - y0), c, 1.5);
  }
}

// A "nice" axis maximum: 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 × 10^k at or above v.
double nice_ceiling(double v) {
  if (v <= 0) return 1;
  double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0})
    if (m * p >= v) return m * p;
  return 10 * p;
}

void panel(Image& img, int x0, int y0, int w, int h, const std::vector<ErrorCurve>& curves, bool use_max,
           double reference, const std::string& label, const std::string& ref_name) {
  const Vec3 axis{0.8, 0.8, 0.8}, grid{0.25, 0.25, 0.27};
  int n_min = 1 << 30, n_max = 1;
  double y_top = 0;
  for (const auto& c : curves)
    for (size_t i = 0; i < c.counts.size(); ++i) {
      n_min = std::min(n_min, c.counts[i]);
      n_max = std::max(n_max, c.counts[i]);
      y_top = std::max(y_top, 100 * (use_max ? c.max[i] : c.mean[i]));
    }
  if (reference > 0) y_top = std::max(y_top, 100 * reference);
  if (n_min > n_max) n_min = 1;
  if (n_max == n_min) n_max = n_min * 2;
  y_top = nice_ceiling(y_top * 1.05);
  double lx0 = std::log2(static_cast<double>(n_min)), lx1 = std::log2(static_cast<double>(n_max));
  auto X = [&](double n) { return x0 + (std::log2(n) - lx0) / (lx1 - lx0) * w; };
  auto Y = [&](double pct) { return y0 + h - pct / y_top * h; };
  // Grid: one vertical line per power of two, five horizontal divisions.
  for (int e = static_cast<int>(std::ceil(lx0)); e <= static_cast<int>(std::floor(lx1)); ++e) {
    double x = X(std::pow(2.0, e));
    ibl::io::draw_line(img, x, y0, x, y0 + h, grid);
    ibl::io::draw_text(img, static_cast<int>(x) - 8, y0 + h + 18, std::to_string(1 << e), 13, axis);
  }
  for (int i = 0; i <= 5; ++i) {
    double pct = y_top * i / 5, y = Y(pct);
    ibl::io::draw_line(img, x0, y, x0 + w, y, grid);
    ibl::io::draw_text(img, x0 - 44, static_cast<int>(y) + 5, fmt::format("{:g}%", pct), 13, axis);
  }
  ibl::io::draw_line(img, x0, y0 + h, x0 + w, y0 + h, axis);
  ibl::io::draw_line(img, x0, y0, x0, y0 + h, axis);
  ibl::io::draw_text(img, x0 + w / 2 - 60, y0 + h + 38, "number of lights N", 14, axis);
  ibl::io::draw_text(img, x0, y0 - 10, label, 16, {1, 1, 1});
  if (reference > 0) {
    dashed_line(img, x0, Y(100 * reference), x0 + w, Y(100 * reference), {0.75, 0.75, 0.75});
    ibl::io::draw_text(img, x0 + w - 90, static_cast<int>(Y(100 * reference)) - 4, ref_name, 12, {0.75, 0.75, 0.75});
  }
  for (size_t ci = 0; ci < curves.size(); ++ci) {
    const auto& c = curves[ci];
    Vec3 col = kPalette[ci % std::size(kPalette)];
    for (size_t i = 0; i < c.counts.size(); ++i) {
      double x = X(c.counts[i]), y = Y(100 * (use_max ? c.max[i] : c.mean[i]));
      if (i > 0)
        ibl::io::draw_line(img, X(c.counts[i - 1]), Y(100 * (use_max ? c.max[i - 1] : c.mean[i - 1])), x, y, col, 2.0);
      ibl::io::draw_disc(img, x, y, 3.5, col);
    }
    // Legend, top right.
    int ly = y0 + 16 + 18 * static_cast<int>(ci);
    ibl::io::draw_line(img, x0 + w - 150, ly - 5, x0 + w - 126, ly - 5, col, 2.0);
    ibl::io::draw_text(img, x0 + w - 120, ly, c.name, 13, {0.95, 0.95, 0.95});
  }
}

// Colour ramp for errors: 0 black-blue → 25% green → 50%+ red.
Vec3 error_colour(double e) {
  double t = std::clamp(e / 0.5, 0.0, 1.0);
  if (t < 0.5) return Vec3{0.05, 0.1, 0.4} * (1 - 2 * t) + Vec3{0.2, 0.8, 0.2} * (2 * t);
  return Vec3{0.2, 0.8, 0.2} * (2 - 2 * t) + Vec3{0.95, 0.15, 0.1} * (2 * t - 1);
}

}  // namespace

Image error_plot(const std::vector<ErrorCurve>& curves, const ErrorPlotDesc& desc) {
  Image img(desc.width, desc.height, 3, 0.07f);
  int margin_l = 70, margin_r = 20, top = 60, bottom = 60, gap = 70;
  int pw = (desc.width - margin_l - margin_r - gap) / 2, ph = desc.height - top - bottom;
  if (!desc.title.empty()) ibl::io::draw_text(img, margin_l, 24, desc.title, 18, {1, 1, 1});
  panel(img, margin_l, top, pw, ph, curves, false, desc.reference_mean, "mean irradiance error", desc.reference_name);
  panel(img, margin_l + pw + gap, top, pw, ph, curves, true, desc.reference_max, "max irradiance error",
        desc.reference_name);
  return img;
}

Image light_overlay(const ibl::sphere::EnvMap& env, const ibl::lights::LightSet& set, int width, int numbered) {
  int height = width / 2;
  ibl::sphere::Mapping ll(ibl::sphere::MappingKind::LatLong, width, height);
  Image pic = ibl::io::tonemap(ibl::sphere::resample(env, ll)).with_channels(3);
  const auto& reg = set.regions;
  // Region outlines: pixels whose region differs from the right or lower neighbour's.
  if (!reg.empty()) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        int rx = x * reg.width / width, ry = y * reg.height / height;
        int rx1 = std::min(reg.width - 1, (x + 1) * reg.width / width),
            ry1 = std::min(reg.height - 1, (y + 1) * reg.height / height);
        if (reg.at(rx, ry) != reg.at(rx1, ry) || reg.at(rx, ry) != reg.at(rx, ry1))
          pic.set_rgb(x, y, pic.rgb(x, y) * 0.15 + Vec3{0.1, 1.0, 0.2} * 0.85);
      }
  }
  for (size_t i = 0; i < set.lights.size(); ++i) {
    const auto& l = set.lights[i];
    double px = 0, py = 0;
    ll.to_pixel(l.direction, &px, &py);
    double u = px / width, v = py / height;
    double r = i < static_cast<size_t>(numbered) ? 5 : 3;
    ibl::io::draw_disc(pic, u * width, v * height, r + 1.5, {0, 0, 0});
    ibl::io::draw_disc(pic, u * width, v * height, r, {1.0, 0.15, 0.1});
    if (static_cast<int>(i) < numbered) {
      int tx = static_cast<int>(u * width) + 7, ty = static_cast<int>(v * height) - 5;
      ibl::io::draw_text(pic, tx + 1, ty + 1, std::to_string(i + 1), 18, {0, 0, 0});
      ibl::io::draw_text(pic, tx, ty, std::to_string(i + 1), 18, {1, 1, 0.2});
    }
  }
  return pic;
}

Image irradiance_comparison(const ibl::sphere::EnvMap& env, const ibl::lights::LightSet& set, int width) {
  int height = width / 2;
  ibl::sphere::Mapping ll(ibl::sphere::MappingKind::LatLong, width, height);
  std::vector<Vec3> normals(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) ll.to_direction(x + 0.5, y + 0.5, &normals[static_cast<size_t>(y) * width + x]);
  auto gt = ibl::lights::irradiance_ground_truth(env, normals);
  auto est = ibl::lights::irradiance_from_lights(set.lights, normals);
  auto err = ibl::lights::relative_error_luminance(est, gt);
  Image a(width, height, 3), b(width, height, 3), e(width, height, 3);
  double maxy = 0;
  for (const auto& v : gt) maxy = std::max(maxy, ibl::luminance(v));
  double scale = maxy > 0 ? 1.0 / maxy : 1.0;  // the same linear exposure for both: brightest = white
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      size_t k = static_cast<size_t>(y) * width + x;
      a.set_rgb(x, y, gt[k] * scale);
      b.set_rgb(x, y, est[k] * scale);
      e.set_rgb(x, y, error_colour(err[k]));
    }
  int pad = 10, cap = 26;
  Image out(3 * width + 4 * pad, height + cap + 2 * pad + 24, 3, 0.07f);
  const Image* parts[3] = {&a, &b, &e};
  const char* names[3] = {"ground truth E(n)", "lights", "relative error"};
  for (int p = 0; p < 3; ++p) {
    int ox = pad + p * (width + pad), oy = pad + cap;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        Vec3 c = parts[p]->rgb(x, y);
        out.set_rgb(ox + x, oy + y, {std::min(1.0, c.x), std::min(1.0, c.y), std::min(1.0, c.z)});
      }
    std::string name = p == 1 ? fmt::format("{} ({} lights)", set.method, set.lights.size()) : names[p];
    ibl::io::draw_text(out, ox, pad + 16, name, 14, {1, 1, 1});
  }
  // Error legend under the third panel.
  int lx = pad + 2 * (width + pad), ly = pad + cap + height + 6;
  for (int x = 0; x < width; ++x) {
    Vec3 c = error_colour(0.5 * x / (width - 1));
    for (int y = 0; y < 8; ++y) out.set_rgb(lx + x, ly + y, c);
  }
  ibl::io::draw_text(out, lx, ly + 22, "0%", 12, {0.9, 0.9, 0.9});
  ibl::io::draw_text(out, lx + width - 40, ly + 22, ">50%", 12, {0.9, 0.9, 0.9});
  return out;
}

}  // namespace iblcli
