// Image: float pixels, any channel count, row-major, interleaved (pixel (x,y) channel c at
// data[(y*width + x)*channels + c]); y = 0 is the top row. ImageView is a cheap non-owning view.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "iblkit/core/vec.h"

namespace ibl {

// How a sampler treats coordinates outside [0,1).
enum class Wrap {
  Clamp,    // repeat the edge pixel
  Repeat,   // tile in both axes
  LatLong,  // repeat in u; clamp in v (an equirectangular image: seamless at u = 0/1)
  Black,    // zero outside
};

class ImageView;

class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels, float fill = 0.0f);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  size_t pixel_count() const { return static_cast<size_t>(width_) * height_; }
  size_t size() const { return pixel_count() * channels_; }

  float* data() { return data_.data(); }
  const float* data() const { return data_.data(); }
  float* pixel(int x, int y) { return data_.data() + (static_cast<size_t>(y) * width_ + x) * channels_; }
  const float* pixel(int x, int y) const { return data_.data() + (static_cast<size_t>(y) * width_ + x) * channels_; }
  float& at(int x, int y, int c) { return pixel(x, y)[c]; }
  float at(int x, int y, int c) const { return pixel(x, y)[c]; }
  // RGB of a pixel (grey images repeat channel 0; extra channels ignored).
  Vec3 rgb(int x, int y) const;
  void set_rgb(int x, int y, Vec3 v);

  ImageView view() const;
  // A copy of the rectangle [x0, x0+w) x [y0, y0+h).
  Image crop(int x0, int y0, int w, int h) const;
  // A copy with `channels` channels: drops extra ones; grey -> RGB repeats; missing alpha = 1.
  Image with_channels(int channels) const;

 private:
  int width_ = 0, height_ = 0, channels_ = 0;
  std::vector<float> data_;
};

// Non-owning view of a rectangle of an image (or of any float buffer with a row stride).
class ImageView {
 public:
  ImageView() = default;
  ImageView(const float* data, int width, int height, int channels, ptrdiff_t row_stride_floats)
      : data_(data), width_(width), height_(height), channels_(channels), stride_(row_stride_floats) {}
  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  const float* pixel(int x, int y) const { return data_ + y * stride_ + static_cast<ptrdiff_t>(x) * channels_; }
  ImageView sub(int x0, int y0, int w, int h) const { return {pixel(x0, y0), w, h, channels_, stride_}; }
  Vec3 rgb(int x, int y) const;

  // Bilinear sample at continuous pixel coordinates (px, py) in [0,width) x [0,height), pixel centres
  // at half-integers. out receives `channels()` floats.
  void bilinear(double px, double py, Wrap wrap, float* out) const;
  // Bilinear sample at normalised coordinates (u,v) in [0,1]^2.
  void sample_uv(double u, double v, Wrap wrap, float* out) const { bilinear(u * width_, v * height_, wrap, out); }
  Vec3 sample_rgb_uv(double u, double v, Wrap wrap) const;

 private:
  const float* data_ = nullptr;
  int width_ = 0, height_ = 0, channels_ = 0;
  ptrdiff_t stride_ = 0;
};

// Σ over pixels of channel c (double accumulation), a small helper used by tests and stats.
double channel_sum(const Image& img, int c);

}  // namespace ibl
