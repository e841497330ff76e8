#pragma once
// Capacity curves (docs/reference/commands.md, `voussoir pushover`; docs/pushover.md).
//
// A pushover is one run (quasi-static unless its mechanism slides) from the settled state under
// gravity (settle(), commands/capacity.hpp) in which the horizontal load factor lambda follows the
// displacement d of a control point, the centroid of the control block, measured along the load
// from the settled state.
//
// Control: lambda is the force of a virtual spring, in load-factor units, between the control
// point and a target that moves along the load at the constant `rate` v:
//     lambda(t) = K (v t - d(t)),          K [1/m] the servo stiffness.
// The lag v t - d = lambda / K does not enter the curve: its points are measured (d, lambda)
// pairs. Why the spring holds the structure past the peak: near a state of the curve
// lambda_c(d) with tangent slope -s (s > 0 on the softening branch), the control point's
// generalized motion obeys
//     m d'' + c d' = W e (lambda - lambda_c(d)) = W e (K (v t - d) - lambda_c(d))
// whose homogeneous part m p^2 + c p + W e (K - s) is stable when K > s: the spring holds the
// structure on the softening branch where a force control (lambda given) would let it fall.
// An integral control (lambda' = G (v t - d)) is unstable there for every G > 0 (the Routh
// test of m p^3 + c p^2 - W e s p + G W e has a negative coefficient): not used.
// Default K = kServoFactor lambda_ref / L_ref (lambda_ref: limit analysis of the same blocks,
// 1 when it has no answer; L_ref: engine/motion.hpp). The steepest softening of a b x h rigid
// block rocking about its corner, control at its centroid, is at the start of the rocking:
// lambda = tan(alpha - theta), d' = R cos(alpha - theta) (R: corner to centroid, tan alpha =
// b / h), so s = 1 / (R cos^3 alpha) = 2 (b^2 + h^2) / h^3, against its K = kServoFactor
// (b / h) / sqrt(b h): K / s = 25 sqrt(b) h^1.5 / (b^2 + h^2), 12.5 for a square block,
// above 2 for any 0.01 h <= b <= 3 h.
// The same spring sets the load rate: lambda grows at K v until the structure yields. Until
// lambda reaches kFastFraction lambda_ref the target moves faster, at the speed that ramps
// lambda_ref on in the capacity trials' ramp_time (0.1 s: ten periods of the lowest mode of
// the shipped arches), at most kFastRate v. The peaks of the regression cases lie above 0.9
// lambda_ref; the lowest seen, the scaled arch on joints of 1e8 N/m3, at 0.6.
//
// The quasi-static load factor of the curve. The applied lambda carries, besides the statics,
// the forces that accelerate the blocks and those of the damping; at the peak of a rigid
// mechanism they are not small (the mechanism starts from rest, and the load grows while it
// picks up speed). Each point of the curve reads instead the lambda whose power balances the
// motion of the window just ended without them, from the energy ledger:
//     lambda_qs g dS = W_h - (dK + dD_local + dD_viscous + dD_impact),
//     S = sum over free blocks of m x (along the load),  W_h = sum over steps of lambda g dS,
// K the kinetic energy and D the rate-dependent dissipations (the friction and the joints'
// elastic energy stay: they are the statics). For a single-degree-of-freedom mechanism this is
// the virtual work equation of the mechanism at the state reached, exactly. A window closes
// when d has moved kWindowDisplacement L_ref, lambda has moved kWindowLambda lambda_ref, or
// after kWindowTime, provided the masses moved by kWindowMotion of the window's displacement
// on average (else too little power to read: it stays open, up to kWindowMaxTime, and reads
// its average applied lambda, as on the stiff rise of rigid blocks, which is static anyway).
// On the semicircular arch at the default rate the applied lambda overshoots the peak by 5%,
// lambda_qs peaks 0.08% below lambda* of `capacity` (docs/pushover.md).
//
// Technique. Quasi-static (as the capacity trials): Cundall's local damping of
// capacity.local_damping and, for rigid blocks, the settle's mass scaling. The kinetic damping
// of the capacity trials is not used: it stops every motion at each peak of the kinetic
// energy, which a mechanism driven at a constant rate reaches at every sample. On a sliding
// mechanism the quasi-static run misreads the statics: the peak of the semicircular arch of
// embrace 120 and friction 0.6 came out 16% above capacity's lambda* (and above the limit
// analysis that bounds it; the likely cause, not proven: under the local damping the slide
// goes by jerks, whose friction work counts as statics), 0.2% above it in the physical run (no
// local damping or mass scaling; the joints' default dashpot). The default ("auto") therefore runs
// the physical pushover when the limit-analysis mechanism slides, the quasi-static one otherwise
// (the physical run cost 4 times as much on the regression cases: the physical step, no mass
// scaling);
// --dynamic and --quasi-static force one.
//
// Default rate: kRateFactor sqrt(g L_ref). On the semicircular arch, from 0.375 to 1.5 times
// it the peak stays within 2e-4 of 0.2933 and d0 within 1e-4 m of 0.0553 m; the curves agree
// with the slowest to 2e-3 in lambda at 0.75 and 1 times it, to 7e-3 at 1.125 and 1.5, but
// for the snap where the fourth hinge moves (d = 0.040-0.044 m) (docs/pushover.md).
//
// The run ends when lambda falls to 0 or below after the peak (the ultimate displacement d0,
// interpolated between the last two quasi-static windows), when it falls to stop_fraction of the
// peak (asked for lambda* alone), when d reaches max_displacement, or at the time that the target
// needs to reach max_displacement and twice the peak's lag.
//
// The equivalent single-degree-of-freedom curve of the kinematic analyses (Eurocode 8-3
// Annex C, NTC 2018 Circolare C8.7.1.2), with P_i the free blocks' weights and dx_i the
// horizontal virtual displacements of their centroids in the mechanism at the peak,
// normalised to 1 at the control block (from the run: each centroid's horizontal displacement
// between the peak and the first sample kMechanismWindow of the way from the peak to the end):
//     M* = (sum P_i dx_i)^2 / (g sum P_i dx_i^2),   e* = g M* / sum P_i,
//     a* = lambda g / e*,   d* = d sum P_i dx_i^2 / (dx_k sum P_i dx_i),
//     d*_u = 0.4 d*_0, d*_0 the d* of the ultimate displacement.
// (The Circolare's confidence factor FC is 1 here: a* is the structure's, not the code's.)

#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "commands/common.hpp"
#include "core/schema.hpp"
#include "engine/kinematics.hpp"

namespace voussoir {

inline constexpr double kServoFactor = 50.0;  // K = 50 lambda_ref / L_ref
inline constexpr double kRateFactor = 0.004;  // v = 0.004 sqrt(g L_ref)
inline constexpr double kFastRate = 10.0;     // x v, while lambda < kFastFraction lambda_ref
inline constexpr double kFastFraction = 0.5;
// A window whose quasi-static load factor differs from the applied one by more than this x
// lambda_ref is dynamic (a snap, a block falling): left out of the curve (JSON
// "dynamic_windows"), never the peak, never the end of the run.
inline constexpr double kDynamicWindow = 0.1;
inline constexpr double kMechanismWindow = 0.1;  // of the way from the peak to the end
// A window of the quasi-static load factor closes when d has moved kWindowDisplacement x
// L_ref, the applied lambda has moved kWindowLambda x lambda_ref, or after kWindowTime.
inline constexpr double kWindowDisplacement = 1e-3;
inline constexpr double kWindowLambda = 0.01;
inline constexpr double kWindowTime = 0.02;  // [s]
inline constexpr double kWindowMotion = 0.1;
inline constexpr double kWindowMaxTime = 0.2;  // [s]
// Default max_displacement: this fraction of the height of the free blocks' bounding box.
inline constexpr double kMaxDisplacementFraction = 0.5;

inline constexpr double kDefault = std::numeric_limits<double>::quiet_NaN();

struct PushoverSettings {
  int control = -1;        // control block; -1: default_control_block
  double direction = 1.0;  // +1: lambda g and d towards +x; -1: towards -x
  // NaN: the default
  double rate = kDefault;              // [m/s] target speed; kRateFactor sqrt(g L_ref)
  double max_displacement = kDefault;  // [m]; kMaxDisplacementFraction x the height
  double servo = kDefault;             // [1/m] K; kServoFactor lambda_ref / L_ref
  // > 0: end when lambda has fallen to this fraction of the peak past the peak (lambda* alone)
  double stop_fraction = 0.0;
  // "auto": quasi-static unless the limit-analysis mechanism slides; "quasi-static";
  // "dynamic" (the physical run)
  std::string technique = "auto";
  TrialCriteria criteria;  // the settle's settle_max_time and limits (quasi_static: technique)
};

// The crown block of an arch (the highest voussoir), or the top free block otherwise: the
// free block, of role "voussoir" when there is one, with the highest centroid; ties go to the
// one nearest the middle of the free blocks, then to the lower index.
int default_control_block(const Model& model);

// Throws DeckError naming the option and value when `s` asks for a control block that does
// not exist or is fixed, or for a rate, limit or servo stiffness that is not positive.
void validate_pushover(const Model& model, const PushoverSettings& s);

struct PushoverPoint {
  double displacement = 0.0;  // d [m], along the load, at the end of the window
  double lambda = 0.0;        // the quasi-static load factor of the window (header comment)
  double time = 0.0;          // run time [s] since the settled state
  double applied = 0.0;       // the load factor applied at the end of the window
  bool quasi_static = true;   // the window is not dynamic (kDynamicWindow)
};

struct HingeEvent {
  Hinge hinge;                // as find_hinges reports it when first seen
  double displacement = 0.0;  // d when it opened (or slid) [m]
  double lambda = 0.0;
};

struct Sdof {
  bool valid = false;                     // false when the run has no mechanism past the peak
  double participating_mass_ratio = 0.0;  // e* = g M* / sum P_i
  double participating_mass = 0.0;        // M* [kg]
  double factor = 0.0;                    // d* / d = sum P dx^2 / (dx_k sum P dx)
  std::vector<double> d_star, a_star;     // [m], [m/s2], one per curve point
  double d_star_0 = 0.0, d_star_u = 0.0;  // [m]; 0 when lambda did not reach 0
  std::vector<double> dx;  // the mechanism's normalised dx_i per block (0 when fixed)
};

struct PushoverResult {
  int control = 0;
  Vec2 control_point;  // its centroid at the start [m]
  double direction = 1.0;
  double rate = 0.0, max_displacement = 0.0, servo = 0.0, lambda_ref = 0.0;
  std::string lambda_ref_from;       // "limit analysis" or "none (1)"
  std::vector<PushoverPoint> curve;  // every sample from the settled state
  PushoverPoint peak;                // its lambda: the median of its window and the two around
  bool reached_zero = false;
  double ultimate_displacement = 0.0;  // d0 [m] where lambda reaches 0 (when reached_zero)
  // "lambda <= 0", "fallen to F x peak", "max displacement", "time limit"
  std::string ended;
  std::vector<HingeEvent> hinges;  // in the order they opened
  Sdof sdof;
  double energy_balance_error = 0.0;  // largest over the samples
  double sim_time = 0.0;              // [s] after the settle
  long long steps = 0;
  double settle_wall_s = 0.0, wall_s = 0.0;
  double dt = 0.0;
  double gravity = 9.81;  // [m/s2]
  bool quasi_static = true;
  std::string technique;  // which, and why
  // The model at the peak and at the end (nodes where they were) for the pictures.
  Model at_peak, at_end;
  std::vector<Hinge> hinges_at_end;
};

// Runs the pushover of `config` (header comment). Throws DeckError for bad settings and
// RunError when the structure does not settle or a run guard fires.
PushoverResult run_pushover(const Config& config, const PushoverSettings& settings, bool quiet);

// The SDOF curve of `r` from its curve and the mechanism at its peak (header comment).
Sdof equivalent_sdof(const std::vector<double>& weights, const std::vector<double>& dx, int control,
                     const std::vector<PushoverPoint>& curve, double gravity, bool reached_zero,
                     double ultimate_displacement);

// The JSON of docs/reference/output.md (`pushover --json`): "curve" holds the quasi-static windows,
// "dynamic_windows" the others (kDynamicWindow); the block outlines at the peak and at the end
// under "mechanisms" for scripts/plot_pushover.
nlohmann::json pushover_json(const PushoverResult& r);

}  // namespace voussoir

namespace voussoir {

struct CommonOptions;

struct PushoverOptions {
  int control = -1;                    // --control BLOCK (-1: default_control_block)
  std::string direction = "+x";        // --direction +x | -x
  double rate = kDefault;              // --rate V [m/s]
  double max_displacement = kDefault;  // --max-displacement D [m]
  double servo = kDefault;             // --servo K [1/m]
  double stop_at = 0.0;                // --stop-at F: end at F x the peak past it
  bool dynamic = false;                // --dynamic: the physical run
  bool quasi_static = false;           // --quasi-static: quasi-static even if it slides
  double settle_time = 5.0;            // --settle-time [s]
  std::string csv;                     // --csv FILE: the curve and its SDOF curve
  std::string plot;                    // --plot FILE.png (scripts/plot_pushover)
  std::string picture;                 // --picture FILE.png|svg: the state at the end, with hinges
};

int command_pushover(const Config& config, const CommonOptions& common,
                     const PushoverOptions& opts);

// Registers the options of `pushover` on `cmd` (commands/table.cpp).
CommandAction add_pushover_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir
