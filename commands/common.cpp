// What every deck command shares on the command line: the common options, the deck, and the
// folders of the output files (commands/common.hpp).

#include "commands/common.hpp"

#include <omp.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <set>
#include <string>
#include <system_error>

#include "engine/solver_report.hpp"
#include "io/deck.hpp"

namespace voussoir {

void add_common(CLI::App& cmd, CommandLine& line) {
  cmd.add_option("deck", line.deck, "input deck (TOML)")->required();
  cmd.add_option("--set", line.sets, "override a deck key: --set model.embrace=150 (repeatable)")
      ->allow_extra_args(false);
  cmd.add_option("--threads", line.common.threads, "OpenMP threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd.add_option("--json", line.common.json_path, "write a JSON summary to FILE ('-' for stdout)");
  cmd.add_flag("-q,--quiet", line.common.quiet, "no progress on stderr");
}

Config load_command_deck(const CommandLine& line) {
  return load_deck(line.deck, line.sets);
}

// Options whose value is a file written by the command; synth's --spectrum names a spectrum,
// pulse's a CSV.
void make_output_folders(const CLI::App& cmd) {
  static const std::set<std::string> kFiles = {
      "--json",     "--mesh-out", "--output",       "--checkpoint",    "--picture",
      "--mode-out", "--movie",    "--csv",          "--mechanism-out", "--series",
      "--plot",     "--resume",   "--spectrum-plot"};
  for (const CLI::Option* opt : cmd.get_options()) {
    const std::string name = opt->get_name();
    const bool file = kFiles.count(name) > 0 || (name == "--spectrum" && cmd.get_name() == "pulse");
    if (!file || opt->count() == 0) continue;
    for (const std::string& value : opt->results()) {
      if (value.empty() || value == "-") continue;
      const std::filesystem::path folder = std::filesystem::path(value).parent_path();
      if (folder.empty()) continue;
      std::error_code ec;
      std::filesystem::create_directories(folder, ec);
      if (!std::filesystem::is_directory(folder))  // another rank may have made it meanwhile
        throw DeckError(name + " " + value + ": cannot create the folder " + folder.string() +
                        (ec ? ": " + ec.message() : ""));
    }
  }
}

int run_parsed_command(const CLI::App& cmd, const CommandLine& line, const CommandAction& action) {
  make_output_folders(cmd);
  if (line.common.threads > 0) omp_set_num_threads(line.common.threads);
  reset_solver_record();
  return action.run();
}

}  // namespace voussoir
