#pragma once
// Coulomb friction on the accumulated slip of one contact pair (non-associative, elastic
// predictor / return mapping; docs/design.md "Contact").
//
// State. Each candidate pair (c, t) carries its elastic tangential displacement s [m] (a 2D
// vector, so that it survives a rotation of the contact normal). Key: the unordered pair of
// triangle ids (a < b) -- the narrow phase always evaluates a pair both ways, so there is no
// direction to tell apart. The state survives re-detection (contact/friction.cpp merges the
// old sorted pair list into the new one) and is reset to zero whenever the pair has no overlap.
//
// Step. n = F_n / |F_n| with F_n the pair's potential (normal) force on c, tangent
// e = (-n_y, n_x). du = relative displacement of c's material with respect to t's at the
// overlap centroid over the last step (dt times the half-step velocities interpolated with the
// shape functions, i.e. x^n - x^(n-1) of the two material points). Then
//     s_trial = (s . e + du . e),     f_trial = -k_t s_trial                 (elastic predictor)
//     if |f_trial| <= mu |F_n|:  f = f_trial,          s = s_trial            (stick)
//     else:                      f = -mu |F_n| sign,   s = mu |F_n| / k_t sign   (slip)
// The return mapping's plastic work of the step is FrictionResult::dissipated,
// mu |F_n| |s_trial - s|. The elastic part 1/2 k_t s^2 is stored energy (booked with the contact
// energy). f acts on c and -f on t at the same point (overlap centroid), so forces and moments
// balance exactly.
//
// Ledger. The contact stage does not book that plastic work: it books as dissipated the work
// the friction forces take from the blocks (trapezoid of their nodal values at the two ends of
// each position increment) less the change of the springs' stored energy, when positive
// (contact/contact.cpp accumulate). Both agree in steady sliding and stick. They differ at the events an explicit
// step cannot resolve: the cap mu |F_n| moving while the pair slides (a chattering joint), a
// spring reversing or released when its pair opens, the overlap centroid moving between
// steps. The plastic-work form then drifts O(dt): 2.8% of the peak energy in 0.01 s on church A
// with rigid blocks, 1.7% in 0.2 s on the rigid semicircular arch, both undamped joints
// (restitution 1), at the rigid step fraction 0.2; the work form closes the balance to the
// integrator's own error (1.9e-4 and 6.1e-4 there, falling 4 to 5 times at half the step) and
// changes no force (docs/rigid.md, "Friction in the energy ledger").
//
// Tangential stiffness. k_t = kTangentialStiffnessRatio x Ep thick (3/h_c + 3/h_t) min(L_c, L_t)
// [N/m], with L the longest boundary edge of a triangle and h its height over that edge:
// Ep thick (|grad phi_c| + |grad phi_t|) x contact length is the normal stiffness of a flat
// contact between the two faces, for the longest contact the two triangles can make. Constant
// per pair, so that 1/2 k_t s^2 is an honest energy (a k_t following the overlap length would
// change the stored energy without work). Ratio 1/4: the tangential spring acts at one point
// with shape-function weights N_i, so its stiffness row sum at a node is 2 k_t N_i <= half the
// normal row sum Ep thick g L of the same edge; max_omega_squared (contact/contact.cpp) adds
// it in the tangential direction. Rejected 1/2: the tangential row would equal the normal one
// and raise the bound at corner nodes (two perpendicular faces) from 1.5 to 2 times one face's
// row, a 13% shorter stable step, for nothing. The elastic slip at stick, f_t / k_t, is
// ~1e-9 m for masonry blocks, far below anything that matters.

#include <cmath>
#include <vector>

#include "contact/broad_phase.hpp"
#include "core/model.hpp"

namespace voussoir {

// Tangential / normal penalty stiffness ratio (dimensionless; 1/4, see above).
inline constexpr double kTangentialStiffnessRatio = 0.25;

struct FrictionResult {
  Vec2 force;               // tangential force on c [N] (minus this on t)
  Vec2 slip;                // new elastic slip vector s [m]
  double dissipated = 0.0;  // energy dissipated this step [J]
  double stored = 0.0;      // 1/2 k_t |s|^2 [J]
  bool sliding = false;
};

// One friction update. normal_force: pair potential force on c [N]; du: relative displacement
// increment of c w.r.t. t at the contact point [m]; slip: elastic slip s before the step [m];
// kt [N/m] > 0; mu >= 0.
inline FrictionResult coulomb_friction(double fn, Vec2 unit_normal, Vec2 du, Vec2 slip, double kt,
                                       double mu);

inline FrictionResult coulomb_friction(Vec2 normal_force, Vec2 du, Vec2 slip, double kt,
                                       double mu) {
  const double fn = std::sqrt(normal_force.x * normal_force.x + normal_force.y * normal_force.y);
  if (!(fn > 0.0)) return FrictionResult{};
  return coulomb_friction(fn, Vec2{normal_force.x / fn, normal_force.y / fn}, du, slip, kt, mu);
}

// The same with the normal force given as its magnitude fn > 0 and unit direction (on c).
inline FrictionResult coulomb_friction(double fn, Vec2 unit_normal, Vec2 du, Vec2 slip, double kt,
                                       double mu) {
  FrictionResult r;
  const double ex = -unit_normal.y, ey = unit_normal.x;
  const double s_trial = (slip.x + du.x) * ex + (slip.y + du.y) * ey;
  const double cap = mu * fn;
  double s = s_trial, f = -kt * s_trial;
  if (std::abs(f) > cap) {
    const double sign = s_trial > 0.0 ? 1.0 : -1.0;
    f = -cap * sign;
    s = cap / kt * sign;
    r.dissipated = cap * std::abs(s_trial - s);
    r.sliding = true;
  }
  r.force = {f * ex, f * ey};
  r.slip = {s * ex, s * ey};
  r.stored = 0.5 * kt * s * s;
  return r;
}

// Carries the friction state across a re-detection: for every pair of `next` (sorted) that
// was also in `prev` (sorted), copies its slip; new pairs start at zero. Linear merge.
void carry_friction_history(const std::vector<IndexPair>& prev, const std::vector<double>& prev_sx,
                            const std::vector<double>& prev_sy, const std::vector<IndexPair>& next,
                            std::vector<double>& next_sx, std::vector<double>& next_sy);

// The same for `width` values per pair (prev_values[width p .. width p + width)), e.g. the
// impact dashpot's last nodal forces (contact/contact.cpp).
void carry_pair_values(const std::vector<IndexPair>& prev, const std::vector<double>& prev_values,
                       std::size_t width, const std::vector<IndexPair>& next,
                       std::vector<double>& next_values);

}  // namespace voussoir
