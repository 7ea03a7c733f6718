// A tiny static HTTP/1.1 file server for the web viewer (iblkit serve, and the demo's screenshot):
// GET and HEAD of files under one folder, on a loopback address, one connection at a time,
// "Connection: close". Not a general web server: no directory listings, no ranges, no keep-alive.
#pragma once
#include <atomic>
#include <functional>
#include <string>

namespace iblcli {

struct StaticServerDesc {
  std::string root;                // folder served as "/"
  std::string host = "127.0.0.1";  // a loopback address (127.0.0.0/8 or ::1); others are refused
  int port = 8080;                 // 0: any free port (the bound one is passed to on_ready)
};

// Content type of a file name by its extension (text/javascript for .js/.mjs, which module scripts
// need; application/octet-stream when unknown).
std::string content_type(const std::string& path);

// Maps a request target ("/a/b.js?x=1") to a file under root, or "" when it is outside root, names a
// folder without index.html, or does not exist. "/" and folders serve their index.html.
std::string resolve_request(const std::string& root, const std::string& target);

// Serves until *stop becomes true (checked every 100 ms). Calls on_ready(port) once listening.
// Throws ibl::Error when the folder is missing, the host is not loopback or the port is taken.
void serve_static(const StaticServerDesc& desc, const std::atomic<bool>* stop,
                  const std::function<void(int)>& on_ready);

}  // namespace iblcli
