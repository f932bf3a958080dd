#pragma once
// Settings as plain Params structs (defaults in place, units in comments, one validate() that
// names the bad field). A Config is the separate loading step: a JSON file (--config) plus
// key=value overrides (--set servo.lambda=0.4), flattened to dotted keys.
//
// A Params struct exposes its fields through `template <class B> void bind(B& b)` calling
// b("name", field) for each field; applyConfig() then overrides fields from a Config section
// and calls validate(). Every bound field is recorded as a known key and every applied one as
// used, so after a command has applied all the Params it uses, requireAllUsed() turns a typo or
// a setting the command does not use into an error naming the closest known key.
#include <nlohmann/json.hpp>

#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "sketchnav/core/error.h"

namespace sketchnav {

using Json = nlohmann::json;

class Config {
 public:
  Config() = default;
  /// Loads a JSON object from `path`; throws InputError naming the file on any problem.
  static Config fromFile(const std::string& path);
  /// Builds from a JSON object (nested objects are flattened to dotted keys).
  static Config fromJson(const Json& j, const std::string& origin = "<json>");

  /// Applies "a.b.c=value"; value is parsed as JSON when it is valid JSON, else a string.
  void set(const std::string& assignment);
  void set(const std::string& key, const Json& value);

  bool has(const std::string& key) const;
  const Json& at(const std::string& key) const;  // throws InputError when absent
  /// The keys under `prefix.` (prefix empty = all keys).
  std::vector<std::string> keys(const std::string& prefix = "") const;
  /// Marks a key as consumed (and known); unusedKeys() returns the rest (typos, stale settings).
  /// Copies of a Config share this record, so a copy handed to a device or a library counts.
  void markUsed(const std::string& key) const;
  /// Records a key some Params could take (applyConfig records every bound field), for the
  /// "did you mean" of requireAllUsed().
  void markKnown(const std::string& key) const;
  std::vector<std::string> unusedKeys(const std::string& prefix = "") const;
  /// Every key recorded by markKnown() / markUsed() so far, sorted.
  std::vector<std::string> knownKeys() const;
  /// The one-line error for an unused key: "<origin>: unknown setting 'servo.lamda' (did you
  /// mean 'servo.lambda'?)" - the closest known key by edit distance, when one is known.
  std::string unknownSettingMessage(const std::string& key) const;
  /// Throws InputError (unknownSettingMessage) for the first unused key under `prefix`.
  void requireAllUsed(const std::string& prefix = "") const;
  /// The same over all keys except those under the `deferred` prefixes (e.g. "base." for the
  /// settings of a device driver, applied only when the device is opened).
  void requireAllUsedExcept(const std::vector<std::string>& deferred) const;

  const std::string& origin(const std::string& key) const;
  Json toJson() const;  // nested form

 private:
  std::map<std::string, Json> values_;
  std::map<std::string, std::string> origins_;
  struct Usage {
    std::set<std::string> used, known;
  };
  std::shared_ptr<Usage> usage_ = std::make_shared<Usage>();
};

/// The candidate nearest to `key` by edit distance (Levenshtein over characters; ties: the first
/// in order); "" when `candidates` is empty.
std::string closestKey(const std::string& key, const std::vector<std::string>& candidates);

namespace detail {
/// True when `v` is a whole number within [lo, hi] (an integer, or a float with no fraction).
bool wholeNumberWithin(const Json& v, long double lo, long double hi);

template <class T>
void assignFromJson(T& field, const Json& v, const std::string& key, const std::string& origin) {
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    // The JSON library converts any number to any integer type: -1 became 18446744073709551615
    // in sim.seed, 2.7 became 2 and 4294967297 became 1 in an int.
    if (v.is_number() &&
        !wholeNumberWithin(v, static_cast<long double>(std::numeric_limits<T>::min()),
                           static_cast<long double>(std::numeric_limits<T>::max())))
      throw InputError(origin + ": setting '" + key + "' must be a whole number in [" +
                       std::to_string(std::numeric_limits<T>::min()) + ", " +
                       std::to_string(std::numeric_limits<T>::max()) + "] (got " + v.dump() + ")");
  }
  try {
    field = v.get<T>();
  } catch (const std::exception&) {
    throw InputError(origin + ": setting '" + key + "' has the wrong type (got " + v.dump() + ")");
  }
}

class ConfigApplier {
 public:
  ConfigApplier(const Config& c, std::string prefix) : c_(c), prefix_(std::move(prefix)) {}
  template <class T>
  void operator()(const char* name, T& field) {
    const std::string key = prefix_.empty() ? name : prefix_ + "." + name;
    c_.markKnown(key);
    if (!c_.has(key)) return;
    c_.markUsed(key);
    assignFromJson(field, c_.at(key), key, c_.origin(key));
  }

 private:
  const Config& c_;
  std::string prefix_;
};

class JsonDumper {
 public:
  explicit JsonDumper(Json& out) : out_(out) {}
  template <class T>
  void operator()(const char* name, T& field) {
    out_[name] = field;
  }

 private:
  Json& out_;
};
}  // namespace detail

/// Overrides fields of `params` from `config` keys under `prefix` (e.g. "servo"), then calls
/// params.validate(). Throws InputError naming the key on a type error or invalid value.
template <class P>
void applyConfig(P& params, const Config& config, const std::string& prefix) {
  detail::ConfigApplier a(config, prefix);
  params.bind(a);
  params.validate();
}

/// The params as a JSON object (for summaries: a run is reproducible from its summary).
template <class P>
Json paramsToJson(const P& params) {
  Json j = Json::object();
  detail::JsonDumper d(j);
  const_cast<P&>(params).bind(d);
  return j;
}

/// Helper for validate(): throws InputError "<owner>.<field> = <value>: <why>" when !ok.
void require(bool ok, const std::string& field, const std::string& why);

/// A setting that has a new name: throws InputError "<origin>: setting '<old_key>' is now
/// '<new_key>' (<why>)" when `config` holds `old_key`.
void rejectRenamed(const Config& config, const std::string& old_key, const std::string& new_key,
                   const std::string& why);

}  // namespace sketchnav
