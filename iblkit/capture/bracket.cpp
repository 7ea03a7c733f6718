#include "iblkit/capture/bracket.h"

#include <cmath>
#include <cstdlib>

#include "iblkit/core/error.h"
#include "iblkit/io/photo.h"

namespace ibl::capture {

namespace {

double parse_number(const std::string& s, const std::string& all) {
  const auto slash = s.find('/');
  char* end = nullptr;
  if (slash != std::string::npos) {
    const std::string a = s.substr(0, slash), b = s.substr(slash + 1);
    const double num = std::strtod(a.c_str(), &end);
    if (a.empty() || *end) fail(ErrorKind::Value, "--exposures {}: '{}' is not a number or a fraction", all, s);
    const double den = std::strtod(b.c_str(), &end);
    if (b.empty() || *end || !(den != 0))
      fail(ErrorKind::Value, "--exposures {}: '{}' is not a number or a fraction", all, s);
    return num / den;
  }
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end) fail(ErrorKind::Value, "--exposures {}: '{}' is not a number or a fraction", all, s);
  return v;
}

}  // namespace

BracketDesc parse_exposures(const std::string& text) {
  BracketDesc d;
  std::string body = text;
  if (body.rfind("ev:", 0) == 0 || body.rfind("EV:", 0) == 0) d.ev = true, body = body.substr(3);
  size_t at = 0;
  while (at <= body.size()) {
    const size_t comma = body.find(',', at);
    const std::string item = body.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    const double v = parse_number(item, text);
    if (d.ev ? !(std::abs(v) <= 40) : !(std::isfinite(v) && v > 0 && v <= 1e6))
      fail(ErrorKind::Value, "--exposures {}: {} is {}", text, item,
           d.ev ? "not an EV step in [-40, 40]" : "not an exposure time in (0, 1e6] seconds");
    d.exposures.push_back(v);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return d;
}

Bracket read_bracket(const std::vector<std::string>& files, const BracketDesc& desc) {
  if (files.size() < 2)
    fail(ErrorKind::Value, "{}: one photograph only: an HDR merge needs a bracket of at least two exposures",
         files.empty() ? std::string("(no input)") : files[0]);
  if (!desc.exposures.empty() && desc.exposures.size() != files.size())
    fail(ErrorKind::Value, "--exposures gives {} values for {} photographs: give one per photograph, in order",
         desc.exposures.size(), files.size());
  Bracket b;
  b.exposure_source = desc.exposures.empty() ? "exif" : (desc.ev ? "ev" : "seconds");
  std::vector<io::Photo> photos;
  for (size_t i = 0; i < files.size(); ++i) {
    io::Photo p = io::read_photo(files[i]);
    const std::string camera = p.meta.make.empty() && p.meta.model.empty() ? "" : p.meta.make + " " + p.meta.model;
    if (i == 0) {
      b.bits = p.bits;
      b.camera = camera;
      b.linear = p.linear;
      b.raw = p.raw;
    } else {
      if (p.linear != b.linear)
        fail(ErrorKind::Value, "{}: {}, but {} is {}: merge raw files or developed photographs, not both", files[i],
             p.linear ? "a raw file" : "a developed photograph", files[0], b.linear ? "a raw file" : "not");
      if (p.bits != b.bits)
        fail(ErrorKind::Value, "{}: {}-bit, but {} is {}-bit: every photograph of a bracket must come from one camera",
             files[i], p.bits, files[0], b.bits);
      if (camera != b.camera)
        fail(ErrorKind::Value, "{}: taken with '{}', but {} with '{}': merge photographs of one camera only", files[i],
             camera, files[0], b.camera);
    }
    photos.push_back(std::move(p));
  }
  const bool any_iso = std::any_of(photos.begin(), photos.end(), [](const io::Photo& p) { return p.meta.iso > 0; });
  for (size_t i = 0; i < files.size(); ++i) {
    const io::PhotoMeta& m = photos[i].meta;
    const double N = m.f_number > 0 ? m.f_number : 1.0;
    const double iso = m.iso > 0 ? m.iso : 100.0;
    if (any_iso && !(m.iso > 0))
      fail(ErrorKind::Value, "{}: has no ISO in its Exif while {} has: give the exposures with --exposures", files[i],
           files[0]);
    double exposure;
    if (desc.exposures.empty()) {
      if (!(m.exposure_time > 0))
        fail(ErrorKind::Value,
             "{}: no exposure time in its Exif (ExposureTime): give every photograph's exposure with --exposures "
             "(seconds, e.g. 1/250,1/60,1/15, or EV steps, e.g. ev:-2,0,2)",
             files[i]);
      exposure = m.exposure_time * (iso / 100) / (N * N);
    } else if (desc.ev) {
      exposure = std::exp2(desc.exposures[i]);
    } else {
      exposure = desc.exposures[i] * (iso / 100) / (N * N);
    }
    b.frames.push_back({std::move(photos[i].codes), exposure, files[i]});
  }
  b.iso_assumed = !any_iso && b.exposure_source != "ev";
  return b;
}

nlohmann::json report_json(const MergeReport& r, const std::vector<Frame>& frames) {
  nlohmann::json fr = nlohmann::json::array();
  for (size_t j = 0; j < frames.size(); ++j)
    fr.push_back({{"file", frames[j].name},
                  {"exposure", frames[j].exposure},
                  {"shift", {r.shifts.empty() ? 0 : r.shifts[j][0], r.shifts.empty() ? 0 : r.shifts[j][1]}}});
  return {{"frames", fr},
          {"reference", r.reference},
          {"response", r.response.kind},
          {"pixels", r.pixels},
          {"well_exposed", r.well_exposed},
          {"saturated_everywhere", r.saturated_everywhere},
          {"black_everywhere", r.black_everywhere},
          {"dynamic_range_stops", r.dynamic_range_stops},
          {"luminance_range", {r.min_luminance, r.max_luminance}},
          {"noise", r.noise},
          {"gains", {r.gains.x, r.gains.y, r.gains.z}}};
}

}  // namespace ibl::capture
