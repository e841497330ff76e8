// The command table (commands/table.cpp) that app/main.cpp registers: every subcommand of the
// program is one row with a help line, each row registers its own options on a CLI11
// subcommand, and the program's help lists them all (docs/design.md, "Where things live": the
// recipe for adding a command).

#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "commands/common.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

const std::vector<std::string> kCommands = {"check", "run",       "capacity", "pushover",
                                            "limit", "spread",    "pulse",    "ida",
                                            "sweep", "stability", "synth",    "keys"};

TEST(CommandTable, ListsEveryCommandOnceWithAHelpLine) {
  std::vector<std::string> names;
  for (const Command& c : command_table()) {
    names.emplace_back(c.name);
    EXPECT_GT(std::string(c.help).size(), 10u) << c.name;
    EXPECT_NE(c.add, nullptr) << c.name;
  }
  EXPECT_EQ(names, kCommands);
}

TEST(CommandTable, EachRowRegistersItsOptionsAndAnAction) {
  CLI::App app{"test"};
  CommandLine line;
  for (const Command& c : command_table()) {
    CLI::App* cmd = app.add_subcommand(c.name, c.help);
    const CommandAction action = c.add(*cmd, line);
    EXPECT_TRUE(static_cast<bool>(action.run)) << c.name;
    if (std::string(c.name) != "keys") {
      EXPECT_FALSE(cmd->get_options().empty()) << c.name;
    }
  }
  // The commands that read a deck take it as their positional argument.
  app.parse("capacity deck.toml --threads 2", false);
  EXPECT_EQ(line.deck, "deck.toml");
  EXPECT_EQ(line.common.threads, 2);
}

TEST(CommandTable, TheProgramsHelpListsEveryCommand) {
  const std::string scratch =
      (std::filesystem::temp_directory_path() / "voussoir_command_table_help").string();
  const testing::ProcessResult r = testing::run_process({VOUSSOIR_BINARY, "--help"}, {}, scratch);
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  for (const Command& c : command_table()) {
    EXPECT_NE(r.out.find(std::string("  ") + c.name), std::string::npos) << c.name;
    EXPECT_NE(r.out.find(c.help), std::string::npos) << c.name;
  }
}

}  // namespace
}  // namespace voussoir
