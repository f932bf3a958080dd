#include "cli.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <sstream>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"

namespace sketchnav::app {

Args::Args(std::string command, std::string summary, std::string usage)
    : command_(std::move(command)), summary_(std::move(summary)), usage_(std::move(usage)) {}

Args& Args::option(const std::string& name, const std::string& help, const std::string& def) {
  opts_[name] = Opt{help, def, false};
  order_.push_back(name);
  return *this;
}

Args& Args::flag(const std::string& name, const std::string& help) {
  opts_[name] = Opt{help, "", true};
  order_.push_back(name);
  return *this;
}

Args& Args::positionals(const std::string& name, const std::string& help, int min, int max) {
  pos_name_ = name;
  pos_help_ = help;
  pos_min_ = min;
  pos_max_ = max;
  return *this;
}

bool Args::parse(const std::vector<std::string>& argv) {
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << helpText();
      return false;
    }
    if (a.rfind("--", 0) == 0 && a.size() > 2) {
      std::string name = a.substr(2), value;
      bool has_value = false;
      if (auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        has_value = true;
      }
      auto it = opts_.find(name);
      if (it == opts_.end())
        throw InputError("sketchnav " + command_ + ": unknown option '--" + name +
                         "' (see sketchnav " + command_ + " --help)");
      if (it->second.is_flag) {
        if (has_value)
          throw InputError("sketchnav " + command_ + ": --" + name + " takes no value");
        values_[name] = "1";
      } else {
        if (!has_value) {
          if (i + 1 >= argv.size())
            throw InputError("sketchnav " + command_ + ": --" + name + " needs a value");
          value = argv[++i];
        }
        values_[name] = value;
      }
    } else {
      positional_.push_back(a);
    }
  }
  const int n = static_cast<int>(positional_.size());
  if (n < pos_min_ || (pos_max_ >= 0 && n > pos_max_)) {
    if (pos_max_ == 0)
      throw InputError("sketchnav " + command_ + ": unexpected argument '" + positional_.front() +
                       "'");
    throw InputError("sketchnav " + command_ + ": expected " +
                     (pos_min_ == pos_max_
                          ? std::to_string(pos_min_)
                          : std::to_string(pos_min_) +
                                (pos_max_ < 0 ? " or more" : " to " + std::to_string(pos_max_))) +
                     " " + pos_name_ + " argument(s), got " + std::to_string(n));
  }
  return true;
}

std::string Args::get(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  if (auto it = opts_.find(name); it != opts_.end()) return it->second.def;
  throw std::logic_error("option not declared: " + name);
}

bool Args::has(const std::string& name) const {
  return values_.count(name) || (opts_.count(name) && !opts_.at(name).def.empty());
}

bool Args::flagSet(const std::string& name) const {
  return values_.count(name) != 0;
}

double Args::getDouble(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  errno = 0;
  const double d = std::strtod(v.c_str(), &end);
  // strtod also takes "nan", "inf" and overflows to HUGE_VAL: no option means any of them
  // (`--max-time nan` ran with the default time before).
  if (v.empty() || *end != '\0' || !std::isfinite(d) || errno == ERANGE)
    throw InputError("sketchnav " + command_ + ": --" + name + " expects a finite number, got '" +
                     clipForMessage(v) + "'");
  return d;
}

int Args::getInt(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  errno = 0;
  const long d = std::strtol(v.c_str(), &end, 10);
  // Out of int's range is an error, not a wrapped value (4294967297 became 1).
  if (v.empty() || *end != '\0' || errno == ERANGE || d < std::numeric_limits<int>::min() ||
      d > std::numeric_limits<int>::max())
    throw InputError("sketchnav " + command_ + ": --" + name + " expects an integer in [" +
                     std::to_string(std::numeric_limits<int>::min()) + ", " +
                     std::to_string(std::numeric_limits<int>::max()) + "], got '" +
                     clipForMessage(v) + "'");
  return static_cast<int>(d);
}

std::vector<std::string> Args::getList(const std::string& name) const {
  std::vector<std::string> out;
  std::stringstream ss(get(name));
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string Args::helpText() const {
  std::ostringstream o;
  o << "sketchnav " << command_ << " — " << summary_ << "\n\nUsage: sketchnav " << command_ << " "
    << usage_ << "\n";
  if (!pos_name_.empty()) o << "\n  " << pos_name_ << "  " << pos_help_ << "\n";
  if (!order_.empty()) o << "\nOptions:\n";
  for (const auto& name : order_) {
    const Opt& opt = opts_.at(name);
    std::string left = "--" + name + (opt.is_flag ? "" : " VALUE");
    o << "  " << left;
    for (size_t i = left.size(); i < 26; ++i) o << ' ';
    o << " " << opt.help;
    if (!opt.def.empty()) o << " (default: " << opt.def << ")";
    o << "\n";
  }
  o << "\nGlobal options: --verbose, --log-file FILE, --json, --config FILE, --set key=value\n";
  return o.str();
}

std::map<std::string, CommandInfo>& commands() {
  static std::map<std::string, CommandInfo> c;
  return c;
}

CommandRegistration::CommandRegistration(std::string name, std::string summary, CommandFn fn) {
  commands()[name] = CommandInfo{name, std::move(summary), std::move(fn)};
}

int notAvailable(const std::string& command, const std::string& what, int issue) {
  std::cerr << "sketchnav " << command << ": not available yet: " << what
            << " has not landed (issue #" << issue << ")\n";
  return 1;
}

void printJson(const Json& j) {
  std::cout << j.dump(2) << std::endl;
}

}  // namespace sketchnav::app
