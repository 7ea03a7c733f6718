#ifdef IBLKIT_HAVE_GEOMETRY
#include "fusion_pictures.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "iblkit/io/draw.h"
#include "iblkit/io/tonemap.h"
#include "lights_pictures.h"

namespace iblcli {

using ibl::Image;
using ibl::Vec3;
using ibl::fusion::PixelStatus;

Image coverage_picture(const ibl::fusion::LocalMap& map, int probes) {
  const Image& r = map.radiance.image;
  Image pic(r.width(), r.height(), 3);
  for (int y = 0; y < r.height(); ++y)
    for (int x = 0; x < r.width(); ++x) {
      PixelStatus s = map.status[static_cast<size_t>(y) * r.width() + x];
      Vec3 c;
      if (s == PixelStatus::Fused)
        c = Vec3{0.1, 1.0, 0.25} *
            (0.3 + 0.7 * std::min(1.0, static_cast<double>(map.coverage.at(x, y, 0)) / std::max(1, probes)));
      else if (s == PixelStatus::LeftProxy)
        c = {0.15, 0.35, 1.0};
      else if (s == PixelStatus::Unseen)
        c = {1.0, 0.12, 0.08};
      pic.set_rgb(x, y, c);
    }
  return pic;
}

Image tone(const Image& img, double scale) {
  ibl::io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(std::max(scale, 1e-30));
  return ibl::io::tonemap(img, td).with_channels(3);
}

Image fused_sheet(const ibl::fusion::LocalMap& ll, int probes, const ibl::lights::LightSet* lights,
                  const std::string& title) {
  std::vector<std::pair<std::string, Image>> pics;
  pics.push_back({"fused map", ibl::io::tonemap(ll.radiance.image).with_channels(3)});
  pics.push_back({fmt::format("coverage: fused {:.1f}% / left {:.1f}% / unseen {:.1f}%", 100 * ll.stats.fused,
                              100 * ll.stats.left_proxy, 100 * ll.stats.unseen),
                  coverage_picture(ll, probes)});
  if (lights) {
    int positioned = 0;
    for (const auto& l : lights->lights) positioned += l.position.has_value();
    pics.push_back({fmt::format("{} lights, {} localised", lights->lights.size(), positioned),
                    light_overlay(ll.radiance, *lights, 512, 8)});
  }
  return ibl::io::contact_sheet(pics, static_cast<int>(pics.size()), 512, 256, title);
}

}  // namespace iblcli
#endif  // IBLKIT_HAVE_GEOMETRY
