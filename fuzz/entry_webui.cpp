#include "entry_points.h"

#include <cmath>

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
      // An accepted seed is the number sent (not wrapped into int); what the page gets back
      // must be accepted again.
      if (j.contains("seed") && Json(r.seed) != j["seed"]) __builtin_trap();
      (void)ui::RunRequest::fromJson(r.toJson());
    });
    refusedIsFine([&] {
      const ui::CaptureRequest c = ui::CaptureRequest::fromJson(j);
      // An accepted box is the numbers sent, rounded to pixels.
      if (c.box) {
        const int got[4] = {c.box->x, c.box->y, c.box->width, c.box->height};
        for (int i = 0; i < 4; ++i)
          if (!(std::abs(got[i] - j["box"][i].get<double>()) <= 0.5)) __builtin_trap();
      }
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
