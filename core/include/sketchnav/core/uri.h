#pragma once
// Device URIs: "scheme://authority/path?key=value&key=value".
//   sim://lab?seed=3    folder:///data/frames?fps=10    video:///clip.mp4    video://0
//   aravis://192.168.1.10    dani://192.168.1.20:5000
#include <map>
#include <string>

namespace sketchnav {

struct Uri {
  std::string text;       // the URI as given
  std::string scheme;     // lower case, e.g. "folder"
  std::string authority;  // "host:port", a device id, or empty for "scheme:///path"
  std::string path;       // "/abs/path" (percent-decoded)
  std::map<std::string, std::string> query;

  /// Throws InputError naming the URI when it has no "scheme://" or a malformed query.
  static Uri parse(const std::string& text);

  bool hasParam(const std::string& k) const { return query.count(k) != 0; }
  std::string param(const std::string& k, const std::string& def) const;
  double paramDouble(const std::string& k, double def) const;  // InputError when not a number
  int paramInt(const std::string& k, int def) const;
  /// Host and port from the authority ("host:port"); InputError when the port is missing/bad.
  std::string host() const;
  int port() const;
};

}  // namespace sketchnav
