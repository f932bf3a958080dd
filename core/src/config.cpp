#include "sketchnav/core/config.h"

#include "sketchnav/core/json_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>

namespace sketchnav {
namespace {
void flatten(const Json& j, const std::string& prefix, const std::string& origin,
             std::map<std::string, Json>& out, std::map<std::string, std::string>& origins) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object() && !it->empty()) {
      flatten(*it, key, origin, out, origins);
    } else {
      // An empty object sets nothing but names a key all the same: kept as a value, so a
      // misspelt {"servo": {"lamda": {}}} is an unknown setting like any other (it was
      // accepted without a word), and {} for a setting is a type error.
      out[key] = *it;
      origins[key] = origin;
    }
  }
}
}  // namespace

Config Config::fromJson(const Json& j, const std::string& origin) {
  if (!j.is_object()) throw InputError(origin + ": a config must be a JSON object");
  Config c;
  flatten(j, "", origin, c.values_, c.origins_);
  return c;
}

Config Config::fromFile(const std::string& path) {
  return fromJson(parseJsonFile(path, "config file"), path);
}

void Config::set(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set '" + assignment + "': expected key=value");
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  Json v = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (v.is_discarded()) v = text;
  set(key, v);
  origins_[key] = "--set " + key;
}

void Config::set(const std::string& key, const Json& value) {
  values_[key] = value;
  if (!origins_.count(key)) origins_[key] = "<code>";
}

bool Config::has(const std::string& key) const {
  return values_.count(key) != 0;
}

const Json& Config::at(const std::string& key) const {
  auto it = values_.find(key);
  if (it == values_.end()) throw InputError("missing setting '" + key + "'");
  return it->second;
}

std::vector<std::string> Config::keys(const std::string& prefix) const {
  std::vector<std::string> out;
  for (const auto& [k, v] : values_)
    if (prefix.empty() || k.rfind(prefix + ".", 0) == 0) out.push_back(k);
  return out;
}

void Config::markUsed(const std::string& key) const {
  usage_->used.insert(key);
  usage_->known.insert(key);
}

void Config::markKnown(const std::string& key) const {
  usage_->known.insert(key);
}

std::vector<std::string> Config::unusedKeys(const std::string& prefix) const {
  std::vector<std::string> out;
  for (const auto& k : keys(prefix)) {
    if (usage_->used.count(k)) continue;
    // An empty section of known settings ({"nav": {}}) is not a setting of its own.
    const Json& v = values_.at(k);
    if (v.is_object() && v.empty()) {
      const auto below = usage_->known.lower_bound(k + ".");
      if (below != usage_->known.end() && below->rfind(k + ".", 0) == 0) continue;
    }
    out.push_back(k);
  }
  return out;
}

std::vector<std::string> Config::knownKeys() const {
  return {usage_->known.begin(), usage_->known.end()};
}

std::string Config::unknownSettingMessage(const std::string& key) const {
  std::string msg = origin(key) + ": unknown setting '" + key + "'";
  const std::string best = closestKey(key, knownKeys());
  if (!best.empty())
    msg += " (did you mean '" + best + "'?)";
  else
    msg += " (this command takes no settings)";
  return msg;
}

void Config::requireAllUsed(const std::string& prefix) const {
  const auto unused = unusedKeys(prefix);
  if (!unused.empty()) throw InputError(unknownSettingMessage(unused.front()));
}

void Config::requireAllUsedExcept(const std::vector<std::string>& deferred) const {
  for (const auto& k : unusedKeys()) {
    bool later = false;
    for (const auto& p : deferred) later = later || k.rfind(p, 0) == 0;
    if (!later) throw InputError(unknownSettingMessage(k));
  }
}

std::string closestKey(const std::string& key, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_d = std::numeric_limits<size_t>::max();
  std::vector<size_t> prev, cur;
  for (const auto& c : candidates) {
    // Levenshtein distance, two rows.
    prev.resize(c.size() + 1);
    cur.resize(c.size() + 1);
    for (size_t j = 0; j <= c.size(); ++j) prev[j] = j;
    for (size_t i = 1; i <= key.size(); ++i) {
      cur[0] = i;
      for (size_t j = 1; j <= c.size(); ++j)
        cur[j] =
            std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (key[i - 1] == c[j - 1] ? 0 : 1)});
      std::swap(prev, cur);
    }
    if (prev[c.size()] < best_d) {
      best_d = prev[c.size()];
      best = c;
    }
  }
  return best;
}

const std::string& Config::origin(const std::string& key) const {
  static const std::string unknown = "<config>";
  auto it = origins_.find(key);
  return it == origins_.end() ? unknown : it->second;
}

Json Config::toJson() const {
  Json out = Json::object();
  for (const auto& [k, v] : values_) {
    Json* node = &out;
    std::stringstream ss(k);
    std::string part;
    std::vector<std::string> parts;
    while (std::getline(ss, part, '.')) parts.push_back(part);
    for (size_t i = 0; i + 1 < parts.size(); ++i) node = &(*node)[parts[i]];
    (*node)[parts.back()] = v;
  }
  return out;
}

namespace detail {
bool wholeNumberWithin(const Json& v, long double lo, long double hi) {
  long double x = 0;
  if (v.is_number_unsigned())
    x = static_cast<long double>(v.get<std::uint64_t>());
  else if (v.is_number_integer())
    x = static_cast<long double>(v.get<std::int64_t>());
  else if (v.is_number_float())
    x = static_cast<long double>(v.get<double>());
  else
    return false;
  return std::isfinite(x) && x == std::floor(x) && x >= lo && x <= hi;
}
}  // namespace detail

void rejectRenamed(const Config& config, const std::string& old_key, const std::string& new_key,
                   const std::string& why) {
  if (config.has(old_key))
    throw InputError(config.origin(old_key) + ": setting '" + old_key + "' is now '" + new_key +
                     "' (" + why + ")");
}

void require(bool ok, const std::string& field, const std::string& why) {
  if (!ok) throw InputError("invalid setting '" + field + "': " + why);
}

}  // namespace sketchnav
