// The static HTTP server of `iblkit serve` and of the demo's screenshot: GET and HEAD of the files
// under one folder, to a browser on this machine. Built on GNU libmicrohttpd (docs/web.md, "Serving"):
// its event loop holds idle connections without a thread each, a fixed pool of threads answers, the
// number of connections is bounded (below the open-file limit) and accept() pauses while at the bound
// or out of descriptors, files go out with sendfile() without being read into memory, and Range
// requests are answered. This file adds what a viewer's server must refuse: a Host that is not this
// machine (DNS rebinding), paths that leave the folder or pass through a link (opened beneath the
// folder with openat2, so no check-then-open race), and requests that take too long (a deadline per
// request, not per byte). No failure of one request ends the server: it answers 503.
// The server lives in the plugin libiblkit_serve.so (libmicrohttpd and GnuTLS stay out of the
// executable's start-up): serve_static loads it.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "iblkit/core/plugin.h"

namespace iblcli {

struct StaticServerDesc {
  std::string root;                // folder served as "/"
  std::string host = "127.0.0.1";  // a loopback address (127.0.0.0/8 or ::1); others are refused
  int port = 8080;                 // 0: any free port (the bound one is passed to on_ready)
  int threads = 4;                 // the pool that answers requests
  int max_connections = 0;         // open connections at most; 0: from the open-file limit (at most 1000)
  double request_seconds = 10;     // deadline for a request's head, from the connection or the previous answer
  double busy_idle_seconds = 1;    // with more than 3/4 of max_connections open, connections that sent no
                                   // whole request for this long are closed, oldest first, down to half
};

// Content type of a file name by its extension (text/javascript for .js/.mjs, which module scripts
// need; application/octet-stream when unknown).
std::string content_type(const std::string& path);

// Opens the file a request path names ("/a/b.js", percent-decoded, without the query) beneath the
// folder open as root_fd, without following any link (openat2 RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS;
// an O_NOFOLLOW walk where the kernel lacks openat2). "/" and folders give their index.html. Returns
// the descriptor of a regular file, or −1 where the path has a ".." segment, leaves the folder, passes
// through a link, or names something else (missing, a FIFO, a device, a folder without index.html).
// *index: the descriptor is a folder's index.html.
int open_beneath(int root_fd, const std::string& path, bool* index = nullptr);
int open_beneath_walk(int root_fd, const std::string& path, bool* index = nullptr);  // the walk alone (its test)

// A Range header ("bytes=0-99", "bytes=500-", "bytes=-200") on a file of `size` bytes: status 200 (no
// range, several ranges or a malformed one: the whole file), 206 (bytes [first, first + length)), or
// 416 (nothing of the file satisfies it).
struct ByteRange {
  int status = 200;
  int64_t first = 0, length = 0;
};
ByteRange parse_range(const char* header, int64_t size);

// Whether a Host header names this machine: localhost, 127.0.0.1, [::1] or the listening address,
// with the listening port.
bool host_is_local(const char* host, const std::string& listen_host, int port);

// Serves until *stop becomes true (checked every 100 ms). Calls on_ready(port) once listening.
// Throws ibl::Error when the folder is missing, the host is not loopback, the port is taken or the
// server cannot start.
void serve_static(const StaticServerDesc& desc, const std::atomic<bool>* stop,
                  const std::function<void(int)>& on_ready);

namespace detail {
struct ServeDriver {
  void (*serve)(const StaticServerDesc& desc, const std::atomic<bool>* stop, const std::function<void(int)>& on_ready);
};
}  // namespace detail
// The slot the plugin fills (in the executable, so that the plugin's registrar finds it).
ibl::plugin::Provided<detail::ServeDriver>& serve_driver();

}  // namespace iblcli
