// clothcd: collision detection for thin deformable objects, from the command line.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>

#include "clothcd/core/error.hpp"
#include "command.hpp"

namespace clothcd::app {
std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}
}  // namespace clothcd::app

int main(int argc, char** argv) {
  using clothcd::app::command_registry;
  CLI::App app{"clothcd: collision detection for thin deformable objects (cloth, garments, shells)",
               "clothcd"};
  app.require_subcommand(1);
  auto& commands = command_registry();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<CLI::App*, std::function<int()>> actions;
  for (const auto& cmd : commands) {
    CLI::App* sub = app.add_subcommand(cmd.name, cmd.description);
    actions[sub] = cmd.setup(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (auto& [sub, action] : actions) {
      if (sub->parsed()) return action();
    }
  } catch (const clothcd::InputError& e) {
    fmt::print(stderr, "clothcd: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "clothcd: error: {}\n", e.what());
    return 1;
  }
  return 1;
}
