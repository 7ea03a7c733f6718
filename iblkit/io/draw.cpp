#include "iblkit/io/draw.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "iblkit/io/codecs.h"

namespace ibl::io {

namespace {
const char* font_path() {
  static const char* candidates[] = {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                                     "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf"};
  for (const char* c : candidates)
    if (std::filesystem::exists(c)) return c;
  return nullptr;
}

void blend(Image& img, int x, int y, Vec3 rgb, double a) {
  if (x < 0 || y < 0 || x >= img.width() || y >= img.height() || a <= 0) return;
  a = std::min(a, 1.0);
  Vec3 c = img.rgb(x, y);
  img.set_rgb(x, y, c * (1 - a) + rgb * a);
}
}  // namespace

bool draw_text(Image& img, int x, int y, const std::string& text, int size, Vec3 rgb) {
  const char* font = font_path();
  if (!font || img.channels() < 3) return false;
  return detail::oiio_codec.get().draw_text(img, x, y, text, size, font, rgb);  // OpenImageIO's FreeType renderer
}

void draw_line(Image& img, double x0, double y0, double x1, double y1, Vec3 rgb, double width) {
  double len = std::hypot(x1 - x0, y1 - y0);
  int steps = std::max(1, static_cast<int>(std::ceil(len * 2)));
  double r = 0.5 * width;
  for (int i = 0; i <= steps; ++i) {
    double t = static_cast<double>(i) / steps, x = x0 + t * (x1 - x0), y = y0 + t * (y1 - y0);
    // Splat a small anti-aliased disc of radius r + ½ at each half-pixel step.
    int xa = static_cast<int>(std::floor(x - r - 1)), xb = static_cast<int>(std::ceil(x + r + 1));
    int ya = static_cast<int>(std::floor(y - r - 1)), yb = static_cast<int>(std::ceil(y + r + 1));
    for (int py = ya; py <= yb; ++py)
      for (int px = xa; px <= xb; ++px) {
        double d = std::hypot(px + 0.5 - x, py + 0.5 - y);
        double a = std::clamp(r + 0.5 - d, 0.0, 1.0);
        if (a > 0) {
          if (px < 0 || py < 0 || px >= img.width() || py >= img.height()) continue;
          // max-blend along the line so overlapping splats don't darken/brighten unevenly
          Vec3 c = img.rgb(px, py);
          Vec3 target = c * (1 - a) + rgb * a;
          double dc = length(target - rgb), dn = length(c - rgb);
          if (dc < dn) img.set_rgb(px, py, target);
        }
      }
  }
}

void draw_disc(Image& img, double cx, double cy, double r, Vec3 rgb) {
  int xa = static_cast<int>(std::floor(cx - r - 1)), xb = static_cast<int>(std::ceil(cx + r + 1));
  int ya = static_cast<int>(std::floor(cy - r - 1)), yb = static_cast<int>(std::ceil(cy + r + 1));
  for (int y = ya; y <= yb; ++y)
    for (int x = xa; x <= xb; ++x) blend(img, x, y, rgb, r + 0.5 - std::hypot(x + 0.5 - cx, y + 0.5 - cy));
}

void fill_rect(Image& img, int x0, int y0, int x1, int y1, Vec3 rgb) {
  for (int y = std::max(0, y0); y < std::min(img.height(), y1); ++y)
    for (int x = std::max(0, x0); x < std::min(img.width(), x1); ++x) img.set_rgb(x, y, rgb);
}

Image resize(const Image& img, int width, int height) {
  Image out(width, height, img.channels());
  double sx = static_cast<double>(img.width()) / width, sy = static_cast<double>(img.height()) / height;
  ImageView v = img.view();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float* o = out.pixel(x, y);
      if (sx <= 1 && sy <= 1) {
        v.bilinear((x + 0.5) * sx, (y + 0.5) * sy, Wrap::Clamp, o);
        continue;
      }
      int x0 = static_cast<int>(x * sx), x1 = std::max(x0 + 1, static_cast<int>((x + 1) * sx));
      int y0 = static_cast<int>(y * sy), y1 = std::max(y0 + 1, static_cast<int>((y + 1) * sy));
      x1 = std::min(x1, img.width());
      y1 = std::min(y1, img.height());
      for (int c = 0; c < img.channels(); ++c) {
        double s = 0;
        for (int yy = y0; yy < y1; ++yy)
          for (int xx = x0; xx < x1; ++xx) s += img.at(xx, yy, c);
        o[c] = static_cast<float>(s / ((x1 - x0) * (y1 - y0)));
      }
    }
  return out;
}

Image contact_sheet(const std::vector<std::pair<std::string, Image>>& pictures, int columns, int cell_width,
                    int cell_height, const std::string& title) {
  constexpr int kPad = 8, kCaption = 22, kTitle = 34;
  int n = static_cast<int>(pictures.size());
  columns = std::max(1, std::min(columns, std::max(1, n)));
  int rows = (n + columns - 1) / columns;
  int top = title.empty() ? 0 : kTitle;
  int W = columns * (cell_width + kPad) + kPad, H = top + rows * (cell_height + kCaption + kPad) + kPad;
  Image sheet(W, H, 3, 0.08f);
  if (!title.empty()) draw_text(sheet, kPad, 24, title, 20, {1, 1, 1});
  for (int i = 0; i < n; ++i) {
    const Image& pic = pictures[i].second;
    int cx = kPad + (i % columns) * (cell_width + kPad),
        cy = top + kPad + (i / columns) * (cell_height + kCaption + kPad);
    double s = std::min(static_cast<double>(cell_width) / pic.width(), static_cast<double>(cell_height) / pic.height());
    int w = std::max(1, static_cast<int>(pic.width() * s)), h = std::max(1, static_cast<int>(pic.height() * s));
    Image small = resize(pic.channels() >= 3 ? pic : pic.with_channels(3), w, h);
    int ox = cx + (cell_width - w) / 2, oy = cy + (cell_height - h) / 2;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) sheet.set_rgb(ox + x, oy + y, small.rgb(x, y));
    draw_text(sheet, cx, cy + cell_height + 16, pictures[i].first, 13, {0.9, 0.9, 0.9});
  }
  return sheet;
}

}  // namespace ibl::io
