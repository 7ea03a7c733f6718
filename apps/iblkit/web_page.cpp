#include "web_page.h"

#include <sys/wait.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <thread>

#include <fmt/format.h>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/ilf/adaptive.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/ilf/threejs_grid.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/lights/gltf.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/sh/export.h"
#include "iblkit/sh/project.h"
#include "iblkit/sphere/envmap.h"
#include "static_server.h"

#ifndef IBLKIT_WEB_PAGE_DIR
#define IBLKIT_WEB_PAGE_DIR ""
#endif

namespace iblcli {

namespace fs = std::filesystem;
using namespace ibl;

std::string built_page_dir() {
  fs::path p = IBLKIT_WEB_PAGE_DIR;
  return !p.empty() && fs::exists(p / "viewer.js") && fs::exists(p / "three/build/three.module.js") ? p.string() : "";
}

namespace {

std::string stem(const std::string& path) { return fs::path(path).stem().string(); }

// Files and folders inside the output folder are written as themselves: a link planted there (to a
// file or a folder outside it) is replaced, never written through.
void copy_into(const fs::path& from, const fs::path& to) { copy_file_atomically(from.string(), to.string()); }
void real_folder(const fs::path& dir) {
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(dir, ec))) fs::remove(dir, ec);
  make_output_folders(dir.string());
}

}  // namespace

nlohmann::json write_web_page(const WebPageDesc& d) {
  std::string page = built_page_dir();
  if (page.empty())
    fail(ErrorKind::Unsupported,
         "the web viewer was not built (it needs node and npm at build time: scripts/install-deps, then rebuild)");
  if (d.specular.size() > d.probes.size())
    fail(ErrorKind::Value, "{} specular KTX2 files for {} probes: each --specular goes with the --probe of its rank",
         d.specular.size(), d.probes.size());
  if (d.probe_height < 8 || d.probe_height > 8192)
    fail(ErrorKind::Value, "probe height {} outside 8..8192", d.probe_height);
  fs::path out = d.out, data = out / "data";
  make_output_folders(out.string());
  real_folder(data);
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(page, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const fs::path to = out / fs::relative(it->path(), page);
    if (it->is_directory())
      real_folder(to);
    else
      copy_into(it->path(), to);
  }
  if (ec) fail(ErrorKind::Io, "cannot copy the viewer from {} to {} ({})", page, out.string(), ec.message());

  nlohmann::json m = {{"format", "iblkit.web/1"},
                      {"probes", nlohmann::json::array()},
                      {"lights", nlohmann::json::array()},
                      {"grids", nlohmann::json::array()}};
  for (size_t i = 0; i < d.probes.size(); ++i) {
    sphere::EnvMap env = io::read_envmap(d.probes[i]);
    std::string name = fmt::format("probe{}", i);
    // The SH of the probe as read (every mapping), the picture as a lat-long for three's EXRLoader.
    sh::Coeffs c = sh::project(env, 3);
    write_file_atomically((data / (name + "_sh.json")).string(), sh::export_text(c, sh::ExportFormat::ThreeJs));
    sphere::Mapping ll(sphere::MappingKind::LatLong, 2 * d.probe_height, d.probe_height);
    Image img = env.mapping.kind() == sphere::MappingKind::LatLong && env.image.height() == d.probe_height
                    ? env.image
                    : sphere::resample(env, ll);
    io::write_image((data / (name + ".exr")).string(), img);
    nlohmann::json p = {{"name", stem(d.probes[i])},
                        {"source", d.probes[i]},
                        {"image", "data/" + name + ".exr"},
                        {"sh", "data/" + name + "_sh.json"}};
    if (i < d.specular.size()) {
      copy_into(d.specular[i], data / (name + ".ktx2"));
      p["specular"] = "data/" + name + ".ktx2";
    }
    m["probes"].push_back(p);
  }
  for (size_t i = 0; i < d.lights.size(); ++i) {
    std::string file = fmt::format("lights{}.gltf", i);
    if (fs::path(d.lights[i]).extension() == ".gltf")
      copy_into(d.lights[i], data / file);
    else
      lights::write_gltf((data / file).string(), lights::read_lights(d.lights[i]));
    m["lights"].push_back({{"name", stem(d.lights[i])}, {"source", d.lights[i]}, {"gltf", "data/" + file}});
  }
  for (size_t i = 0; i < d.grids.size(); ++i) {
    std::string name = fmt::format("grid{}", i);
    ilf::write_threejs_grid(ilf::read_dense(d.grids[i]), data.string(), name);  // .shtree: resampled to dense
    m["grids"].push_back({{"name", stem(d.grids[i])}, {"source", d.grids[i]}, {"grid", "data/" + name + ".json"}});
  }
  write_json_file((out / "iblkit-web.json").string(), m, 2);
  return m;
}

std::string find_chromium() {
  if (fs::exists("/usr/bin/chromium")) return "/usr/bin/chromium";
  const char* path = std::getenv("PATH");
  std::string ps = path ? path : "";
  for (size_t i = 0; i <= ps.size();) {
    size_t j = ps.find(':', i);
    if (j == std::string::npos) j = ps.size();
    for (const char* n : {"chromium", "chromium-browser"}) {
      fs::path c = fs::path(ps.substr(i, j - i)) / n;
      if (!ps.substr(i, j - i).empty() && fs::exists(c)) return c.string();
    }
    i = j + 1;
  }
  return "";
}

namespace {
// Single-quoted for /bin/sh.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace

int screenshot_page(const std::string& dir, const std::string& query, const std::string& png, int width, int height) {
  std::string chromium = find_chromium();
  if (chromium.empty())
    fail(ErrorKind::Unsupported, "no Chromium found (scripts/install-deps installs Debian's chromium)");
  std::atomic<bool> stop{false};
  std::promise<int> ready;
  auto port_future = ready.get_future();
  std::thread server([&] {
    try {
      serve_static({dir, "127.0.0.1", 0}, &stop, [&](int port) { ready.set_value(port); });
    } catch (...) {
      ready.set_exception(std::current_exception());
    }
  });
  int status = -1;
  try {
    int port = port_future.get();
    // The page sets its size from the URL; the virtual time budget lets its module scripts, fetches
    // and the first frame finish before Chromium takes the picture.
    std::string url = fmt::format("http://127.0.0.1:{}/index.html?ui=0&size={}x{}&{}", port, width, height, query);
    std::string cmd = fmt::format(
        "{} --headless --no-sandbox --disable-gpu-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader "
        "--hide-scrollbars "
        "--window-size={},{} --virtual-time-budget=20000 --screenshot={} {} >/dev/null 2>&1",
        shell_quote(chromium), width, height, shell_quote(fs::absolute(png).string()), shell_quote(url));
    int rc = std::system(cmd.c_str());
    status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  } catch (...) {
    stop = true;
    server.join();
    throw;
  }
  stop = true;
  server.join();
  return status;
}

}  // namespace iblcli
