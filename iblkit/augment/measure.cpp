#include "iblkit/augment/measure.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "iblkit/core/error.h"

namespace ibl::augment {

namespace {
double l1(Vec3 a) { return std::abs(a.x) + std::abs(a.y) + std::abs(a.z); }

// Luminance averaged over the (2r+1)² box around each pixel (clamped at the borders): which pixels the
// object darkens is decided on these, so that a Monte Carlo truth's grain does not pass for a shadow.
constexpr int kClassifyRadius = 1;
std::vector<double> box_luminance(const Image& im) {
  const int W = im.width(), H = im.height();
  std::vector<double> out(static_cast<size_t>(W) * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double s = 0;
      int n = 0;
      for (int dy = -kClassifyRadius; dy <= kClassifyRadius; ++dy)
        for (int dx = -kClassifyRadius; dx <= kClassifyRadius; ++dx) {
          int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
          s += luminance(im.rgb(xx, yy));
          ++n;
        }
      out[static_cast<size_t>(y) * W + x] = s / n;
    }
  return out;
}
}  // namespace

CompositeErrors measure(const Image& photo, const Image& comp, const Image& truth, const Image& mask, double tau) {
  const int W = photo.width(), H = photo.height();
  for (const Image* im : {&comp, &truth, &mask})
    if (im->width() != W || im->height() != H)
      fail(ErrorKind::Value, "measure: images of {}x{} and {}x{} differ in size", W, H, im->width(), im->height());
  double on = 0, od = 0, sn = 0, sd = 0, un = 0, ud = 0, rel = 0;
  const std::vector<double> bp = box_luminance(photo), bt = box_luminance(truth);
  CompositeErrors e;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      Vec3 p = photo.rgb(x, y), c = comp.rgb(x, y), t = truth.rgb(x, y);
      double m = mask.at(x, y, 0);
      if (m >= 1) {
        on += l1(c - t);
        od += l1(t);
        ++e.object_pixels;
        continue;
      }
      if (m > 0) continue;  // object edges: neither
      double yp = bp[static_cast<size_t>(y) * W + x], yt = bt[static_cast<size_t>(y) * W + x];
      if (yp - yt > tau * yp) {
        sn += l1(c - t);
        sd += l1(p - t);
        rel += (yp - yt) / yp;
        ++e.shadow_pixels;
      } else if (yt - yp > tau * yp) {
        ++e.brightened_pixels;
      } else {
        un += l1(c - t);
        ud += l1(t);
        ++e.unchanged_pixels;
      }
    }
  e.object = od > 0 ? on / od : 0;
  e.shadow = sd > 0 ? sn / sd : 0;
  e.unchanged = ud > 0 ? un / ud : 0;
  e.shadow_signal = e.shadow_pixels > 0 ? rel / e.shadow_pixels : 0;
  return e;
}

Image error_picture(const Image& comp, const Image& truth) {
  Image out(comp.width(), comp.height(), 3);
  for (int y = 0; y < comp.height(); ++y)
    for (int x = 0; x < comp.width(); ++x) {
      double t = luminance(truth.rgb(x, y)), d = t > 0 ? (luminance(comp.rgb(x, y)) - t) / t : 0;
      out.set_rgb(x, y, {std::max(0.0, d), std::max(0.0, -d), 0});
    }
  return out;
}

TruthErrors measure_against(const Image& photo, const Image& comp, const std::vector<Image>& truths, const Image& mask,
                            double tau) {
  if (truths.empty()) fail(ErrorKind::Value, "measure: no truth");
  const Image& t1 = truths.front();
  TruthErrors r;
  r.mean = Image(t1.width(), t1.height(), 3);
  for (const Image& t : truths) {
    if (t.width() != t1.width() || t.height() != t1.height() || t.channels() < 3)
      fail(ErrorKind::Value, "measure: truths of {}x{} and {}x{} (RGB) differ", t1.width(), t1.height(), t.width(),
           t.height());
    for (int y = 0; y < t1.height(); ++y)
      for (int x = 0; x < t1.width(); ++x)
        r.mean.set_rgb(x, y, r.mean.rgb(x, y) + t.rgb(x, y) / static_cast<double>(truths.size()));
  }
  r.errors = measure(photo, comp, r.mean, mask, tau);
  if (truths.size() > 1) {
    r.noise = measure(photo, t1, r.mean, mask, tau);
    const double s = 1 / std::sqrt(static_cast<double>(truths.size() - 1));
    r.noise.object *= s;
    r.noise.shadow *= s;
    r.noise.unchanged *= s;
  }
  return r;
}

}  // namespace ibl::augment
