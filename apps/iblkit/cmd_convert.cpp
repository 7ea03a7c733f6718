// iblkit convert IN OUT --mapping M [--size N]: any mapping to any other, any format.
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/sphere/envmap.h"

namespace {

namespace fs = std::filesystem;
using ibl::sphere::MappingKind;

// Output size from a "size" (height for latlong, face edge for cubes, diameter for discs).
ibl::sphere::Mapping output_mapping(MappingKind k, int size) {
  switch (k) {
    case MappingKind::LatLong:
      return {k, 2 * size, size};
    case MappingKind::CubeHCross:
      return {k, 4 * size, 3 * size};
    case MappingKind::CubeVCross:
      return {k, 3 * size, 4 * size};
    case MappingKind::CubeStrip:
      return {k, 6 * size, size};
    default:
      return {k, size, size};
  }
}

void setup(CLI::App& app) {
  struct Opts {
    std::string in, out, mapping = "latlong";
    int size = 0;
    bool half = false, faces = false;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("input", o->in, "input probe (image, or folder of six cube faces)")->required();
  app.add_option("output", o->out, "output image (.exr .hdr .pfm .tif .png), or a folder with --faces")->required();
  app.add_option("-m,--mapping", o->mapping,
                 "output mapping: latlong, mirrorball, angular, hcross, vcross, cubestrip, octahedral")
      ->capture_default_str();
  app.add_option("-s,--size", o->size,
                 "output size: latlong height, cube face edge, disc/octahedral diameter (default: keeps the "
                 "input's pixel count roughly)")
      ->check(CLI::Range(1, 16384));
  app.add_flag("--half", o->half, "write .exr as 16-bit half floats");
  app.add_flag("--faces", o->faces, "cube mappings: write six face images px..nz into the output folder");
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer(
      "Examples:\n  iblkit convert probe.exr probe_cross.exr --mapping hcross --size 256\n"
      "  iblkit convert ../shared/probes/debevec/grace_cube grace.exr --mapping latlong --size 512");
  app.callback([o, &rd] {
    std::error_code ec;  // the output would replace the probe it is made from: refuse
    if (std::filesystem::exists(o->out, ec) && std::filesystem::equivalent(o->in, o->out, ec))
      ibl::fail(ibl::ErrorKind::Value, "{}: the output is the input file; write the conversion to another path",
                o->out);
    ibl::io::ReadReport rep;
    auto src = ibl::io::read_envmap(o->in, rd, &rep);
    if (rep.sanitized) iblcli::info(fmt::format("sanitized {} NaN/Inf/negative values", rep.sanitized));
    MappingKind k = ibl::sphere::parse_mapping(o->mapping);
    int size = o->size;
    if (size == 0) {
      double pixels = static_cast<double>(src.image.width()) * src.image.height();
      double per = k == MappingKind::LatLong                                                                       ? 2
                   : (k == MappingKind::CubeHCross || k == MappingKind::CubeVCross || k == MappingKind::CubeStrip) ? 6
                                                                                                                   : 1;
      size = std::max(1, static_cast<int>(std::sqrt(pixels / per)));
    }
    auto dst = output_mapping(k, size);
    // the resampled image, the map's copy of it and its solid angles
    ibl::require_allocation(fmt::format("--size {}: a {} map of {}x{} pixels", size, ibl::sphere::mapping_name(k),
                                        dst.width(), dst.height()),
                            double(dst.width()) * dst.height(), 3 * 3 * sizeof(float) + sizeof(double),
                            "choose a smaller --size");
    ibl::sphere::ResampleDesc rs;
    rs.progress = iblcli::progress_bar();
    ibl::sphere::EnvMap out(ibl::sphere::resample(src, dst, rs), dst);
    iblcli::progress_done();
    if (o->faces) {
      ibl::io::write_cube_faces(o->out, out);
    } else {
      ibl::io::write_image(o->out, out.image, {o->half});
    }
    auto pin = src.integral(), pout = out.integral();
    double ratio = pin[0] > 0 ? pout[0] / pin[0] : 1.0;
    nlohmann::json j = {{"input", o->in},       {"output", o->out},       {"mapping", ibl::sphere::mapping_name(k)},
                        {"width", dst.width()}, {"height", dst.height()}, {"power_in", pin},
                        {"power_out", pout},    {"power_ratio", ratio}};
    iblcli::emit(j, [&] {
      fmt::print("wrote {} ({} {}x{}), power out/in = {:.5f}\n", o->out, ibl::sphere::mapping_name(k), dst.width(),
                 dst.height(), ratio);
    });
  });
}

iblcli::Command reg("convert", setup);

}  // namespace
