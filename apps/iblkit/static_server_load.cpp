// serve_static in the executable: the server itself is the "serve" plugin (static_server.cpp).
#include "iblkit/core/plugin.h"
#include "static_server.h"

namespace iblcli {

ibl::plugin::Provided<detail::ServeDriver>& serve_driver() {
  static constinit ibl::plugin::Provided<detail::ServeDriver> slot{"serve", "HTTP server"};
  return slot;
}

void serve_static(const StaticServerDesc& desc, const std::atomic<bool>* stop,
                  const std::function<void(int)>& on_ready) {
  serve_driver().get().serve(desc, stop, on_ready);
}

}  // namespace iblcli
