#include "sketchnav/core/uri.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "sketchnav/core/error.h"

namespace sketchnav {
namespace {
std::string percentDecode(const std::string& s, const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%') {
      if (i + 2 >= s.size() || !std::isxdigit(static_cast<unsigned char>(s[i + 1])) ||
          !std::isxdigit(static_cast<unsigned char>(s[i + 2])))
        throw InputError("URI '" + uri + "': bad percent escape");
      out += static_cast<char>(std::strtol(s.substr(i + 1, 2).c_str(), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}
}  // namespace

Uri Uri::parse(const std::string& text) {
  Uri u;
  u.text = text;
  const auto sep = text.find("://");
  if (sep == std::string::npos || sep == 0)
    throw InputError("URI '" + text + "': expected scheme://... (e.g. folder:///path, sim://lab)");
  u.scheme = text.substr(0, sep);
  for (char c : u.scheme)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '+' && c != '-' && c != '.')
      throw InputError("URI '" + text + "': bad scheme '" + u.scheme + "'");
  std::transform(u.scheme.begin(), u.scheme.end(), u.scheme.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string rest = text.substr(sep + 3);
  std::string query;
  if (auto q = rest.find('?'); q != std::string::npos) {
    query = rest.substr(q + 1);
    rest = rest.substr(0, q);
  }
  const auto slash = rest.find('/');
  u.authority = percentDecode(rest.substr(0, slash), text);
  if (slash != std::string::npos) u.path = percentDecode(rest.substr(slash), text);
  size_t pos = 0;
  while (pos < query.size()) {
    auto amp = query.find('&', pos);
    if (amp == std::string::npos) amp = query.size();
    const std::string kv = query.substr(pos, amp - pos);
    if (!kv.empty()) {
      const auto eq = kv.find('=');
      if (eq == 0) throw InputError("URI '" + text + "': empty parameter name");
      const std::string k = percentDecode(kv.substr(0, eq), text);
      const std::string v = eq == std::string::npos ? "1" : percentDecode(kv.substr(eq + 1), text);
      u.query[k] = v;
    }
    pos = amp + 1;
  }
  return u;
}

std::string Uri::param(const std::string& k, const std::string& def) const {
  auto it = query.find(k);
  return it == query.end() ? def : it->second;
}

double Uri::paramDouble(const std::string& k, double def) const {
  auto it = query.find(k);
  if (it == query.end()) return def;
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  if (end == it->second.c_str() || *end != '\0')
    throw InputError("URI '" + text + "': parameter '" + k + "' is not a number");
  return v;
}

int Uri::paramInt(const std::string& k, int def) const {
  auto it = query.find(k);
  if (it == query.end()) return def;
  char* end = nullptr;
  const long v = std::strtol(it->second.c_str(), &end, 10);
  if (end == it->second.c_str() || *end != '\0')
    throw InputError("URI '" + text + "': parameter '" + k + "' is not an integer");
  return static_cast<int>(v);
}

std::string Uri::host() const {
  const auto colon = authority.rfind(':');
  return colon == std::string::npos ? authority : authority.substr(0, colon);
}

int Uri::port() const {
  const auto colon = authority.rfind(':');
  if (colon == std::string::npos) throw InputError("URI '" + text + "': expected host:port");
  char* end = nullptr;
  const std::string p = authority.substr(colon + 1);
  const long v = std::strtol(p.c_str(), &end, 10);
  if (p.empty() || *end != '\0' || v <= 0 || v > 65535)
    throw InputError("URI '" + text + "': bad port '" + p + "'");
  return static_cast<int>(v);
}

}  // namespace sketchnav
