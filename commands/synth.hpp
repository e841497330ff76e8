#pragma once
// `voussoir synth`: spectrum-compatible artificial accelerograms (seismic/synth.hpp;
// docs/records.md "Artificial records"). No deck: the options say everything.

#include <string>
#include <vector>

#include "commands/common.hpp"

namespace voussoir {

struct SynthOptions {
  std::string spectrum = "ec8";  // --spectrum: the target (EN 1998-1 Type 1 only)
  double ag = 0.0;               // --ag [g]: design ground acceleration on type A ground
  std::string soil = "B";        // --soil A..E (EN 1998-1 Table 3.2)
  int count = 7;                 // --count: records (EN 1998-1 3.2.3.1.2 (4): mean of >= 3;
                                 // 7 for mean results, 4.3.3.4.3 (3))
  double duration = 20.0;        // --duration [s] (strong part 10.8 s: >= 10 s)
  long long seed = 1;            // --seed >= 0
  double dt = 0.01;              // --dt [s]
  std::vector<double> range = {0.05, 3.0};  // --range TMIN,TMAX [s]: matching and check
  std::string output = "synth";             // -o DIR
  std::string plot;                         // --plot FILE.png (default DIR/spectra.png)
  bool no_plot = false;                     // --no-plot
  std::string json;                         // --json FILE ('-': stdout)
  int threads = 0;                          // --threads N (records in parallel; 0: OpenMP default)
};

// Checks the options (DeckError naming the option and its value: exit 2), makes the records,
// writes DIR/synth_NN.AT2, DIR/spectra.csv, the plot and the JSON; prints a summary. Returns 0
// when the set meets EN 1998-1 3.2.3.1.2 (4) (mean spectrum >= 0.9 x the target over --range,
// mean PGA >= ag S); otherwise, everything written, throws RunError naming what failed (exit 1).
int command_synth(const SynthOptions& opts);

// Registers the options of `synth` on `cmd` (commands/table.cpp).
CommandAction add_synth_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir
