// iblkit info PROBE: size, mapping, channels, range and total power of a probe.
#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/error.h"
#include "iblkit/io/envmap_io.h"

namespace {

void setup(CLI::App& app) {
  auto* path = iblcli::app_owned<std::string>();
  app.add_option("probe", *path, "HDR probe image (or a folder of six cube faces)")->required();
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer("Example:\n  iblkit info /usr/share/blender/datafiles/studiolights/world/forest.exr");
  app.callback([path, &rd] {
    ibl::io::ReadReport rep;
    auto env = ibl::io::read_envmap(*path, rd, &rep);
    const auto& img = env.image;
    double lo = 1e300, hi = 0;
    for (size_t i = 0; i < img.size(); ++i) {
      lo = std::min<double>(lo, img.data()[i]);
      hi = std::max<double>(hi, img.data()[i]);
    }
    auto power = env.integral();
    nlohmann::json j = {{"file", *path},
                        {"width", img.width()},
                        {"height", img.height()},
                        {"channels", img.channels()},
                        {"format", rep.format},
                        {"mapping", ibl::sphere::mapping_name(env.mapping.kind())},
                        {"min", lo},
                        {"max", hi},
                        {"power", power},
                        {"sanitized", rep.sanitized}};
    iblcli::emit(j, [&] {
      fmt::print("file      {}\n", *path);
      fmt::print("size      {} x {}, {} channels ({})\n", img.width(), img.height(), img.channels(), rep.format);
      fmt::print("mapping   {}\n", ibl::sphere::mapping_name(env.mapping.kind()));
      fmt::print("range     {:.6g} .. {:.6g}\n", lo, hi);
      fmt::print("∫L dω     ");
      for (double p : power) fmt::print("{:.6g} ", p);
      fmt::print("\n");
      if (rep.sanitized) fmt::print("sanitized {} values\n", rep.sanitized);
    });
  });
}

iblcli::Command reg("info", setup);

}  // namespace
