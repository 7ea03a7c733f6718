#include "static_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <linux/openat2.h>
#include <microhttpd.h>
#include <netdb.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "iblkit/core/error.h"

namespace iblcli {

namespace fs = std::filesystem;
using ibl::ErrorKind;
using ibl::fail;
using Clock = std::chrono::steady_clock;

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

// The path's segments without empty and "." ones; false where one is "..".
bool segments(const std::string& path, std::vector<std::string>* out) {
  if (path.empty() || path[0] != '/') return false;
  for (size_t i = 1; i <= path.size();) {
    size_t j = path.find('/', i);
    if (j == std::string::npos) j = path.size();
    std::string s = path.substr(i, j - i);
    if (s == "..") return false;
    if (!s.empty() && s != ".") out->push_back(s);
    i = j + 1;
  }
  return true;
}

// fd when it is a regular file, else closes it and returns −1; a folder gives its index.html.
int regular_or_index(int fd, int (*open_in)(int, const char*), bool* index) {
  struct stat st {};
  if (fd < 0 || ::fstat(fd, &st) != 0) {
    if (fd >= 0) ::close(fd);
    return -1;
  }
  if (S_ISDIR(st.st_mode) && open_in) {
    int f = open_in(fd, "index.html");
    ::close(fd);
    if (index) *index = true;
    return regular_or_index(f, nullptr, nullptr);
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return -1;
  }
  return fd;
}

constexpr int kOpenFlags = O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK;  // O_NONBLOCK: a FIFO never blocks the open

int openat2_beneath(int dir, const char* rel) {
  open_how how{};
  how.flags = kOpenFlags;
  how.resolve = RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS | RESOLVE_NO_MAGICLINKS;
  return int(::syscall(SYS_openat2, dir, rel, &how, sizeof how));
}

int openat_nofollow(int dir, const char* name) { return ::openat(dir, name, kOpenFlags | O_NOFOLLOW); }

}  // namespace

int open_beneath(int root_fd, const std::string& path, bool* index) {
  if (index) *index = false;
  std::vector<std::string> seg;
  if (path.find('\0') != std::string::npos || !segments(path, &seg)) return -1;
  std::string rel = ".";
  for (const auto& s : seg) rel += "/" + s;
  // IBLKIT_SERVE_WALK=1: the O_NOFOLLOW walk even where openat2 exists (cli_serve tests both).
  static const bool walk = std::getenv("IBLKIT_SERVE_WALK") && std::string(std::getenv("IBLKIT_SERVE_WALK")) == "1";
  if (walk) return open_beneath_walk(root_fd, path, index);
  int fd = openat2_beneath(root_fd, rel.c_str());
  if (fd < 0 && errno == ENOSYS) return open_beneath_walk(root_fd, path, index);
  return regular_or_index(fd, openat2_beneath, index);
}

int open_beneath_walk(int root_fd, const std::string& path, bool* index) {
  if (index) *index = false;
  std::vector<std::string> seg;
  if (path.find('\0') != std::string::npos || !segments(path, &seg)) return -1;
  int cur = ::openat(root_fd, ".", O_PATH | O_DIRECTORY | O_CLOEXEC);
  for (size_t i = 0; cur >= 0 && i + 1 < seg.size(); ++i) {
    // O_NOFOLLOW with O_PATH opens a link itself, which O_DIRECTORY then refuses.
    int next = ::openat(cur, seg[i].c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    ::close(cur);
    cur = next;
  }
  if (cur < 0) return -1;
  int fd = seg.empty() ? ::openat(cur, ".", kOpenFlags) : openat_nofollow(cur, seg.back().c_str());
  ::close(cur);
  return regular_or_index(fd, openat_nofollow, index);
}

ByteRange parse_range(const char* header, int64_t size) {
  ByteRange whole{200, 0, size};
  if (!header) return whole;
  std::string h = header;
  h.erase(std::remove_if(h.begin(), h.end(), [](unsigned char c) { return std::isspace(c); }), h.end());
  if (h.size() < 7 || !std::equal(h.begin(), h.begin() + 6, "bytes=", [](char a, char b) {
        return std::tolower(static_cast<unsigned char>(a)) == b;
      }))
    return whole;
  std::string spec = h.substr(6);
  size_t dash = spec.find('-');
  if (spec.find(',') != std::string::npos || dash == std::string::npos) return whole;  // several: the whole file
  auto number = [](const std::string& s, int64_t* v) {
    if (s.empty() || s.size() > 18 || !std::all_of(s.begin(), s.end(), ::isdigit)) return false;
    *v = std::stoll(s);
    return true;
  };
  int64_t a = 0, b = 0;
  std::string sa = spec.substr(0, dash), sb = spec.substr(dash + 1);
  if (sa.empty()) {  // the last b bytes
    if (!number(sb, &b)) return whole;
    if (b == 0 || size == 0) return {416, 0, 0};
    b = std::min(b, size);
    return {206, size - b, b};
  }
  if (!number(sa, &a)) return whole;
  if (sb.empty())
    b = size - 1;
  else if (!number(sb, &b) || b < a)
    return whole;
  if (a >= size) return {416, 0, 0};
  b = std::min(b, size - 1);
  return {206, a, b - a + 1};
}

bool host_is_local(const char* host, const std::string& listen_host, int port) {
  if (!host) return false;
  std::string h = host;
  std::transform(h.begin(), h.end(), h.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  std::string name = h, p;
  size_t colon = h.rfind(':');
  if (colon != std::string::npos && h.find(']', colon) == std::string::npos) {
    name = h.substr(0, colon);
    p = h.substr(colon + 1);
  }
  if (p.empty() ? port != 80 : p != std::to_string(port)) return false;
  std::string listen = listen_host.find(':') != std::string::npos ? "[" + listen_host + "]" : listen_host;
  return name == "localhost" || name == "127.0.0.1" || name == "[::1]" || name == listen;
}

namespace {

// The connections MHD holds, with the deadline each runs against: the watchdog shuts down the socket
// of one past its deadline (MHD then closes it). An entry leaves in MHD's "closed" notification,
// which comes before MHD closes the socket, under the same lock as the shutdown: a socket number is
// never shut down after it was reused.
class Deadlines {
 public:
  struct Conn {
    int fd = -1;
    Clock::time_point since;
    bool answering = false;  // a response is under way (its own deadline), else waiting for a request
    double seconds = 0;      // the deadline of the current phase
  };
  void started(MHD_Connection* c, int fd, double s) {
    std::lock_guard lk(mu_);
    conns_[c] = {fd, Clock::now(), false, s};
  }
  void closed(MHD_Connection* c) {
    std::lock_guard lk(mu_);
    conns_.erase(c);
  }
  void phase(MHD_Connection* c, bool answering, double s) {
    std::lock_guard lk(mu_);
    auto it = conns_.find(c);
    if (it != conns_.end()) it->second = {it->second.fd, Clock::now(), answering, s};
  }
  // Shuts down the connections past their deadline; with more than `high` open, also those waiting
  // for a request longer than idle_s, oldest first, until `low` remain.
  void sweep(size_t high, size_t low, double idle_s) {
    std::lock_guard lk(mu_);
    auto now = Clock::now();
    auto age = [&](const Conn& c) { return std::chrono::duration<double>(now - c.since).count(); };
    std::vector<std::pair<double, Conn*>> idle;
    size_t open = 0;
    for (auto& [k, c] : conns_) {
      if (c.fd < 0) continue;
      if (age(c) > c.seconds) {
        ::shutdown(c.fd, SHUT_RDWR);
        c.fd = -1;
        continue;
      }
      ++open;
      if (!c.answering && age(c) > idle_s) idle.push_back({age(c), &c});
    }
    if (open <= high) return;
    std::sort(idle.begin(), idle.end(), [](auto& a, auto& b) { return a.first > b.first; });
    for (auto& [a, c] : idle) {
      if (open <= low) break;
      ::shutdown(c->fd, SHUT_RDWR);
      c->fd = -1;
      --open;
    }
  }

 private:
  std::mutex mu_;
  std::unordered_map<MHD_Connection*, Conn> conns_;
};

struct Server {
  StaticServerDesc desc;
  int root_fd = -1, port = 0;
  Deadlines deadlines;
};

// Time for a response of `bytes` to go out: half a minute and 256 KiB/s.
double response_seconds(int64_t bytes) { return 30 + double(bytes) / (256 * 1024); }

MHD_Result answer_text(MHD_Connection* c, unsigned status, const char* text) {
  MHD_Response* r = MHD_create_response_from_buffer(std::strlen(text), const_cast<char*>(text), MHD_RESPMEM_PERSISTENT);
  if (!r) return MHD_NO;  // MHD closes the connection
  MHD_add_response_header(r, "Content-Type", "text/plain; charset=utf-8");
  MHD_add_response_header(r, "Cache-Control", "no-store");
  if (status == MHD_HTTP_METHOD_NOT_ALLOWED) MHD_add_response_header(r, "Allow", "GET, HEAD");
  MHD_Result q = MHD_queue_response(c, status, r);
  MHD_destroy_response(r);
  return q;
}

MHD_Result answer_file(Server& s, MHD_Connection* c, const char* url) {
  bool index = false;
  int fd = open_beneath(s.root_fd, url, &index);
  if (fd < 0)
    return answer_text(c, errno == EMFILE || errno == ENFILE ? 503 : MHD_HTTP_NOT_FOUND,
                       errno == EMFILE || errno == ENFILE ? "busy: try again\n" : "not found\n");
  struct stat st {};
  ::fstat(fd, &st);
  const int64_t size = st.st_size;
  ByteRange range = parse_range(MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_RANGE), size);
  if (range.status == 416) {
    ::close(fd);
    MHD_Response* r = MHD_create_response_from_buffer(0, nullptr, MHD_RESPMEM_PERSISTENT);
    if (!r) return MHD_NO;
    MHD_add_response_header(r, "Content-Range", fmt::format("bytes */{}", size).c_str());
    MHD_Result q = MHD_queue_response(c, MHD_HTTP_RANGE_NOT_SATISFIABLE, r);
    MHD_destroy_response(r);
    return q;
  }
  // The file goes out from its descriptor (sendfile), never read whole into memory; MHD closes fd.
  MHD_Response* r = MHD_create_response_from_fd_at_offset64(uint64_t(range.length), fd, uint64_t(range.first));
  if (!r) {
    ::close(fd);
    return answer_text(c, MHD_HTTP_SERVICE_UNAVAILABLE, "busy: try again\n");
  }
  MHD_add_response_header(r, "Content-Type", content_type(index ? "index.html" : url).c_str());
  MHD_add_response_header(r, "Cache-Control", "no-store");
  MHD_add_response_header(r, "Accept-Ranges", "bytes");
  MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
  if (range.status == 206)
    MHD_add_response_header(r, "Content-Range",
                            fmt::format("bytes {}-{}/{}", range.first, range.first + range.length - 1, size).c_str());
  s.deadlines.phase(c, true, response_seconds(range.length));
  MHD_Result q = MHD_queue_response(c, unsigned(range.status), r);
  MHD_destroy_response(r);
  return q;
}

MHD_Result on_request(void* cls, MHD_Connection* c, const char* url, const char* method, const char* /*version*/,
                      const char* /*upload*/, size_t* upload_size, void** req) {
  Server& s = *static_cast<Server*>(cls);
  try {
    if (*req) {  // a request body (none is expected): dropped
      *upload_size = 0;
      return MHD_YES;
    }
    *req = &s;
    if (!host_is_local(MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_HOST), s.desc.host, s.port))
      return answer_text(c, MHD_HTTP_MISDIRECTED_REQUEST, "this server answers requests for this machine only\n");
    if (std::strcmp(method, MHD_HTTP_METHOD_GET) != 0 && std::strcmp(method, MHD_HTTP_METHOD_HEAD) != 0)
      return answer_text(c, MHD_HTTP_METHOD_NOT_ALLOWED, "GET or HEAD only\n");
    return answer_file(s, c, url);
  } catch (...) {  // bad_alloc and anything else: this request fails, the server goes on
    return answer_text(c, MHD_HTTP_SERVICE_UNAVAILABLE, "busy: try again\n");
  }
}

void on_connection(void* cls, MHD_Connection* c, void** /*socket_context*/, MHD_ConnectionNotificationCode code) {
  Server& s = *static_cast<Server*>(cls);
  try {
    if (code == MHD_CONNECTION_NOTIFY_STARTED) {
      const MHD_ConnectionInfo* info = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
      s.deadlines.started(c, info ? info->connect_fd : -1, s.desc.request_seconds);
    } else {
      s.deadlines.closed(c);
    }
  } catch (...) {  // no entry: the connection goes without a deadline (MHD's idle timeout still holds)
  }
}

void on_completed(void* cls, MHD_Connection* c, void** /*req*/, MHD_RequestTerminationCode /*why*/) {
  Server& s = *static_cast<Server*>(cls);
  s.deadlines.phase(c, false, s.desc.request_seconds);  // the next request's head has the same deadline
}

// Bound (and listening) socket on desc's loopback address; *port the bound port.
int listen_loopback(const StaticServerDesc& d, int* port, bool* v6) {
  addrinfo hints{}, *ai = nullptr;
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICHOST | AI_PASSIVE;
  if (::getaddrinfo(d.host.c_str(), std::to_string(d.port).c_str(), &hints, &ai) != 0 || !ai)
    fail(ErrorKind::Value, "serve: --host {} is not a numeric address", d.host);
  *v6 = ai->ai_family == AF_INET6;
  bool loopback = ai->ai_family == AF_INET
                      ? (ntohl(reinterpret_cast<sockaddr_in*>(ai->ai_addr)->sin_addr.s_addr) >> 24) == 127
                      : IN6_IS_ADDR_LOOPBACK(&reinterpret_cast<sockaddr_in6*>(ai->ai_addr)->sin6_addr);
  if (!loopback) {
    ::freeaddrinfo(ai);
    fail(ErrorKind::Value,
         "serve: --host {} is not a loopback address (127.0.0.0/8 or ::1): the viewer is served to this machine only",
         d.host);
  }
  int s = ::socket(ai->ai_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
  int one = 1;
  if (s >= 0) ::setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (s < 0 || ::bind(s, ai->ai_addr, ai->ai_addrlen) != 0 || ::listen(s, SOMAXCONN) != 0) {
    int e = errno;
    ::freeaddrinfo(ai);
    if (s >= 0) ::close(s);
    fail(ErrorKind::Io, "serve: cannot listen on {}:{}: {}", d.host, d.port, std::strerror(e));
  }
  ::freeaddrinfo(ai);
  sockaddr_storage bound{};
  socklen_t len = sizeof bound;
  ::getsockname(s, reinterpret_cast<sockaddr*>(&bound), &len);
  *port = ntohs(bound.ss_family == AF_INET ? reinterpret_cast<sockaddr_in*>(&bound)->sin_port
                                           : reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port);
  return s;
}

// Connections at most: each may hold a socket and a file open, within the open-file limit less a
// reserve for the process's own files.
unsigned connection_limit(int asked) {
  rlimit rl{};
  ::getrlimit(RLIMIT_NOFILE, &rl);
  const int64_t by_files = rl.rlim_cur == RLIM_INFINITY ? 100000 : (int64_t(rl.rlim_cur) - 64) / 2;
  int64_t n = asked > 0 ? asked : 1000;
  return unsigned(std::clamp<int64_t>(std::min(n, by_files), 8, 100000));
}

}  // namespace

namespace {

void serve(const StaticServerDesc& d, const std::atomic<bool>* stop, const std::function<void(int)>& on_ready) {
  if (d.port < 0 || d.port > 65535) fail(ErrorKind::Value, "serve: --port {} is not in 0..65535", d.port);
  if (d.threads < 1 || d.threads > 64) fail(ErrorKind::Value, "serve: {} threads is not in 1..64", d.threads);
  Server s;
  s.desc = d;
  s.root_fd = ::open(d.root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (s.root_fd < 0) fail(ErrorKind::Io, "serve: {} is not a folder ({})", d.root, std::strerror(errno));
  bool v6 = false;
  int listen_fd = -1;
  try {
    listen_fd = listen_loopback(d, &s.port, &v6);
  } catch (...) {
    ::close(s.root_fd);
    throw;
  }
  std::signal(SIGPIPE, SIG_IGN);  // a client that goes away mid-answer is that answer's failure only
  const unsigned limit = connection_limit(d.max_connections);
  unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL | MHD_USE_ITC;
  if (v6) flags |= MHD_USE_IPv6;
  MHD_Daemon* daemon = MHD_start_daemon(
      flags, 0, nullptr, nullptr, &on_request, &s, MHD_OPTION_LISTEN_SOCKET, listen_fd, MHD_OPTION_THREAD_POOL_SIZE,
      unsigned(d.threads), MHD_OPTION_CONNECTION_LIMIT, limit, MHD_OPTION_CONNECTION_TIMEOUT,
      unsigned(std::max(1.0, d.request_seconds)), MHD_OPTION_CONNECTION_MEMORY_LIMIT, size_t(64 * 1024),
      MHD_OPTION_NOTIFY_CONNECTION, &on_connection, &s, MHD_OPTION_NOTIFY_COMPLETED, &on_completed, &s, MHD_OPTION_END);
  if (!daemon) {
    ::close(listen_fd);
    ::close(s.root_fd);
    fail(ErrorKind::Io, "serve: the HTTP server could not start on {}:{} (out of threads or memory?)", d.host, s.port);
  }
  try {
    if (on_ready) on_ready(s.port);
  } catch (...) {
    MHD_stop_daemon(daemon);
    ::close(listen_fd);
    ::close(s.root_fd);
    throw;
  }
  const size_t high = limit * 3 / 4, low = limit / 2;
  while (!(stop && stop->load())) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    s.deadlines.sweep(high, low, d.busy_idle_seconds);
  }
  MHD_stop_daemon(daemon);
  ::close(listen_fd);
  ::close(s.root_fd);
}

const detail::ServeDriver kDriver{serve};
[[maybe_unused]] const bool kProvided = (serve_driver().provide(&kDriver), true);

}  // namespace

}  // namespace iblcli
