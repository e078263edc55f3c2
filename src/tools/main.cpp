// `spinradar`: command-line front end to the core. Subcommands live in src/tools/cmd_*.cpp.
#include <algorithm>
#include <exception>
#include <iostream>

#include "cli_checks.hpp"
#include "command.hpp"

namespace spinradar::cli {
std::vector<Command>& commands() {
  static std::vector<Command> list;
  return list;
}
}  // namespace spinradar::cli

int main(int argc, char** argv) {
  using namespace spinradar::cli;
  CLI::App app{"spinradar: spinning FMCW radar odometry, simulation and diagnosis"};
  app.require_subcommand(1);
  auto& list = commands();
  std::sort(list.begin(), list.end(), [](const Command& a, const Command& b) { return a.name < b.name; });
  for (auto& c : list) c.setup(*app.add_subcommand(c.name, c.summary));
  requireFiniteNumbers(app);  // NaN and infinities are never valid, for every option
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
