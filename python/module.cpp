// _voussoir: the C++ half of the Python module `voussoir` (python/voussoir/__init__.py,
// docs/guide/python.md). It runs a subcommand of the command table (commands/table.cpp) in
// this process, from the same argument list the program parses, with the GIL released; it
// lists the table's commands and options, from which the package makes one function per
// command; and it carries the stop request of Ctrl-C (engine/stop.hpp).

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "commands/common.hpp"
#include "engine/stop.hpp"
#include "io/deck.hpp"
#include "voussoir/config.hpp"

namespace py = pybind11;

namespace voussoir {
namespace {

const Command& command_named(const std::string& name) {
  for (const Command& c : command_table())
    if (name == c.name) return c;
  throw DeckError("no command `" + name + "` (voussoir --help lists them)");
}

// Parses `args` (the program's arguments after its name: the command first) and runs the
// command as app/main.cpp does in one process. Exceptions as the program's: CLI::ParseError and
// DeckError for bad input, the rest a failure during the run.
int parse_and_run(const std::vector<std::string>& args) {
  if (args.empty()) throw DeckError("no command given");
  const Command& command = command_named(args.front());
  CLI::App app{"voussoir"};
  app.require_subcommand(1);
  CommandLine line;
  CLI::App* cmd = app.add_subcommand(command.name, command.help);
  const CommandAction action = command.add(*cmd, line);
  std::vector<std::string> argv_text{"voussoir"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  app.parse(static_cast<int>(argv.size()), argv.data());
  return run_parsed_command(*cmd, line, action);
}

// The table's commands and options, for the package's functions and the reference page.
py::list command_list() {
  py::list out;
  for (const Command& command : command_table()) {
    CLI::App app{"voussoir"};
    CommandLine line;
    CLI::App* cmd = app.add_subcommand(command.name, command.help);
    command.add(*cmd, line);
    py::list options;
    bool deck = false;
    for (const CLI::Option* opt : cmd->get_options()) {
      if (opt->get_positional()) {
        deck = deck || opt->get_name() == "deck";
        continue;
      }
      if (opt->get_lnames().empty() || opt->get_lnames().front() == "help") continue;
      py::dict o;
      o["name"] = opt->get_lnames().front();
      o["help"] = opt->get_description();
      o["flag"] = opt->get_expected_max() == 0;
      o["many"] = opt->get_items_expected_max() > 1;
      o["required"] = opt->get_required();
      o["default"] = opt->get_default_str();
      options.append(o);
    }
    py::dict c;
    c["name"] = command.name;
    c["help"] = command.help;
    c["deck"] = deck;
    c["options"] = options;
    out.append(c);
  }
  return out;
}

}  // namespace
}  // namespace voussoir

PYBIND11_MODULE(_voussoir, m) {
  m.doc() = "voussoir's engine (use the package `voussoir`: docs/guide/python.md)";
  m.attr("version") = VOUSSOIR_VERSION;
  static py::exception<voussoir::DeckError> deck_error(m, "DeckError", PyExc_ValueError);
  static py::exception<voussoir::RunError> run_error(m, "RunError", PyExc_RuntimeError);

  m.def(
      "run_command",
      [](const std::vector<std::string>& args, bool summary) {
        std::string bad_input, failure;
        int status = 0;
        {
          py::gil_scoped_release free;
          // Without the summary, the commands' printf goes to /dev/null: C's stdout is swapped
          // for the call (Python's own prints write to file descriptor 1 and still show).
          FILE* const out = stdout;
          FILE* const null = summary ? nullptr : std::fopen("/dev/null", "w");
          if (null) stdout = null;
          try {
            status = voussoir::parse_and_run(args);
          } catch (const CLI::ParseError& e) {
            bad_input = args.front() + ": " + e.what();
          } catch (const voussoir::DeckError& e) {
            bad_input = e.what();
          } catch (const std::exception& e) {
            failure = e.what();
          }
          std::fflush(stdout);
          stdout = out;
          if (null) std::fclose(null);
        }
        if (!bad_input.empty()) {
          PyErr_SetString(deck_error.ptr(), bad_input.c_str());
          throw py::error_already_set();
        }
        if (!failure.empty()) {
          PyErr_SetString(run_error.ptr(), failure.c_str());
          throw py::error_already_set();
        }
        return status;
      },
      py::arg("args"), py::arg("summary"),
      "Runs `voussoir ARGS...` in this process (GIL released); returns its exit status. "
      "summary=False: the command's summary on stdout is not printed.");
  m.def(
      "load_deck",
      [](const std::string& path, const std::vector<std::string>& sets) {
        try {
          voussoir::load_deck(path, sets);
        } catch (const voussoir::DeckError& e) {
          PyErr_SetString(deck_error.ptr(), e.what());
          throw py::error_already_set();
        }
      },
      py::arg("path"), py::arg("sets"), "Reads and validates a deck with its --set overrides.");
  m.def("commands", &voussoir::command_list, "The command table: names, help, options.");
  m.def("request_stop", &voussoir::request_stop, "Asks every computation in progress to stop.");
  m.def("clear_stop", &voussoir::clear_stop, "Clears a stop request.");
}
