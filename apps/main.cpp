// sketchnav: the command-line entry point. Parses the global options, dispatches to the
// registered subcommand, and is the one place where errors become exit codes:
// 0 ok, 1 runtime failure, 2 bad usage or input.
#include <opencv2/core/utility.hpp>

#include <exception>
#include <iostream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"

using namespace sketchnav;

namespace {
void printUsage() {
  std::cout << "sketchnav — navigate a mobile robot with an inaccurate, hand-drawn map\n\n"
               "Usage: sketchnav [global options] <subcommand> [options]\n\nSubcommands:\n";
  for (const auto& [name, info] : app::commands()) {
    std::cout << "  " << name;
    for (size_t i = name.size(); i < 15; ++i) std::cout << ' ';
    std::cout << info.summary << "\n";
  }
  std::cout << "\nGlobal options:\n"
               "  --verbose          debug-level log lines on stderr\n"
               "  --log-file FILE    also append every log line to FILE\n"
               "  --json             print the subcommand's figures as one JSON object on stdout\n"
               "  --config FILE      JSON settings file overriding any Params field\n"
               "  --set key=value    override one setting (e.g. --set servo.lambda=0.4)\n\n"
               "`sketchnav <subcommand> --help` describes each subcommand.\n";
}
}  // namespace

int main(int argc, char** argv) {
  // One thread for OpenCV: the pipeline is sized for one core per process and parallel
  // sweeps run one process (or thread) per scenario.
  cv::setNumThreads(1);
  std::vector<std::string> rest;
  app::GlobalOptions g;
  std::string sub;
  try {
    std::vector<std::string> sets;
    std::string config_file;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto value = [&](const std::string& name) -> std::string {
        if (i + 1 >= argc) throw InputError(name + " needs a value");
        return argv[++i];
      };
      if (a == "--verbose")
        g.verbose = true;
      else if (a == "--json")
        g.json = true;
      else if (a == "--log-file")
        g.log_file = value(a);
      else if (a.rfind("--log-file=", 0) == 0)
        g.log_file = a.substr(11);
      else if (a == "--config")
        config_file = value(a);
      else if (a.rfind("--config=", 0) == 0)
        config_file = a.substr(9);
      else if (a == "--set")
        sets.push_back(value(a));
      else if (a.rfind("--set=", 0) == 0)
        sets.push_back(a.substr(6));
      else if (sub.empty() && (a == "--help" || a == "-h" || a == "help")) {
        printUsage();
        return 0;
      } else if (sub.empty() && a == "--version") {
        std::cout << "sketchnav " << SKETCHNAV_VERSION << "\n";
        return 0;
      } else if (sub.empty() && a.rfind("-", 0) != 0)
        sub = a;
      else
        rest.push_back(a);
    }
    if (!config_file.empty()) g.config = Config::fromFile(config_file);
    for (const auto& s : sets) g.config.set(s);
    log::setLevel(g.verbose ? log::Level::Debug : log::Level::Info);
    if (!g.log_file.empty()) log::setFile(g.log_file);
    if (sub.empty()) {
      printUsage();
      return 2;
    }
    auto it = app::commands().find(sub);
    if (it == app::commands().end())
      throw InputError("unknown subcommand '" + sub + "' (see sketchnav --help)");
    const int rc = it->second.run(rest, g);
    // Each subcommand applies every setting it uses and checks none is left before its work;
    // this is the backstop for one that does not: a setting nothing read is never accepted.
    g.config.requireAllUsed();
    return rc;
  } catch (const InputError& e) {
    std::cerr << "sketchnav: error: " << e.what() << "\n";
    return 2;
  } catch (const NotImplementedError& e) {
    std::cerr << "sketchnav: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "sketchnav: failed: " << e.what() << "\n";
    return 1;
  }
}
