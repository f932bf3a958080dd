#include "entry_points.h"

// Eigen (through sketch.h) before httplib.h (server.h): a macro of httplib's breaks Eigen.
#include "sketchnav/mapsketch/sketch.h"
// clang-format off
#include "run_request.h"
#include "server.h"
#include "sketchnav/core/error.h"
// clang-format on

namespace sketchnav::fuzz {

// The JSON bodies the web UI's server parses, without a server: the body check
// (parseJsonBody: UTF-8, JSON), then each POST route's validation of it (run start, capture,
// the editor's sketch save / route preview), and the names taken from the URL.
void webui(const std::uint8_t* d, std::size_t n) {
  httplib::Request req;
  req.body = text(d, n);
  refusedIsFine([&] {
    const Json j = ui::parseJsonBody(req, "run request");
    refusedIsFine([&] {
      const ui::RunRequest r = ui::RunRequest::fromJson(j);
      // What the page gets back must be accepted again.
      (void)ui::RunRequest::fromJson(r.toJson());
    });
    refusedIsFine([&] {
      const ui::CaptureRequest c = ui::CaptureRequest::fromJson(j);
      (void)ui::safeClassName(c.class_name);
    });
  });
  refusedIsFine([&] { (void)ui::sketchFromBody(req.body, "sketch", {"Left", "Right", "Ball"}); });
  // A byte offset is chosen by the input too: jsonFieldAt() is called on arbitrary offsets.
  (void)ui::jsonFieldAt(req.body, n > 0 ? d[0] % (n + 1) : 0);
  const std::string first = req.body.substr(0, req.body.find('\n'));
  refusedIsFine([&] { (void)ui::safeSketchFileName(first); });
}

}  // namespace sketchnav::fuzz
