#pragma once
// The `sketchnav` command's plumbing: a tiny argument parser and the subcommand registry.
// Each subcommand lives in its own cmd_<name>.cpp and registers itself with a static
// CommandRegistration, so adding one touches no shared switch.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sketchnav/core/config.h"

namespace sketchnav::app {

/// Options shared by every subcommand (given before or after the subcommand name).
struct GlobalOptions {
  bool verbose = false;
  bool json = false;
  std::string log_file;
  Config config;  // --config FILE and --set key=value, in order
};

/// Declarative options for one subcommand: declare, then parse(); --help prints them.
class Args {
 public:
  Args(std::string command, std::string summary, std::string usage);
  /// An option with a value (--name VALUE or --name=VALUE).
  Args& option(const std::string& name, const std::string& help, const std::string& def = "");
  /// A boolean flag (--name).
  Args& flag(const std::string& name, const std::string& help);
  /// Named positional arguments; `min`..`max` of them (max -1 = unbounded).
  Args& positionals(const std::string& name, const std::string& help, int min, int max);

  /// Parses argv (after the subcommand). Throws InputError on unknown options / bad counts.
  /// Returns false when --help was printed.
  bool parse(const std::vector<std::string>& argv);

  std::string get(const std::string& name) const;
  bool has(const std::string& name) const;  // given on the command line (or a default exists)
  bool flagSet(const std::string& name) const;
  double getDouble(const std::string& name) const;  // InputError naming the option
  int getInt(const std::string& name) const;
  /// Comma separated list ("10,100,1000").
  std::vector<std::string> getList(const std::string& name) const;
  const std::vector<std::string>& positional() const { return positional_; }
  std::string helpText() const;

 private:
  struct Opt {
    std::string help, def;
    bool is_flag = false;
  };
  std::string command_, summary_, usage_;
  std::map<std::string, Opt> opts_;
  std::vector<std::string> order_;
  std::map<std::string, std::string> values_;
  std::string pos_name_, pos_help_;
  int pos_min_ = 0, pos_max_ = 0;
  std::vector<std::string> positional_;
};

using CommandFn = std::function<int(const std::vector<std::string>& argv, GlobalOptions& g)>;

struct CommandInfo {
  std::string name;
  std::string summary;  // one line, for `sketchnav --help`
  CommandFn run;        // returns the exit code: 0 ok, 1 runtime failure, 2 bad usage/input
};

std::map<std::string, CommandInfo>& commands();

struct CommandRegistration {
  CommandRegistration(std::string name, std::string summary, CommandFn fn);
};

/// For subcommands whose capability has not landed: says so and exits non-zero.
int notAvailable(const std::string& command, const std::string& what, int issue);

/// Prints `j` on stdout as one JSON object (the --json contract).
void printJson(const Json& j);

}  // namespace sketchnav::app
