// The table of subcommands that app/main.cpp registers: one row per command, in the order of
// `voussoir --help`. A command lives in commands/NAME.hpp and .cpp (its options, its analysis,
// its JSON record) and is added here (docs/design.md, "Where things live").

#include "commands/capacity.hpp"
#include "commands/check.hpp"
#include "commands/common.hpp"
#include "commands/ida.hpp"
#include "commands/keys.hpp"
#include "commands/limit.hpp"
#include "commands/pulse.hpp"
#include "commands/pushover.hpp"
#include "commands/run.hpp"
#include "commands/spread.hpp"
#include "commands/stability.hpp"
#include "commands/sweep.hpp"
#include "commands/synth.hpp"

namespace voussoir {

const std::vector<Command>& command_table() {
  static const std::vector<Command> kTable = {
      {"check", "validate the deck and print the model summary", add_check_command},
      {"run", "one simulation: HDF5 output and JSON summary", add_run_command},
      {"capacity", "collapse load factor lambda* by bisection on lambda", add_capacity_command},
      {"pushover",
       "capacity curve: lambda against a control point's displacement, through the "
       "peak and down the softening branch, with its equivalent SDOF curve",
       add_pushover_command},
      {"limit", "rigid-block limit analysis: lambda_la and its mechanism (LP)", add_limit_command},
      {"spread", "move a support step by step until the structure collapses: thrust, hinges",
       add_spread_command},
      {"pulse", "base-excitation run; --curve: collapse amplitude per frequency (failure curve)",
       add_pulse_command},
      {"ida", "incremental dynamic analysis: collapse intensity per record, lognormal fragility",
       add_ida_command},
      {"sweep", "capacity over a grid of deck values", add_sweep_command},
      {"stability", "gravity-only stability map over a grid (kinetic-energy criterion)",
       add_stability_command},
      {"synth",
       "artificial accelerograms compatible with the EN 1998-1 elastic spectrum (AT2 "
       "records, their spectra; docs/records.md)",
       add_synth_command},
      {"keys",
       "print the deck reference: every key, type, unit, default, allowed values "
       "(docs/reference/deck.md)",
       add_keys_command},
  };
  return kTable;
}

}  // namespace voussoir
