#include "iblkit/nearfield/dataset.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/io/image_io.h"
#include "iblkit/nearfield/basis.h"

namespace ibl::nearfield {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {
constexpr EnumName<Basis> kBasisNames[] = {{Basis::Bilinear, "bilinear"}, {Basis::Biquadratic, "biquadratic"}};
}  // namespace

const char* basis_name(Basis b) { return name_of(kBasisNames, b); }
Basis parse_basis(const std::string& name, const std::string& what) {
  return parse_enum(kBasisNames, name, "basis", what);
}

Image Dataset::measurement(int i, int j) const {
  const size_t k = static_cast<size_t>(j * nx + i);
  const Image& p = positive.at(k);
  const Image& n = negative.at(k);
  Image e(p.width(), p.height(), 3);
  for (int y = 0; y < p.height(); ++y)
    for (int x = 0; x < p.width(); ++x) e.set_rgb(x, y, (p.rgb(x, y) - n.rgb(x, y)) * filter_gain);
  return e;
}

void Dataset::validate(const std::string& what) const {
  if (nx < 1 || ny < 1) fail(ErrorKind::Value, "{}: grid {}x{} has no filter positions", what, nx, ny);
  if (!(spacing > 0) || !std::isfinite(spacing))
    fail(ErrorKind::Value, "{}: spacing {} must be positive", what, spacing);
  const double want = 2 * dual_half_width(basis) * spacing;
  if (!(std::abs(filter_width - want) <= 1e-6 * want))  // written with 6+ significant digits
    fail(ErrorKind::Value, "{}: filter_width {} m does not match the {} basis at spacing {} m (its dual is {} m wide)",
         what, filter_width, basis_name(basis), spacing, want);
  if (!(distance > 0) || !std::isfinite(distance))
    fail(ErrorKind::Value, "{}: distance {} must be positive", what, distance);
  if (!(m_max.x > m_min.x) || !(m_max.y > m_min.y))
    fail(ErrorKind::Value, "{}: M extent [{}, {}]x[{}, {}] is empty", what, m_min.x, m_max.x, m_min.y, m_max.y);
  if (!(filter_gain > 0)) fail(ErrorKind::Value, "{}: filter_gain {} must be positive", what, filter_gain);
  const size_t n = static_cast<size_t>(count());
  if (positive.size() != n || negative.size() != n)
    fail(ErrorKind::Value, "{}: {} positive and {} negative images for {}x{} filter positions", what, positive.size(),
         negative.size(), nx, ny);
  const int w = positive[0].width(), h = positive[0].height();
  for (size_t k = 0; k < n; ++k)
    for (int part = 0; part < 2; ++part) {
      const Image& img = part ? negative[k] : positive[k];
      const int i = static_cast<int>(k) % nx, j = static_cast<int>(k) / nx;
      const char* pn = part ? "negative" : "positive";
      if (img.empty())
        fail(ErrorKind::Value, "{}: the {} image of filter position ({}, {}) is missing", what, pn, i, j);
      if (img.width() != w || img.height() != h || img.channels() < 3)
        fail(ErrorKind::Value, "{}: the {} image of ({}, {}) is {}x{}x{}, the first is {}x{}x3", what, pn, i, j,
             img.width(), img.height(), img.channels(), w, h);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int c = 0; c < 3; ++c) {
            const float v = img.at(x, y, c);
            if (!std::isfinite(v) || v < 0)
              fail(ErrorKind::Value,
                   "{}: the {} image of ({}, {}) has pixel ({}, {}) channel {} = {} (measurements are non-negative "
                   "irradiances)",
                   what, pn, i, j, x, y, c, v);
          }
    }
}

namespace {

double number(const json& j, const char* key, const std::string& what) { return req_field<double>(j, what, key); }

Vec2 vec2(const json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 2 || !j[0].is_number() || !j[1].is_number())
    fail(ErrorKind::Format, "{}: expected [x, y]", what);
  return {j[0].get<double>(), j[1].get<double>()};
}

}  // namespace

Dataset read_dataset(const std::string& path) {
  const json j = read_json_file(path);
  require_format(j, path, "iblkit.nearfield/1");
  Dataset ds;
  ds.name = opt_field(j, path, "name", fs::path(path).stem().string());
  ds.luminaire = opt_field(j, path, "luminaire", "");
  ds.basis = parse_basis(opt_field(j, path, "basis", ""), path + ": basis");
  ds.spacing = number(j, "spacing", path);
  ds.filter_width = number(j, "filter_width", path);
  ds.distance = number(j, "distance", path);
  if (!j.contains("grid") || !j["grid"].is_array() || j["grid"].size() != 2 || !j["grid"][0].is_number_integer() ||
      !j["grid"][1].is_number_integer())
    fail(ErrorKind::Format, "{}: field \"grid\" must be [nx, ny] of whole numbers, got {}", path,
         j.contains("grid") ? j["grid"].dump() : "nothing");
  const int64_t nx = json_integer<int64_t>(j["grid"][0], path, "grid"),
                ny = json_integer<int64_t>(j["grid"][1], path, "grid");
  if (nx < 1 || ny < 1 || nx > 256 || ny > 256)
    fail(ErrorKind::Value, "{}: field \"grid\": {}x{} out of range (1..256)", path, nx, ny);
  ds.nx = static_cast<int>(nx);
  ds.ny = static_cast<int>(ny);
  if (!j.contains("m_extent") || !j["m_extent"].is_object())
    fail(ErrorKind::Format, "{}: 'm_extent' {{min, max}} missing", path);
  ds.m_min = vec2(j["m_extent"].value("min", json()), path + ": m_extent.min");
  ds.m_max = vec2(j["m_extent"].value("max", json()), path + ": m_extent.max");
  ds.m_basis = parse_basis(opt_field(j, path, "m_basis", "bilinear"), path + ": m_basis");
  ds.filter_gain = opt_field(j, path, "filter_gain", 1.0);
  if (!j.contains("measurements") || !j["measurements"].is_array())
    fail(ErrorKind::Format, "{}: 'measurements' array missing", path);
  const size_t n = static_cast<size_t>(ds.count());
  ds.positive.assign(n, Image());
  ds.negative.assign(n, Image());
  std::vector<bool> seen(n, false);
  const fs::path dir = fs::path(path).parent_path();
  size_t index = 0;
  for (const auto& m : j["measurements"]) {
    const std::string where = fmt::format("{}: measurements[{}]", path, index++);
    const int64_t i64 = req_field<int64_t>(m, where, "i"), j64 = req_field<int64_t>(m, where, "j");
    if (i64 < 0 || i64 >= ds.nx || j64 < 0 || j64 >= ds.ny)
      fail(ErrorKind::Value, "{}: measurement ({}, {}) is outside the {}x{} grid", path, i64, j64, ds.nx, ds.ny);
    const int i = static_cast<int>(i64), jj = static_cast<int>(j64);
    if (i < 0 || i >= ds.nx || jj < 0 || jj >= ds.ny)
      fail(ErrorKind::Value, "{}: measurement ({}, {}) is outside the {}x{} grid", path, i, jj, ds.nx, ds.ny);
    const size_t k = static_cast<size_t>(jj * ds.nx + i);
    if (seen[k]) fail(ErrorKind::Value, "{}: filter position ({}, {}) is listed twice", path, i, jj);
    seen[k] = true;
    for (int part = 0; part < 2; ++part) {
      const char* key = part ? "negative" : "positive";
      const std::string file = req_field<std::string>(m, where, key);
      io::ReadDesc rd;
      rd.max_channels = 3;
      Image img = io::read_image((dir / file).string(), rd);
      if (img.channels() < 3) img = img.with_channels(3);
      (part ? ds.negative : ds.positive)[k] = std::move(img);
    }
  }
  for (size_t k = 0; k < n; ++k)
    if (!seen[k])
      fail(ErrorKind::Value, "{}: filter position ({}, {}) of the {}x{} grid has no measurement", path, k % ds.nx,
           k / ds.nx, ds.nx, ds.ny);
  ds.validate(path);
  return ds;
}

void write_dataset(const std::string& path, const Dataset& ds) {
  ds.validate(path);
  const fs::path dir = fs::path(path).parent_path();
  // Images go to STEM_images/ so that two manifests in one folder never share (and overwrite) images.
  const std::string sub = fs::path(path).stem().string() + "_images";
  ibl::make_output_folders((dir / sub).string());
  json ms = json::array();
  for (int j = 0; j < ds.ny; ++j)
    for (int i = 0; i < ds.nx; ++i) {
      const size_t k = static_cast<size_t>(j * ds.nx + i);
      std::string pos = fmt::format("{}/ij_{}_{}_pos.exr", sub, i, j),
                  neg = fmt::format("{}/ij_{}_{}_neg.exr", sub, i, j);
      io::write_image((dir / pos).string(), ds.positive[k]);
      io::write_image((dir / neg).string(), ds.negative[k]);
      ms.push_back({{"i", i}, {"j", j}, {"positive", pos}, {"negative", neg}});
    }
  json j = {{"format", "iblkit.nearfield/1"},
            {"name", ds.name},
            {"luminaire", ds.luminaire},
            {"basis", basis_name(ds.basis)},
            {"spacing", ds.spacing},
            {"filter_width", ds.filter_width},
            {"grid", {ds.nx, ds.ny}},
            {"distance", ds.distance},
            {"m_extent", {{"min", {ds.m_min.x, ds.m_min.y}}, {"max", {ds.m_max.x, ds.m_max.y}}}},
            {"m_basis", basis_name(ds.m_basis)},
            {"filter_gain", ds.filter_gain},
            {"measurements", ms}};
  write_json_file(path, j);
}

}  // namespace ibl::nearfield
