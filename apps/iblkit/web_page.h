// The web viewer's folder (docs/web.md): the page built into build/web (web/viewer and the three.js
// files it imports) copied into OUT, and the data it opens written beside it under OUT/data, listed
// in OUT/iblkit-web.json. `iblkit web` and the demo's web step write it; `iblkit serve OUT` serves it.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace iblcli {

struct WebPageDesc {
  std::string out;                    // the folder to write
  std::vector<std::string> probes;    // HDR probes (any mapping): lat-long EXR + three.js SH each
  std::vector<std::string> specular;  // specular KTX2 (iblkit specular), paired with probes in order
  std::vector<std::string> lights;    // light sets: iblkit.lights/1 JSON or glTF (KHR_lights_punctual)
  std::vector<std::string> grids;     // SH grids (.shgrid) -> three.js LightProbeGridWebGL atlases
  int probe_height = 512;             // the lat-long copy's height (width twice): the page's background
};

// The folder the build assembled (IBLKIT_WEB_PAGE_DIR), or "" when it was not built (no npm).
std::string built_page_dir();

// Writes the folder; returns the manifest. Throws ibl::Error when the page was not built, or on any
// input that cannot be read.
nlohmann::json write_web_page(const WebPageDesc& d);

// Where Chromium is (/usr/bin/chromium, chromium or chromium-browser on PATH), or "".
std::string find_chromium();

// Serves `dir` on a free loopback port and has headless Chromium screenshot `query` (URL parameters
// of the viewer, docs/web.md) into png at width × height. Returns Chromium's exit status.
int screenshot_page(const std::string& dir, const std::string& query, const std::string& png, int width, int height);

}  // namespace iblcli
