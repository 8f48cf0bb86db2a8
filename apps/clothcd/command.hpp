#pragma once
// Subcommand registry of the clothcd tool: each cmd_*.cpp file registers one subcommand with a
// static `const bool registered = register_command(...)`.

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace clothcd::app {

/// Adds the subcommand's options to `sub`; returns the action to run once the line is parsed.
/// The action returns the process exit code; it throws clothcd::InputError on bad input.
using CommandSetup = std::function<std::function<int()>(CLI::App& sub)>;

struct Command {
  std::string name;
  std::string description;
  CommandSetup setup;
};

std::vector<Command>& command_registry();

inline bool register_command(std::string name, std::string description, CommandSetup setup) {
  command_registry().push_back({std::move(name), std::move(description), std::move(setup)});
  return true;
}

}  // namespace clothcd::app
