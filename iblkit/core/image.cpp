#include "iblkit/core/image.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"

#include <new>

namespace ibl {

Image::Image(int width, int height, int channels, float fill) : width_(width), height_(height), channels_(channels) {
  if (width < 0 || height < 0 || channels < 1 || channels > 64)
    fail(ErrorKind::Value, "image size {}x{}x{} is invalid", width, height, channels);
  require_allocation(fmt::format("an image of {}x{} pixels, {} channels,", width, height, channels),
                     double(width) * height * channels, sizeof(float), "choose a smaller image size");
  try {
    data_.assign(static_cast<size_t>(width) * height * channels, fill);
  } catch (const std::bad_alloc&) {
    fail(ErrorKind::Value,
         "out of memory: an image of {}x{} pixels, {} channels, needs {:.3g} GB more than this process can get (its "
         "memory limit or the machine's); choose a smaller image size",
         width, height, channels, double(width) * height * channels * sizeof(float) / 1e9);
  }
}

Vec3 Image::rgb(int x, int y) const {
  const float* p = pixel(x, y);
  return channels_ >= 3 ? Vec3{p[0], p[1], p[2]} : Vec3{p[0], p[0], p[0]};
}

void Image::set_rgb(int x, int y, Vec3 v) {
  float* p = pixel(x, y);
  if (channels_ >= 3) {
    p[0] = static_cast<float>(v.x);
    p[1] = static_cast<float>(v.y);
    p[2] = static_cast<float>(v.z);
  } else {
    p[0] = static_cast<float>(luminance(v));
  }
}

ImageView Image::view() const {
  return {data_.data(), width_, height_, channels_, static_cast<ptrdiff_t>(width_) * channels_};
}

Image Image::crop(int x0, int y0, int w, int h) const {
  if (x0 < 0 || y0 < 0 || w < 0 || h < 0 || x0 + w > width_ || y0 + h > height_)
    fail(ErrorKind::Value, "crop {}x{}+{}+{} is outside the {}x{} image", w, h, x0, y0, width_, height_);
  Image out(w, h, channels_);
  for (int y = 0; y < h; ++y) std::copy_n(pixel(x0, y0 + y), static_cast<size_t>(w) * channels_, out.pixel(0, y));
  return out;
}

Image Image::with_channels(int channels) const {
  Image out(width_, height_, channels);
  for (size_t i = 0; i < pixel_count(); ++i) {
    const float* s = data_.data() + i * channels_;
    float* d = out.data() + i * channels;
    for (int c = 0; c < channels; ++c) {
      if (channels_ == 1 && c < 3)
        d[c] = s[0];
      else if (c < channels_)
        d[c] = s[c];
      else
        d[c] = (c == 3) ? 1.0f : 0.0f;
    }
  }
  return out;
}

Vec3 ImageView::rgb(int x, int y) const {
  const float* p = pixel(x, y);
  return channels_ >= 3 ? Vec3{p[0], p[1], p[2]} : Vec3{p[0], p[0], p[0]};
}

namespace {
// Resolves integer coordinate i against size n; returns -1 for "black".
inline int resolve(int i, int n, bool repeat, bool black) {
  if (i >= 0 && i < n) return i;
  if (black) return -1;
  if (repeat) {
    i %= n;
    return i < 0 ? i + n : i;
  }
  return i < 0 ? 0 : n - 1;
}
}  // namespace

void ImageView::bilinear(double px, double py, Wrap wrap, float* out) const {
  double fx = px - 0.5, fy = py - 0.5;
  double x0f = std::floor(fx), y0f = std::floor(fy);
  float tx = static_cast<float>(fx - x0f), ty = static_cast<float>(fy - y0f);
  int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
  bool rep_x = wrap == Wrap::Repeat || wrap == Wrap::LatLong;
  bool rep_y = wrap == Wrap::Repeat;
  bool black = wrap == Wrap::Black;
  int xa = resolve(x0, width_, rep_x, black), xb = resolve(x0 + 1, width_, rep_x, black);
  int ya = resolve(y0, height_, rep_y, black), yb = resolve(y0 + 1, height_, rep_y, black);
  float w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
  for (int c = 0; c < channels_; ++c) out[c] = 0.0f;
  auto add = [&](int x, int y, float w) {
    if (x < 0 || y < 0 || w == 0.0f) return;
    const float* p = pixel(x, y);
    for (int c = 0; c < channels_; ++c) out[c] += w * p[c];
  };
  add(xa, ya, w00);
  add(xb, ya, w10);
  add(xa, yb, w01);
  add(xb, yb, w11);
}

Vec3 ImageView::sample_rgb_uv(double u, double v, Wrap wrap) const {
  float buf[64];
  sample_uv(u, v, wrap, buf);
  return channels_ >= 3 ? Vec3{buf[0], buf[1], buf[2]} : Vec3{buf[0], buf[0], buf[0]};
}

double channel_sum(const Image& img, int c) {
  double s = 0;
  for (size_t i = 0; i < img.pixel_count(); ++i) s += img.data()[i * img.channels() + c];
  return s;
}

}  // namespace ibl
