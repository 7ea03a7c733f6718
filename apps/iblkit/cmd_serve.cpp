// iblkit serve DIR: serve the web viewer folder that `iblkit demo` (DIR/web) or `iblkit web` writes,
// on a loopback address, so that a browser can open it (module scripts and fetch() need http://).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include <fmt/format.h>

#include "cli.h"
#include "static_server.h"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

void setup(CLI::App& app) {
  struct Opts {
    iblcli::StaticServerDesc d;
    double seconds = 0;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("dir", o->d.root, "folder to serve (its index.html is the page)")->required();
  app.add_option("--port", o->d.port, "TCP port (0: any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--host", o->d.host, "loopback address to listen on (127.0.0.0/8 or ::1)")->capture_default_str();
  app.add_option("--request-timeout", o->d.request_seconds,
                 "seconds a client has to send a whole request (from connecting or the previous answer)")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 3600.0));
  app.add_option("--seconds", o->seconds, "stop after this many seconds (0: until interrupted)")
      ->check(CLI::Range(0.0, 1e7));
  app.footer(
      "Prints the page's address on its first line, then serves until Ctrl-C.\n"
      "Example:\n  iblkit demo --out demo-out --only sh,lights,web && iblkit serve demo-out/web --port 8080");
  app.callback([o] {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::thread timer;
    if (o->seconds > 0)
      timer = std::thread([s = o->seconds] {
        auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
        while (!g_stop && std::chrono::steady_clock::now() < end)
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        g_stop = true;
      });
    try {
      iblcli::serve_static(o->d, &g_stop, [&](int port) {
        std::string host = o->d.host.find(':') != std::string::npos ? "[" + o->d.host + "]" : o->d.host;
        fmt::print("serving {} at http://{}:{}/\n", o->d.root, host, port);
        std::fflush(stdout);
      });
    } catch (...) {
      g_stop = true;
      if (timer.joinable()) timer.join();
      throw;
    }
    if (timer.joinable()) timer.join();
  });
}

iblcli::Command reg("serve", setup);

}  // namespace
