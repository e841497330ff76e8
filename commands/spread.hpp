#pragma once
// `voussoir spread DECK`: a support moved step by step until the structure collapses
// (the spreading study; docs/supports.md).
//
// Procedure. The deck's model is settled under gravity and its own [supports] moves are made
// (commands/capacity.hpp settle, quasi-static as `capacity` runs it). Then one fixed block (the
// study's support) is moved on along a unit direction e (and, optionally, turned) in steps:
//   d_k = d_(k-1) + step,   its pose from the last one by the ramp of core/supports.hpp over
//   supports.ramp, then held until rest (the settle's rest rule),
// each step from the state the last one left. A step is collapsed when a free block moves or
// turns more than the settle's collapse limits, widened by what the step's own movement
// imposes (commands/capacity.hpp support_allowance), or does not come to rest within the
// settle's time limit. At each state at rest the study records the support thrust (the
// horizontal components of the joint resultants at the joints with a fixed block,
// engine/thrust.hpp; left and right of the free blocks' centre of weight) and the open
// joints (engine/kinematics.hpp find_hinges with kHingeFraction L_ref). After the first
// collapsed step the movement at collapse is bisected from the last state at rest (its copy)
// until the bracket [last at rest, first collapsed] is narrower than `tolerance` times its
// upper end.
//
// Outputs: a table on stdout, a CSV (movement, thrusts, hinges per state at rest) and the JSON
// (SpreadResult below), the limit-analysis thrust bounds of the unmoved structure beside them.

#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "commands/common.hpp"
#include "core/schema.hpp"

namespace voussoir {

struct SpreadOptions {
  int block = -1;                  // --block B: the fixed block to move (-1: the deck's first move,
                                   // else the fixed block with the smallest centroid x)
  std::vector<double> direction;   // --direction DX,DY (normalised); empty: horizontal, away from
                                   // the free blocks' centre of weight
  double rotation = 0.0;           // --rotation R: degrees of turn per metre of movement
  double step = 0.0;               // --step D [m]; 0: 0.25% of the free blocks' width
  double max_movement = 0.0;       // --max D [m]; 0: 25% of the free blocks' width
  double tolerance = 0.05;         // --tolerance: relative width of the collapse bracket
  std::string csv = "spread.csv";  // --csv FILE
  TrialCriteria criteria;          // quasi-static settle criteria (capacity's defaults)
};

struct SpreadState {
  double movement = 0.0;      // of the study's support along e since the deck's moves [m]
  bool collapsed = false;     // this step collapsed (no thrust recorded)
  double thrust = 0.0;        // mean of thrust_left and thrust_right [N]
  double thrust_left = 0.0;   // outward horizontal force on the supports left of x_G [N]
  double thrust_right = 0.0;  // and right of it [N]
  std::vector<Hinge> hinges;  // open (or slid) joints at rest
  double sim_time = 0.0;      // [s] of this step
  double wall_s = 0.0;
};

struct SpreadResult {
  int block = 0;
  Vec2 direction;
  double step = 0.0, max_movement = 0.0, tolerance = 0.0;
  std::vector<SpreadState> states;            // in the order run (bisection steps last)
  bool collapsed = false;                     // some step collapsed
  double collapse_lo = 0.0;                   // largest movement at rest [m]
  double collapse_hi = 0.0;                   // smallest collapsed movement [m] (collapsed only)
  double thrust_min = 0.0, thrust_max = 0.0;  // limit analysis, unmoved structure [N]
  double settle_wall_s = 0.0, wall_s = 0.0;
};

SpreadResult run_spread(const Config& config, const SpreadOptions& opts, bool quiet);

int command_spread(const Config& config, const CommonOptions& common, const SpreadOptions& opts);

// Registers the options of `spread` on `cmd` (commands/table.cpp).
CommandAction add_spread_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir
