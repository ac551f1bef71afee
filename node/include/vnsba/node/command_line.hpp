// The command line of every executable (vnsba_node, vnsba_plan, vnsba_slicer, vnsba_recorder,
// vnsba_send_goal, vnsba_bench): one way to parse it and one exit code for a usage error.
//
// CLI11 exits with an error code of its own per kind of error (106 a required option missing,
// 109 an argument not expected, ...), and checks required options before it looks for unknown
// ones, so a misspelt flag was reported as the flag it was meant to be missing
// ("--goal is required" for `--goal-pose 1 2`). Here every usage error exits kExitUsage, and
// arguments nobody expected are reported first, each unknown flag named with the nearest known
// one when there is one.
//
// Header-only (CLI11 is): vnsba_plan and vnsba_bench use it without the DDS library.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "vnsba/node/spelling.hpp"

namespace vnsba::node {

// The exit code of every usage error: an unknown or malformed flag, a bad value, a bad config.
inline constexpr int kExitUsage = 2;

namespace command_line_detail {

// Whether a left-over argument is a flag (a negative number is a value: "-6.5").
inline bool looks_like_flag(const std::string& argument) {
  if (argument.size() < 2 || argument[0] != '-') return false;
  char* end = nullptr;
  std::strtod(argument.c_str(), &end);
  return end == nullptr || *end != '\0';
}

// Every flag (with its dashes) and subcommand name of `app` and its subcommands.
inline void collect_names(const CLI::App& app, std::vector<std::string>& flags,
                          std::vector<std::string>& words) {
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
    for (const std::string& name : option->get_snames()) flags.push_back("-" + name);
  }
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    words.push_back(sub->get_name());
    collect_names(*sub, flags, words);
  }
}

// The known flag `flag` was meant to be: the one known flag it abbreviates ("--min" for
// --min-readers), the known flag it extends at a word boundary ("--goal-pose" for --goal), or a
// near miss ("--gaol"); "" when none fits.
inline std::string meant_flag(const std::string& flag, const std::vector<std::string>& known) {
  std::string abbreviated;
  bool ambiguous = false;
  for (const std::string& k : known) {
    if (flag.size() < 5 || k.size() <= flag.size() || k.compare(0, flag.size(), flag) != 0)
      continue;
    ambiguous = !abbreviated.empty();
    abbreviated = k;
  }
  if (!abbreviated.empty() && !ambiguous) return abbreviated;
  std::string extended;
  for (const std::string& k : known) {
    const bool extends = k.size() > 2 && flag.size() > k.size() &&
                         flag.compare(0, k.size(), k) == 0 &&
                         (flag[k.size()] == '-' || flag[k.size()] == '_');
    if (extends && k.size() > extended.size()) extended = k;
  }
  if (!extended.empty()) return extended;
  return closest(flag, known);
}

}  // namespace command_line_detail

// The message for arguments `app` did not expect: every unknown flag named, with the flag it was
// probably meant to be (or, with none, the first stray word, with the subcommand it was probably
// meant to be), then the whole left-over list when there is more.
inline std::string unexpected_arguments_message(const CLI::App& app,
                                                const std::vector<std::string>& left_over) {
  using namespace command_line_detail;
  std::vector<std::string> flags, words;
  collect_names(app, flags, words);
  auto did_you_mean = [](const std::string& meant) {
    return meant.empty() ? std::string() : " (did you mean " + meant + "?)";
  };
  std::string message;
  for (const std::string& argument : left_over) {
    if (!looks_like_flag(argument)) continue;
    const std::string name = argument.substr(0, argument.find('='));
    message += "unknown option " + name + did_you_mean(meant_flag(name, flags)) + "\n";
  }
  if (message.empty())
    message = "unexpected argument " + left_over.front() +
              did_you_mean(closest(left_over.front(), words)) + "\n";
  if (left_over.size() > 1) {
    message += "arguments not expected:";
    for (const std::string& argument : left_over) message += " " + argument;
    message += "\n";
  }
  return message;
}

// Parses the command line into `app`. nullopt: go on. Otherwise the code to exit with: 0 after
// --help (printed to stdout), kExitUsage after a usage error, printed to stderr as
// "<program>: <what>" naming the flag, arguments not expected first.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv) {
  try {
    app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    const std::string program = std::filesystem::path(argc > 0 ? argv[0] : "").filename().string();
    // CLI11 has read every argument before it checks required options and values, so what it
    // could not place is known even when another error came first.
    const std::vector<std::string> left_over = app.remaining(true);
    std::istringstream lines(left_over.empty() ? std::string(e.what())
                                               : unexpected_arguments_message(app, left_over));
    for (std::string line; std::getline(lines, line);) std::cerr << program << ": " << line << "\n";
    std::cerr << "Run with --help for more information.\n";
    return kExitUsage;
  }
}

// How an error message names a value a flag or a config key may have set: the flag when it was
// given, otherwise the key with its file ("slicer.resolution in robot.yaml"), or, without a
// config, the flag's default ("--z-min (default)").
inline std::string value_source(bool flag_given, const std::string& flag, const std::string& key,
                                const std::string& config_file) {
  if (flag_given) return flag;
  if (!config_file.empty()) return key + " in " + config_file;
  return flag + " (default)";
}

}  // namespace vnsba::node
