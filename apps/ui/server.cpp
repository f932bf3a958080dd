#include "server.h"

#include <algorithm>

#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"

namespace sketchnav::ui {

void sendJson(httplib::Response& res, const Json& j, int status) {
  res.status = status;
  res.set_content(j.dump(), "application/json");
}

void sendError(httplib::Response& res, int status, const std::string& message) {
  sendJson(res, Json{{"error", message}}, status);
}

Server::Server(ServerOptions options)
    : opt_(std::move(options)), http_(std::make_unique<httplib::Server>()) {
  http_->set_payload_max_length(opt_.max_body_bytes);
  // Guards run before routing, for every request including static files: a page on another
  // site (or a DNS-rebinding name) must not read or drive the editor or, later, the robot.
  http_->set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    if (!hostAllowed(req.get_header_value("Host"))) {
      sendError(
          res, 403,
          "request refused: Host '" + req.get_header_value("Host") + "' is not this local server");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (req.has_header("Origin") && !originAllowed(req.get_header_value("Origin"))) {
      sendError(res, 403,
                "request refused: Origin '" + req.get_header_value("Origin") +
                    "' is not this local page");
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
  });
  http_->set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    // Keep handler-written error bodies; fill in the ones httplib produced itself (404, 413).
    if (!res.body.empty()) return;
    if (res.status == 413)
      sendError(res, 413, "request body too large");
    else if (res.status == 404)
      sendError(res, 404, "not found: " + req.path);
    else
      sendError(res, res.status, "HTTP error " + std::to_string(res.status));
  });
  http_->set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unknown error";
        try {
          std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
        }
        log::error("ui", "request failed", {{"path", req.path}, {"error", what}});
        sendError(res, 500, what);
      });
  http_->set_default_headers({{"Cache-Control", "no-store"},
                              {"X-Content-Type-Options", "nosniff"},
                              {"X-Frame-Options", "DENY"}});
  if (!opt_.web_root.empty() && !http_->set_mount_point("/", opt_.web_root))
    throw RuntimeError("ui: web assets not found in '" + opt_.web_root + "'");
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
