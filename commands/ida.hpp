#pragma once
// Incremental dynamic analysis (`voussoir ida DECK --records F1,F2,...`;
// docs/reference/commands.md, docs/ida.md): for each ground-motion record, the smallest intensity
// at which the structure collapses, and the lognormal fragility of collapse fitted to them
// (seismic/fragility.hpp).
//
// Intensity measure (IM, `--im`):
//   pga  the record's peak ground acceleration |a_g|max [g];
//   sa   its 5%-damped pseudo-spectral acceleration Sa(T) at `--period T` [g]
//        (seismic/spectrum.hpp, of the record as the run uses it: read, baseline-corrected,
//        band-passed and resampled as the deck's [load.base] says, commands/pulse.hpp).
// Both scale with the record: the record scaled by s has IM s IM_1, so a record is searched in
// its PGA (the amplitude of `pulse`: the record scaled to that peak) and every PGA A read as the
// IM A r, r = IM / PGA of the record (1 for pga; Sa(T) / PGA for sa).
//
// Each record is one search of commands/pulse.hpp (find_collapse_amplitude), exactly as
// `pulse --curve` searches a frequency: the structure settled once under gravity; each run a
// pulse run of the record at PGA A from a copy of that state, classified fall / rest / timeout
// (pulse.hpp); A stepped up from the start by the factor 1 + step until the first collapse, the
// last step bisected down to the relative tolerance, then `steps_above` steps above the first
// collapse to find survivals there (rocking can survive a larger record that a smaller one
// fells: reported, never used to move the collapse intensity). The start is lambda* in PGA
// (--start X in IM units overrides it): a record whose peak stays below lambda* g cannot tip a
// structure whose tilting capacity is lambda*, up to dynamic effects. The collapse intensity is
// the smallest IM seen to collapse (the bracket's upper end). A record that does not collapse
// up to the search's cap (kMaxAmplitude g in PGA) enters the fit censored at the largest IM it
// survived (seismic/fragility.hpp).
//
// Records are dealt to threads and MPI ranks (engine/dealer.hpp) by deal_searches; a record's
// result does not depend on which thread or rank ran it, so the CSV and JSON are the same but
// for wall times. `--resume FILE` journals every run with its record's path and the hash of the
// file's bytes (a record edited since is run again); lambda* is journalled in FILE.capacity.

#include <string>
#include <vector>

#include "commands/common.hpp"

namespace voussoir {

struct IdaOptions {
  std::vector<std::string> records;  // --records F1,F2,... (AT2 or two-column files)
  std::string im = "pga";            // --im pga|sa
  double period = 0.0;               // --period T [s] (for sa)
  bool period_given = false;
  double lambda_star = -1.0;  // --lambda-star X: skip the capacity search (< 0: compute)
  bool lambda_star_given = false;
  int points = 2;      // --points: capacity trials per round
  double start = 0.0;  // --start X [g of IM] (not given: lambda* in PGA)
  bool start_given = false;
  double step = 0.10;           // --step: relative IM step of the search
  int steps_above = 2;          // --steps-above N
  double tolerance = 0.05;      // --tolerance: relative bracket width on the IM
  double free_time = 1.5;       // --free-time S after the record [s]
  int bootstrap = 1000;         // --bootstrap N: resamples for the median's interval
  double confidence = 0.95;     // --confidence C of that interval
  long long seed = 1;           // --seed K of the bootstrap
  std::string csv = "ida.csv";  // --csv FILE: a line per record; FILE's stem + _runs.csv
  std::string plot;             // --plot FILE.png (scripts/plot_ida)
  std::string resume;           // --resume FILE
};

// DeckError (exit 2) naming the option, the value and what is allowed.
void validate_ida_options(const IdaOptions& opts);

// The runs CSV next to the records CSV: ida.csv -> ida_runs.csv.
std::string ida_runs_csv(const std::string& csv);

int command_ida(const Config& config, const CommonOptions& common, const IdaOptions& opts);

// Registers the options of `ida` on `cmd` (commands/table.cpp).
CommandAction add_ida_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir
