#include "static_server.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "iblkit/core/error.h"

namespace iblcli {

namespace fs = std::filesystem;
using ibl::ErrorKind;
using ibl::fail;

std::string content_type(const std::string& path) {
  static const std::pair<const char*, const char*> kTypes[] = {{".html", "text/html; charset=utf-8"},
                                                               {".js", "text/javascript"},
                                                               {".mjs", "text/javascript"},
                                                               {".json", "application/json"},
                                                               {".css", "text/css"},
                                                               {".png", "image/png"},
                                                               {".jpg", "image/jpeg"},
                                                               {".gltf", "model/gltf+json"},
                                                               {".glb", "model/gltf-binary"},
                                                               {".ktx2", "image/ktx2"},
                                                               {".wasm", "application/wasm"},
                                                               {".svg", "image/svg+xml"}};
  std::string ext = fs::path(path).extension().string();
  for (auto& [e, t] : kTypes)
    if (ext == e) return t;
  return "application/octet-stream";
}

namespace {

// %XX decoding of a URL path; "" when malformed.
std::string percent_decode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '%') {
      out += s[i];
      continue;
    }
    if (i + 2 >= s.size() || !std::isxdigit(static_cast<unsigned char>(s[i + 1])) ||
        !std::isxdigit(static_cast<unsigned char>(s[i + 2])))
      return "";
    out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
    i += 2;
  }
  return out;
}

bool send_all(int fd, const char* p, size_t n) {
  while (n > 0) {
    ssize_t w = ::send(fd, p, n, MSG_NOSIGNAL);
    if (w <= 0) return false;
    p += w;
    n -= size_t(w);
  }
  return true;
}

void respond(int fd, int code, const char* reason, const std::string& type, const std::string& body, bool head) {
  std::string h = fmt::format(
      "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: "
      "close\r\n\r\n",
      code, reason, type, body.size());
  if (send_all(fd, h.data(), h.size()) && !head) send_all(fd, body.data(), body.size());
}

void handle(int fd, const std::string& root, const std::atomic<bool>* stop) {
  // Read the request head (up to 16 KiB). A browser opens connections ahead of its requests and may
  // use one after seconds: wait up to 60 s, or until the server stops.
  std::string req;
  char buf[4096];
  while (req.find("\r\n\r\n") == std::string::npos && req.size() < 16384) {
    pollfd p{fd, POLLIN, 0};
    int waited = 0, ready = 0;
    while ((ready = ::poll(&p, 1, 100)) == 0 && (waited += 100) < 60000)
      if (stop && stop->load()) return;
    if (ready <= 0) return;
    ssize_t r = ::recv(fd, buf, sizeof buf, 0);
    if (r <= 0) return;
    req.append(buf, size_t(r));
  }
  size_t sp1 = req.find(' '), sp2 = sp1 == std::string::npos ? sp1 : req.find(' ', sp1 + 1);
  if (sp2 == std::string::npos) return respond(fd, 400, "Bad Request", "text/plain", "bad request\n", false);
  std::string method = req.substr(0, sp1), target = req.substr(sp1 + 1, sp2 - sp1 - 1);
  bool head = method == "HEAD";
  if (method != "GET" && !head)
    return respond(fd, 405, "Method Not Allowed", "text/plain", "GET or HEAD only\n", false);
  std::string file = resolve_request(root, target);
  if (file.empty()) return respond(fd, 404, "Not Found", "text/plain", "not found\n", head);
  std::ifstream in(file, std::ios::binary);
  std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) return respond(fd, 500, "Internal Server Error", "text/plain", "read error\n", head);
  respond(fd, 200, "OK", content_type(file), body, head);
}

// Half-closes and drains what the client still sends (up to 2 s) before closing: closing a socket
// with unread input sends a reset, which can destroy the response's tail in the client.
void lingering_close(int fd) {
  ::shutdown(fd, SHUT_WR);
  char buf[1024];
  for (int i = 0; i < 20; ++i) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    if (::recv(fd, buf, sizeof buf, 0) <= 0) break;
  }
  ::close(fd);
}

}  // namespace

std::string resolve_request(const std::string& root, const std::string& target) {
  std::string path = target.substr(0, target.find_first_of("?#"));
  path = percent_decode(path);
  if (path.empty() || path[0] != '/' || path.find('\0') != std::string::npos) return "";
  for (size_t i = 0; i <= path.size();) {  // refuse any ".." segment before touching the disk
    size_t j = path.find('/', i);
    if (j == std::string::npos) j = path.size();
    if (path.compare(i, j - i, "..") == 0) return "";
    i = j + 1;
  }
  std::error_code ec;
  fs::path base = fs::canonical(root, ec);
  if (ec) return "";
  fs::path p = base / fs::path(path.substr(1));
  if (fs::is_directory(p, ec)) p /= "index.html";
  fs::path real = fs::canonical(p, ec);  // follows links: the result must still lie under root
  if (ec || !fs::is_regular_file(real, ec)) return "";
  auto [b, r] = std::mismatch(base.begin(), base.end(), real.begin(), real.end());
  if (b != base.end()) return "";
  return real.string();
}

void serve_static(const StaticServerDesc& d, const std::atomic<bool>* stop, const std::function<void(int)>& on_ready) {
  if (!fs::is_directory(d.root)) fail(ErrorKind::Io, "serve: {} is not a folder", d.root);
  if (d.port < 0 || d.port > 65535) fail(ErrorKind::Value, "serve: --port {} is not in 0..65535", d.port);
  addrinfo hints{}, *ai = nullptr;
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICHOST | AI_PASSIVE;
  if (::getaddrinfo(d.host.c_str(), std::to_string(d.port).c_str(), &hints, &ai) != 0 || !ai)
    fail(ErrorKind::Value, "serve: --host {} is not a numeric address", d.host);
  bool loopback = ai->ai_family == AF_INET
                      ? (ntohl(reinterpret_cast<sockaddr_in*>(ai->ai_addr)->sin_addr.s_addr) >> 24) == 127
                      : IN6_IS_ADDR_LOOPBACK(&reinterpret_cast<sockaddr_in6*>(ai->ai_addr)->sin6_addr);
  if (!loopback) {
    ::freeaddrinfo(ai);
    fail(ErrorKind::Value,
         "serve: --host {} is not a loopback address (127.0.0.0/8 or ::1): the viewer is served to this machine only",
         d.host);
  }
  int s = ::socket(ai->ai_family, SOCK_STREAM, 0);
  int one = 1;
  ::setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (s < 0 || ::bind(s, ai->ai_addr, ai->ai_addrlen) != 0 || ::listen(s, 64) != 0) {
    int e = errno;
    ::freeaddrinfo(ai);
    if (s >= 0) ::close(s);
    fail(ErrorKind::Io, "serve: cannot listen on {}:{}: {}", d.host, d.port, std::strerror(e));
  }
  ::freeaddrinfo(ai);
  sockaddr_storage bound{};
  socklen_t len = sizeof bound;
  ::getsockname(s, reinterpret_cast<sockaddr*>(&bound), &len);
  int port = ntohs(bound.ss_family == AF_INET ? reinterpret_cast<sockaddr_in*>(&bound)->sin_port
                                              : reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port);
  if (on_ready) on_ready(port);
  struct Worker {
    std::thread t;
    std::shared_ptr<std::atomic<bool>> done;
  };
  std::vector<Worker> workers;
  while (!(stop && stop->load())) {
    pollfd p{s, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    int c = ::accept(s, nullptr, nullptr);
    if (c < 0) continue;
    // One thread a connection: a browser opens speculative connections that send nothing for a while.
    auto done = std::make_shared<std::atomic<bool>>(false);
    workers.push_back({std::thread([c, root = d.root, stop, done] {
                         handle(c, root, stop);
                         lingering_close(c);
                         *done = true;
                       }),
                       done});
    // Reap the connections already served, so that a long session keeps no finished threads.
    for (size_t i = 0; i < workers.size();)
      if (*workers[i].done) {
        workers[i].t.join();
        workers[i] = std::move(workers.back());
        workers.pop_back();
      } else {
        ++i;
      }
  }
  for (auto& w : workers) w.t.join();  // each ends within 100 ms of the stop
  ::close(s);
}

}  // namespace iblcli
