#pragma once
// The local web server behind `sketchnav ui`: static pages plus a JSON API, guarded so only
// the page it serves can drive it. Other areas add their routes (e.g. a live-run page and
// control endpoints) with get()/post()/put()/del(): every route gets the same guards
// (Host/Origin check, body size limit) and the same error mapping (InputError -> 400 with
// {"error": "..."}, anything else -> 500), so a new endpoint is safe by default.
//
// Threading: httplib serves requests from a thread pool; handlers must be thread-safe.
#include <httplib.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/core/config.h"

namespace sketchnav::mapsketch {
struct Sketch;
}

namespace sketchnav::ui {

struct ServerOptions {
  std::string host = "127.0.0.1";         // bind address; only loopback unless the user says so
  int port = 8080;                        // 0 = any free port (tests)
  std::string web_root;                   // static files; "" = none
  std::size_t max_body_bytes = 5u << 20;  // larger request bodies get 413
  std::vector<std::string> extra_hosts;   // more Host names to accept (e.g. "robot.local")
  // Connections: each is served on its own thread (so idle or slow clients cannot hold up
  // STOP behind them), at most max_connections at once; more wait for a free slot.
  std::size_t max_connections = 1024;
  int read_timeout_s = 5;        // a request's headers or body stalled this long [s]: closed
  int keep_alive_timeout_s = 5;  // an idle kept-alive connection is closed after this [s]
};

using Handler = std::function<void(const httplib::Request&, httplib::Response&)>;

class Server {
 public:
  explicit Server(ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Patterns are httplib regexes, e.g. R"(/api/sketches/([^/]+))" (captures in req.matches).
  void get(const std::string& pattern, Handler h);
  void post(const std::string& pattern, Handler h);
  void put(const std::string& pattern, Handler h);
  void del(const std::string& pattern, Handler h);

  /// Binds the socket; returns the port (useful with port 0). RuntimeError when it cannot.
  int bind();
  /// Serves until stop(); call bind() first. Blocks.
  void serve();
  /// Safe from another thread or a signal-watching thread.
  void stop();
  bool running() const;

  int port() const { return port_; }
  /// "http://127.0.0.1:8080/"
  std::string url() const;
  /// True when a request with these headers may use the API (exposed for tests).
  bool hostAllowed(const std::string& host_header) const;
  bool originAllowed(const std::string& origin_header) const;

 private:
  Handler wrap(Handler h) const;
  httplib::Server::HandlerResponse guard(const httplib::Request& req, httplib::Response& res) const;
  ServerOptions opt_;
  std::unique_ptr<httplib::Server> http_;
  int port_ = 0;
};

/// The request body as JSON; InputError naming the field (or byte) when it is not UTF-8 or
/// not JSON. `what` names the request in the message ("run request"). "" -> {}.
Json parseJsonBody(const httplib::Request& req, const std::string& what);
/// Byte offset of the first byte of `s` that is not well-formed UTF-8, or npos.
std::size_t invalidUtf8At(const std::string& s);
/// "in 'key'" for the JSON object key whose value holds byte `offset` of `text` (a guess from
/// the text before it), or "" when none is found.
std::string jsonFieldAt(const std::string& text, std::size_t offset);

/// Response helpers for handlers (messages that are not UTF-8 are sent with U+FFFD).
void sendJson(httplib::Response& res, const Json& j, int status = 200);
void sendError(httplib::Response& res, int status, const std::string& message);

/// The sketch editor's API (doc/ui.md):
///   GET  /api/classes                       landmark classes [{name, thumbnail}]
///   GET  /api/classes/<name>/thumbnail      an image of that class
///   GET  /api/sketches                      sketches in the sketch directory + shipped examples
///   GET  /api/sketches/<file>               one sketch (from the sketch directory)
///   GET  /api/examples/<file>               one shipped example sketch (read-only)
///   POST /api/sketches/<file>               validate and save (file name only, no path)
///   POST /api/route                         sketch -> route (the live preview)
struct EditorOptions {
  std::string landmarks_dir;  // the landmark set: one folder per class
  std::string sketch_dir;     // where sketches are opened from and saved to
  std::string examples_dir;   // shipped examples (read-only); "" = none
};
void addEditorRoutes(Server& server, const EditorOptions& options);

/// A sketch from a POST body (save, route preview): UTF-8, then the sketch parser, then its
/// classes against `classes`; InputError naming `origin` and the field otherwise. Public so
/// the fuzzer (fuzz/entry_webui.cpp) reaches exactly what the routes run.
mapsketch::Sketch sketchFromBody(const std::string& body, const std::string& origin,
                                 const std::vector<std::string>& classes);

/// A sketch file name a user may save to: letters, digits, '_', '-', '.', no leading dot,
/// at most 100 characters; ".sketch.json" is appended when missing. InputError otherwise.
std::string safeSketchFileName(const std::string& name);

}  // namespace sketchnav::ui
