#include "server.h"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "sketchnav/core/error.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/core/log.h"

namespace sketchnav::ui {

namespace {

// httplib's TaskQueue with one thread per connection, at most `max` at once: a connection that
// sends nothing (or a byte now and then) holds only its own thread until the read timeout, never
// a shared pool slot that STOP would have to wait for. When all slots are taken the accept loop
// waits for one to free (new connections queue in the kernel's backlog).
class ConnectionThreads final : public httplib::TaskQueue {
 public:
  explicit ConnectionThreads(std::size_t max) : max_(std::max<std::size_t>(max, 1)) {}
  void enqueue(std::function<void()> fn) override {
    std::unique_lock<std::mutex> l(m_);
    free_.wait(l, [&] { return running_ < max_; });
    ++running_;
    l.unlock();
    try {
      std::thread([this, fn = std::move(fn)] {
        try {
          fn();
        } catch (...) {
          // httplib reports handler exceptions itself; nothing may escape a thread.
        }
        std::lock_guard<std::mutex> g(m_);
        --running_;
        free_.notify_all();
      }).detach();
    } catch (const std::system_error& e) {  // no thread to be had: the connection is dropped
      std::lock_guard<std::mutex> g(m_);
      --running_;
      log::warn("ui", "connection dropped: cannot start a thread", {{"error", e.what()}});
    }
  }
  void shutdown() override {
    std::unique_lock<std::mutex> l(m_);
    free_.wait(l, [&] { return running_ == 0; });
  }

 private:
  const std::size_t max_;
  std::size_t running_ = 0;
  std::mutex m_;
  std::condition_variable free_;
};

// Messages may quote request text that is not UTF-8: sent with U+FFFD, never an exception.
std::string dumpSafe(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace

std::size_t invalidUtf8At(const std::string& s) {
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const std::size_t n = s.size();
  std::size_t i = 0;
  while (i < n) {
    const unsigned c = p[i];
    std::size_t len = 0;
    unsigned lo = 0x80, hi = 0xBF;  // allowed range of the second byte (RFC 3629)
    if (c < 0x80) {
      ++i;
      continue;
    } else if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      if (c == 0xE0) lo = 0xA0;  // overlong
      if (c == 0xED) hi = 0x9F;  // surrogates
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      if (c == 0xF0) lo = 0x90;  // overlong
      if (c == 0xF4) hi = 0x8F;  // above U+10FFFF
    } else {
      return i;  // 0x80..0xC1 (continuation or overlong lead), 0xF5..0xFF
    }
    if (i + len > n) return i;
    if (p[i + 1] < lo || p[i + 1] > hi) return i;
    for (std::size_t k = 2; k < len; ++k)
      if (p[i + k] < 0x80 || p[i + k] > 0xBF) return i;
    i += len;
  }
  return std::string::npos;
}

std::string jsonFieldAt(const std::string& t, std::size_t offset) {
  if (offset > t.size()) return "";
  // Back to the quote opening the string that holds the byte.
  auto quoteBefore = [&](std::size_t from) -> std::size_t {
    for (std::size_t i = from; i-- > 0;) {
      if (t[i] != '"') continue;
      std::size_t bs = 0;
      for (std::size_t k = i; k-- > 0 && t[k] == '\\';) ++bs;
      if (bs % 2 == 0) return i;
    }
    return std::string::npos;
  };
  const std::size_t open = quoteBefore(offset);
  if (open == std::string::npos) return "";
  std::size_t i = open;
  while (i > 0 && std::isspace(static_cast<unsigned char>(t[i - 1]))) --i;
  if (i == 0 || t[i - 1] != ':') return "";  // not a value (a key, or an array element)
  --i;
  while (i > 0 && std::isspace(static_cast<unsigned char>(t[i - 1]))) --i;
  if (i == 0 || t[i - 1] != '"') return "";
  const std::size_t key_end = i - 1;
  const std::size_t key_open = quoteBefore(key_end);
  if (key_open == std::string::npos) return "";
  const std::string key = t.substr(key_open + 1, key_end - key_open - 1);
  if (key.size() > 80 || invalidUtf8At(key) != std::string::npos) return "";
  return key;
}

Json parseJsonBody(const httplib::Request& req, const std::string& what) {
  if (req.body.empty()) return Json::object();
  const std::size_t bad = invalidUtf8At(req.body);
  if (bad != std::string::npos) {
    const std::string field = jsonFieldAt(req.body, bad);
    throw InputError(what + ": " + (field.empty() ? "the body" : "'" + field + "'") +
                     " is not valid UTF-8 (byte " + std::to_string(bad) + ")");
  }
  // The project's JSON parser, not Json::parse(): that let a number overflow ("1e400", an
  // out_of_range, not a parse_error) escape as a 500, and took any nesting depth (a 5 MB body
  // of '[' cost ~0.7 GB).
  return parseJsonText(req.body, what);
}

void sendJson(httplib::Response& res, const Json& j, int status) {
  res.status = status;
  res.set_content(dumpSafe(j), "application/json");
}

void sendError(httplib::Response& res, int status, const std::string& message) {
  sendJson(res, Json{{"error", message}}, status);
}

Server::Server(ServerOptions options)
    : opt_(std::move(options)), http_(std::make_unique<httplib::Server>()) {
  http_->set_payload_max_length(opt_.max_body_bytes);
  http_->set_read_timeout(opt_.read_timeout_s, 0);
  http_->set_keep_alive_timeout(opt_.keep_alive_timeout_s);
  const std::size_t max_conn = opt_.max_connections;
  http_->new_task_queue = [max_conn] { return new ConnectionThreads(max_conn); };
  // Guards run before routing, for every request including static files: a page on another
  // site (or a DNS-rebinding name) must not read or drive the editor or, later, the robot.
  http_->set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    try {
      return guard(req, res);
    } catch (const std::exception& e) {  // nothing may escape a request (httplib would abort)
      sendError(res, 400, std::string("bad request: ") + e.what());
      return httplib::Server::HandlerResponse::Handled;
    }
  });
  http_->set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    try {
      // Keep handler-written error bodies; fill in the ones httplib produced itself (404, 413).
      if (!res.body.empty()) return;
      if (res.status == 413)
        sendError(res, 413, "request body too large");
      else if (res.status == 404)
        sendError(res, 404, "not found: " + req.path.substr(0, 200));
      else
        sendError(res, res.status, "HTTP error " + std::to_string(res.status));
    } catch (...) {
      res.set_content("{\"error\": \"HTTP error\"}", "application/json");
    }
  });
  http_->set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unknown error";
        try {
          std::rethrow_exception(ep);
        } catch (const InputError& e) {
          sendError(res, 400, e.what());
          return;
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
        }
        try {
          log::error("ui", "request failed", {{"path", req.path.substr(0, 200)}, {"error", what}});
          sendError(res, 500, what);
        } catch (...) {
          res.status = 500;
          res.set_content("{\"error\": \"internal error\"}", "application/json");
        }
      });
  http_->set_default_headers({{"Cache-Control", "no-store"},
                              {"X-Content-Type-Options", "nosniff"},
                              {"X-Frame-Options", "DENY"}});
  if (!opt_.web_root.empty() && !http_->set_mount_point("/", opt_.web_root))
    throw RuntimeError("ui: web assets not found in '" + opt_.web_root + "'");
}

// Runs before routing, for every request including static files.
httplib::Server::HandlerResponse Server::guard(const httplib::Request& req,
                                               httplib::Response& res) const {
  // A path that is not UTF-8 (raw or percent-encoded) names nothing here.
  if (invalidUtf8At(req.path) != std::string::npos) {
    sendError(res, 400, "request refused: the path is not valid UTF-8");
    return httplib::Server::HandlerResponse::Handled;
  }
  // One Host header only: a second one could name another site than the one checked.
  if (req.get_header_value_count("Host") > 1) {
    sendError(res, 400, "request refused: more than one Host header");
    return httplib::Server::HandlerResponse::Handled;
  }
  if (!hostAllowed(req.get_header_value("Host"))) {
    sendError(
        res, 403,
        "request refused: Host '" + req.get_header_value("Host") + "' is not this local server");
    return httplib::Server::HandlerResponse::Handled;
  }
  if (req.has_header("Origin") && !originAllowed(req.get_header_value("Origin"))) {
    sendError(
        res, 403,
        "request refused: Origin '" + req.get_header_value("Origin") + "' is not this local page");
    return httplib::Server::HandlerResponse::Handled;
  }
  if (req.get_header_value("Sec-Fetch-Site") == "cross-site") {
    sendError(res, 403, "request refused: cross-site request");
    return httplib::Server::HandlerResponse::Handled;
  }
  if (req.body.size() > opt_.max_body_bytes) {
    sendError(res, 413,
              "request body too large (limit " + std::to_string(opt_.max_body_bytes) + " bytes)");
    return httplib::Server::HandlerResponse::Handled;
  }
  return httplib::Server::HandlerResponse::Unhandled;
}

Server::~Server() {
  stop();
}

Handler Server::wrap(Handler h) const {
  return [h = std::move(h)](const httplib::Request& req, httplib::Response& res) {
    try {
      h(req, res);
    } catch (const InputError& e) {
      sendError(res, 400, e.what());
    } catch (const Json::exception& e) {
      sendError(res, 400, std::string("bad JSON: ") + e.what());
    }
  };
}

void Server::get(const std::string& p, Handler h) {
  http_->Get(p, wrap(std::move(h)));
}
void Server::post(const std::string& p, Handler h) {
  http_->Post(p, wrap(std::move(h)));
}
void Server::put(const std::string& p, Handler h) {
  http_->Put(p, wrap(std::move(h)));
}
void Server::del(const std::string& p, Handler h) {
  http_->Delete(p, wrap(std::move(h)));
}

int Server::bind() {
  if (opt_.port == 0) {
    port_ = http_->bind_to_any_port(opt_.host);
    if (port_ < 0) throw RuntimeError("ui: cannot bind " + opt_.host);
  } else {
    if (!http_->bind_to_port(opt_.host, opt_.port))
      throw RuntimeError("ui: cannot bind " + opt_.host + ":" + std::to_string(opt_.port) +
                         " (port in use?)");
    port_ = opt_.port;
  }
  return port_;
}

void Server::serve() {
  http_->listen_after_bind();
}
void Server::stop() {
  if (http_ && http_->is_running()) http_->stop();
}
bool Server::running() const {
  return http_->is_running();
}

std::string Server::url() const {
  const std::string h = (opt_.host == "0.0.0.0" || opt_.host == "::") ? "127.0.0.1" : opt_.host;
  return "http://" + h + ":" + std::to_string(port_) + "/";
}

bool Server::hostAllowed(const std::string& host) const {
  const std::string p = ":" + std::to_string(port_);
  std::vector<std::string> ok = {"127.0.0.1" + p, "localhost" + p, "[::1]" + p};
  if (opt_.host != "0.0.0.0" && opt_.host != "::") ok.push_back(opt_.host + p);
  for (const auto& h : opt_.extra_hosts) ok.push_back(h + p);
  std::string lower = host;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return std::find(ok.begin(), ok.end(), lower) != ok.end();
}

bool Server::originAllowed(const std::string& origin) const {
  const std::string prefix = "http://";
  if (origin.rfind(prefix, 0) != 0) return false;  // also refuses "null" (file://, sandboxes)
  return hostAllowed(origin.substr(prefix.size()));
}

}  // namespace sketchnav::ui
