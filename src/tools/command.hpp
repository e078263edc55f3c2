#pragma once
// Subcommands of the `spinradar` CLI register themselves: one file per subcommand,
// `SPINRADAR_COMMAND(name, "summary", setup)` where setup(CLI::App&) adds options and a
// callback. Throwing std::exception from the callback prints "error: ..." and exits 1.
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace spinradar::cli {

struct Command {
  std::string name;
  std::string summary;
  std::function<void(CLI::App&)> setup;
};

std::vector<Command>& commands();

struct CommandRegistrar {
  CommandRegistrar(std::string name, std::string summary, std::function<void(CLI::App&)> setup) {
    commands().push_back({std::move(name), std::move(summary), std::move(setup)});
  }
};

}  // namespace spinradar::cli

#define SPINRADAR_CAT2(a, b) a##b
#define SPINRADAR_CAT(a, b) SPINRADAR_CAT2(a, b)
#define SPINRADAR_COMMAND(name, summary, setup)                                    \
  static ::spinradar::cli::CommandRegistrar SPINRADAR_CAT(spinradar_cmd_, __LINE__)( \
      name, summary, setup)
