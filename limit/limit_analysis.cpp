// Rigid-block limit analysis as a linear programme (Livesley 1978; Gilbert, Casapulla, Ahmed
// 2006), solved with GLPK.
//
// Unknowns. Each interface k (between blocks a and b, ends p_a and p_b, unit normal n from a
// into b, tangent t = (p_b - p_a) / |p_b - p_a|) carries at each end e a force on block b
//   F_e = N_e n + S_e t,   N_e >= 0 (no tension),   |S_e| <= mu N_e (Coulomb),
// and -F_e on block a. The friction cone of one end has two edges, so it is written exactly
// as F_e = f+ (n + mu t) + f- (n - mu t) with f+, f- >= 0 (N = f+ + f-, S = mu (f+ - f-)): the
// LP then has only bounds on its columns and one equality row per equilibrium equation. With
// mu = 0 the two edges coincide and only f+ is kept. Plus the load factor lambda (free). An
// end marked open (Interface::open_a, open_b: an open joint kept as a point contact at its
// other end) carries none: its columns are fixed at 0.
//
// Equilibrium of each free block i (weight W_i = rho A_i out_of_plane g at the centroid c_i,
// horizontal load lambda W_i at c_i, moments about a reference point O):
//   sum F_x + lambda W_i          = 0
//   sum F_y                       = W_i
//   sum (r x F) - lambda W_i r_cy = W_i r_cx,        r = p - O, r_c = c_i - O.
// Fixed blocks have no equations. Objective: maximise lambda (gravity_only: lambda fixed at 0,
// a feasibility problem; thrust: below). Scaling: lengths in units of the free blocks' bounding-box
// diagonal L about its centre O, forces in units of the mean free-block weight, so the coefficients
// are O(1) for any model size; lambda does not depend on either choice (or on g, rho).
//
// The dual is the virtual-work (kinematic) problem: the row multipliers of block i are its
// virtual velocity (u_x, u_y, omega) (velocity of the point r: u + omega e_z x r), the dual
// row of the lambda column normalises the power of the horizontal load to 1, and the dual
// constraint of each cone edge d = n +- mu t reads  d . dv_e >= 0, dv_e = v_b(p_e) - v_a(p_e),
// i.e. dv.n >= mu |dv.t|: opening without interpenetration and associative (dilatant) sliding.
// Hence lambda_la is exact for mu large enough that no joint slides, and an upper bound on the
// non-associative (real Coulomb) value where sliding governs (Drucker 1954).
//
// Mechanism. At the optimum GLPK gives the row duals (GLPK: d_j = c_j - sum_i a_ij pi_i, so pi
// is the velocity field with load power +1; the sign is checked anyway). An interface end
// whose relative velocity has a normal component opens; an interface whose ends have relative
// velocity is in the mechanism: sliding if its tangential rate is non-zero, else a hinge at
// the end that stays in contact (the smaller opening), "separation" if both ends open.
//
// Thrust (limit_thrust). With lambda fixed at 0 the free blocks' loads have no horizontal
// component, so the horizontal forces on all the fixed blocks sum to zero: what the structure
// pushes outward on its supports on the left equals what it pushes outward on the right. Let
// x_G be the abscissa of the free blocks' centre of weight and L the interfaces between a free
// and a fixed block whose middle lies left of x_G. The thrust is
//   H = - sum over L of (horizontal force on the fixed block)
//     = sum over the edge columns f of L:  -d_x f  (fixed block b)  or  +d_x f  (fixed block a),
// linear in the columns, so min H and max H are LPs over the same feasible set (Heyman's least
// and greatest thrust: the arch on supports that spread, or that are pushed together). The
// dual of the min thrust LP is the mechanism that a unit spreading of the supports drives.
// A flat arch (a lintel of voussoirs) has no greatest thrust: the LP is unbounded.
//
// Solver: glp_simplex (dual then primal phases, presolve off so that duals and an infeasible
// status are always available), then glp_exact from the final basis: the rational re-solve
// confirms (or corrects, in a few pivots) the basis and the status without the floating
// simplex's feasibility tolerance (1e-7), which matters for the gravity-only verdict near a
// critical thickness. glp_exact turns every double into the simplest fraction within 1e-9
// relative of it, so its verdict is exact for data perturbed at that level, and its values
// are not used: a last floating-point glp_simplex from its basis (no pivots when the basis
// is optimal) gives the values of the data as given. Tried and rejected: taking glp_exact's
// values directly (the single block gave lambda = 0.5 + 2.5e-11 instead of 0.5).

#include "limit/limit_analysis.hpp"

#include <glpk.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace voussoir {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct GlpDeleter {
  void operator()(glp_prob* p) const { glp_delete_prob(p); }
};

// One LP column: a cone edge at one end of one interface.
struct EdgeColumn {
  Index interface;
  int end;      // 0: end a, 1: end b
  double sign;  // +1: n + mu t, -1: n - mu t
};

// What the LP optimises: lambda, nothing (admissibility), or the support thrust.
enum class Objective { Lambda, Admissible, ThrustMin, ThrustMax };

LimitResult solve_limit_lp(const Model& model, double mu, double gravity, Objective objective,
                           const LimitOptions& options);

}  // namespace

LimitResult limit_analysis(const Model& model, double mu, double gravity, bool gravity_only) {
  return limit_analysis(model, mu, gravity, gravity_only, LimitOptions{});
}

LimitResult limit_analysis(const Model& model, double mu, double gravity, bool gravity_only,
                           const LimitOptions& options) {
  return solve_limit_lp(model, mu, gravity,
                        gravity_only ? Objective::Admissible : Objective::Lambda, options);
}

LimitResult limit_thrust(const Model& model, double mu, double gravity, ThrustBound bound,
                         const LimitOptions& options) {
  return solve_limit_lp(model, mu, gravity,
                        bound == ThrustBound::Min ? Objective::ThrustMin : Objective::ThrustMax,
                        options);
}

namespace {

// The free blocks in LP units (header, "Scaling"): each block's area and centroid, the GLPK row
// of its x equation, and the units.
struct LpBlocks {
  std::vector<double> area;
  std::vector<Vec2> centroid;
  std::vector<int> first_row;  // 1-based GLPK row of the block's x equation; -1: fixed
  Vec2 origin;                 // O, the free blocks' bounding-box centre [m]
  double length = 0.0;         // L, its diagonal [m]
  double area_ref = 0.0;       // mean free-block area: the LP force unit is its weight
  double x_weight = 0.0;       // x_G, the free blocks' centre of weight [m]
  Vec2 scaled(Vec2 p) const { return Vec2{(p.x - origin.x) / length, (p.y - origin.y) / length}; }
};

// Areas, centroids and rows of the blocks; counts the free blocks into res.
LpBlocks scale_blocks(const Model& model, LimitResult& res) {
  const std::size_t nb = model.blocks.size();
  LpBlocks B;
  B.area.assign(nb, 0.0);
  B.centroid.resize(nb);
  B.first_row.assign(nb, -1);
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY, free_area_sum = 0.0;
  double free_moment_x = 0.0;  // sum of A x_c over the free blocks, for x_G
  for (std::size_t i = 0; i < nb; ++i) {
    const Block& b = model.blocks[i];
    B.area[i] = polygon_centroid(b.polygon, &B.centroid[i]);
    if (b.fixed) continue;
    B.first_row[i] = 1 + 3 * res.free_blocks++;
    free_area_sum += B.area[i];
    free_moment_x += B.area[i] * B.centroid[i].x;
    for (const Vec2& p : b.polygon) {
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
    }
  }
  if (res.free_blocks == 0) throw std::invalid_argument("limit_analysis: no free block");
  B.origin = Vec2{0.5 * (x0 + x1), 0.5 * (y0 + y1)};
  B.length = std::max(std::hypot(x1 - x0, y1 - y0), 1e-300);
  B.area_ref = free_area_sum / res.free_blocks;
  B.x_weight = free_moment_x / free_area_sum;
  return B;
}

// The LP of the header: a row per equilibrium equation of a free block, the lambda column,
// then a column per cone edge (cols), the objective's coefficients.
void build_lp(glp_prob* P, const Model& model, double mu, Objective objective, const LpBlocks& B,
              const std::vector<EdgeColumn>& cols, const LimitResult& res) {
  const bool gravity_only = objective != Objective::Lambda;
  const bool thrust = objective == Objective::ThrustMin || objective == Objective::ThrustMax;
  glp_set_obj_dir(P, objective == Objective::ThrustMin ? GLP_MIN : GLP_MAX);
  glp_add_rows(P, res.rows);
  glp_add_cols(P, res.columns);
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  ia.reserve(1 + 6 * cols.size() + 2 * res.free_blocks);
  ja.reserve(ia.capacity());
  ar.reserve(ia.capacity());
  auto put = [&](int row, int col, double v) {
    if (v == 0.0) return;
    ia.push_back(row), ja.push_back(col), ar.push_back(v);
  };

  // Rows (right-hand sides: gravity) and the lambda column.
  for (std::size_t i = 0; i < model.blocks.size(); ++i) {
    if (B.first_row[i] < 0) continue;
    const double w = B.area[i] / B.area_ref;
    const Vec2 rc = B.scaled(B.centroid[i]);
    const int r = B.first_row[i];
    glp_set_row_bnds(P, r, GLP_FX, 0.0, 0.0);
    glp_set_row_bnds(P, r + 1, GLP_FX, w, w);
    glp_set_row_bnds(P, r + 2, GLP_FX, w * rc.x, w * rc.x);
    put(r, 1, w);
    put(r + 2, 1, -w * rc.y);
  }
  if (gravity_only)
    glp_set_col_bnds(P, 1, GLP_FX, 0.0, 0.0);
  else
    glp_set_col_bnds(P, 1, GLP_FR, 0.0, 0.0);
  glp_set_obj_coef(P, 1, objective == Objective::Lambda ? 1.0 : 0.0);

  // Cone-edge columns.
  for (std::size_t c = 0; c < cols.size(); ++c) {
    const int col = 2 + static_cast<int>(c);
    const Interface& f = res.interfaces[cols[c].interface];
    const double len = f.length();
    const Vec2 t{(f.b.x - f.a.x) / len, (f.b.y - f.a.y) / len};
    const Vec2 d{f.normal.x + cols[c].sign * mu * t.x, f.normal.y + cols[c].sign * mu * t.y};
    const Vec2 r = B.scaled(cols[c].end == 0 ? f.a : f.b);
    const double m = r.x * d.y - r.y * d.x;
    const bool open = cols[c].end == 0 ? f.open_a : f.open_b;  // no force at an open end
    glp_set_col_bnds(P, col, open ? GLP_FX : GLP_LO, 0.0, 0.0);
    if (thrust && 0.5 * (f.a.x + f.b.x) < B.x_weight) {
      // Outward (-x) force on the fixed block of a left support interface (header).
      if (model.blocks[f.block_b].fixed) glp_set_obj_coef(P, col, -d.x);
      if (model.blocks[f.block_a].fixed) glp_set_obj_coef(P, col, d.x);
    }
    if (const int rb = B.first_row[f.block_b]; rb > 0) {
      put(rb, col, d.x), put(rb + 1, col, d.y), put(rb + 2, col, m);
    }
    if (const int ra = B.first_row[f.block_a]; ra > 0) {
      put(ra, col, -d.x), put(ra + 1, col, -d.y), put(ra + 2, col, -m);
    }
  }
  glp_load_matrix(P, static_cast<int>(ia.size()) - 1, ia.data(), ja.data(), ar.data());
}

// The solver of the header: the simplex, then glp_exact's verdict and a last floating-point
// simplex from its basis. Returns GLPK's status (GLP_UNDEF when the simplex failed).
int solve_lp(glp_prob* P, const LimitOptions& options, LimitResult& res) {
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_OFF;
  parm.meth = GLP_DUALP;
  // GLPK writes to the terminal from glp_scale_prob and glp_adv_basis whatever msg_lev says:
  // silence it for the solve and restore the caller's setting afterwards.
  const int term_was = glp_term_out(GLP_OFF);
  glp_scale_prob(P, GLP_SF_AUTO);
  glp_adv_basis(P, 0);
  int rc = glp_simplex(P, &parm);
  if (rc != 0) {
    // Retry from the standard basis with the primal simplex before giving up.
    glp_std_basis(P);
    parm.meth = GLP_PRIMAL;
    rc = glp_simplex(P, &parm);
  }
  int status = rc == 0 ? glp_get_status(P) : GLP_UNDEF;
  if (rc == 0 && options.exact && res.rows <= options.exact_max_rows && glp_exact(P, &parm) == 0) {
    // The rational verdict (optimal / infeasible / unbounded) is the one reported. glp_exact
    // reads each double as the simplest fraction within 1e-9 relative of it (GLPK's set_d_eps),
    // so its values belong to data perturbed at that level: re-solve in floating point from
    // its basis (no pivot when the basis is optimal) to report values of the data as given.
    res.exact = true;
    status = glp_get_status(P);
    if (status == GLP_OPT && glp_simplex(P, &parm) == 0 && glp_get_status(P) != GLP_OPT)
      status = glp_get_status(P);
  }
  glp_term_out(term_was);
  res.iterations = glp_get_it_cnt(P);
  return status;
}

// Status, lambda_la or the thrust, admissibility.
void read_verdict(glp_prob* P, int status, Objective objective, double newton, LimitResult& res) {
  const bool gravity_only = objective != Objective::Lambda;
  const bool thrust = objective == Objective::ThrustMin || objective == Objective::ThrustMax;
  if (status == GLP_OPT)
    res.status = "optimal";
  else if (status == GLP_NOFEAS)
    res.status = "infeasible";
  else if (status == GLP_UNBND)
    res.status = "unbounded";
  else
    res.status = "error";
  if (thrust) {
    res.admissible = status == GLP_OPT || status == GLP_UNBND;
    if (status == GLP_OPT) res.thrust = glp_get_obj_val(P) * newton;
  } else if (gravity_only) {
    res.admissible = status == GLP_OPT;
  } else if (status == GLP_OPT) {
    res.lambda_la = glp_get_col_prim(P, 1);
    res.admissible = res.lambda_la >= 0.0;
  } else {
    res.admissible = status == GLP_UNBND;
  }
}

// Forces of the equilibrium found [N] (a feasible LP).
void read_forces(glp_prob* P, const std::vector<EdgeColumn>& cols, double mu, double newton,
                 LimitResult& res) {
  res.forces.assign(res.interfaces.size(), InterfaceForces{});
  for (std::size_t c = 0; c < cols.size(); ++c) {
    const double v = glp_get_col_prim(P, 2 + static_cast<int>(c)) * newton;
    InterfaceForces& F = res.forces[cols[c].interface];
    (cols[c].end == 0 ? F.normal_a : F.normal_b) += v;
    (cols[c].end == 0 ? F.shear_a : F.shear_b) += cols[c].sign * mu * v;
  }
}

// The mechanism's joints from the relative velocities dv (b w.r.t. a, 2 per interface: ends a
// and b) and their scale 1 / max |dv|, in report order.
void classify_joints(const std::vector<Vec2>& dv, double scale, double tol, LimitResult& res) {
  const Index ni = static_cast<Index>(res.interfaces.size());
  for (Index k = 0; k < ni; ++k) {
    const Interface& f = res.interfaces[k];
    const double len = f.length();
    const Vec2 t{(f.b.x - f.a.x) / len, (f.b.y - f.a.y) / len};
    const Vec2 da{dv[2 * k].x * scale, dv[2 * k].y * scale};
    const Vec2 db{dv[2 * k + 1].x * scale, dv[2 * k + 1].y * scale};
    MechanismJoint m;
    m.interface = k;
    m.joint = f.joint;
    m.block_a = f.block_a;
    m.block_b = f.block_b;
    m.position_deg = f.position_deg;
    m.opening_a = da.x * f.normal.x + da.y * f.normal.y;
    m.opening_b = db.x * f.normal.x + db.y * f.normal.y;
    // Rigid motion: the tangential rate is the same at both ends (up to rounding).
    m.slip = 0.5 * std::abs(da.x * t.x + da.y * t.y + db.x * t.x + db.y * t.y);
    if (std::max({std::abs(m.opening_a), std::abs(m.opening_b), m.slip}) <= tol) continue;
    if (m.slip > tol) {
      m.kind = "sliding";
      m.x = 0.5 * (f.a.x + f.b.x);
      m.y = 0.5 * (f.a.y + f.b.y);
    } else {
      // A point contact (an open end) turns about its closed end whatever the open end does.
      const bool pivot_a = f.open_b || (!f.open_a && m.opening_a <= m.opening_b);
      m.kind = (pivot_a ? m.opening_a : m.opening_b) <= tol ? "hinge" : "separation";
      m.side = pivot_a ? "intrados" : "extrados";
      m.x = pivot_a ? f.a.x : f.b.x;
      m.y = pivot_a ? f.a.y : f.b.y;
    }
    res.mechanism.push_back(m);
  }
  // Report order: by Model::joints index (along the arch for arch scenes), then the rest.
  std::stable_sort(res.mechanism.begin(), res.mechanism.end(),
                   [](const MechanismJoint& p, const MechanismJoint& q) {
                     const bool pn = p.joint < 0, qn = q.joint < 0;
                     return pn != qn ? qn : (!pn && p.joint < q.joint);
                   });
}

// Mechanism from the row duals (the full problem at its optimum): the blocks' velocities and
// the joints that move (header, "Mechanism").
void read_mechanism(glp_prob* P, const LpBlocks& B, const LimitOptions& options, LimitResult& res) {
  const std::size_t nb = B.area.size();
  const Index ni = static_cast<Index>(res.interfaces.size());
  std::vector<double> ux(nb, 0.0), uy(nb, 0.0), om(nb, 0.0);  // LP units, about O
  double power = 0.0;
  for (std::size_t i = 0; i < nb; ++i) {
    if (B.first_row[i] < 0) continue;
    ux[i] = glp_get_row_dual(P, B.first_row[i]);
    uy[i] = glp_get_row_dual(P, B.first_row[i] + 1);
    om[i] = glp_get_row_dual(P, B.first_row[i] + 2);
    power += B.area[i] / B.area_ref * (ux[i] - om[i] * B.scaled(B.centroid[i]).y);
  }
  const double sign = power < 0.0 ? -1.0 : 1.0;
  auto velocity = [&](Index i, Vec2 p) {
    const Vec2 r = B.scaled(p);
    return Vec2{sign * (ux[i] - om[i] * r.y), sign * (uy[i] + om[i] * r.x)};
  };
  // Relative velocities (b w.r.t. a) at both ends of every interface.
  std::vector<Vec2> dv(2 * ni);
  double vmax = 0.0;
  for (Index k = 0; k < ni; ++k) {
    const Interface& f = res.interfaces[k];
    for (int end = 0; end < 2; ++end) {
      const Vec2 p = end == 0 ? f.a : f.b;
      const Vec2 vb = velocity(f.block_b, p), va = velocity(f.block_a, p);
      dv[2 * k + end] = {vb.x - va.x, vb.y - va.y};
      vmax = std::max(vmax, std::hypot(dv[2 * k + end].x, dv[2 * k + end].y));
    }
  }
  const double scale = vmax > 0.0 ? 1.0 / vmax : 0.0;
  res.velocities.assign(nb, BlockVelocity{});
  for (std::size_t i = 0; i < nb; ++i) {
    if (B.first_row[i] < 0) continue;
    const Vec2 vc = velocity(static_cast<Index>(i), B.centroid[i]);
    res.velocities[i] = {vc.x * scale, vc.y * scale, sign * om[i] / B.length * scale};
  }
  if (vmax > 0.0) classify_joints(dv, scale, options.motion_tol, res);
}

LimitResult solve_limit_lp(const Model& model, double mu, double gravity, Objective objective,
                           const LimitOptions& options) {
  const bool gravity_only = objective != Objective::Lambda;
  if (!(mu >= 0.0) || !std::isfinite(mu))
    throw std::invalid_argument("limit_analysis: friction must be finite and >= 0");
  if (!(gravity > 0.0) || !std::isfinite(gravity))
    throw std::invalid_argument("limit_analysis: gravity must be > 0");
  const auto t0 = std::chrono::steady_clock::now();

  LimitResult res;
  res.gravity_only = gravity_only;
  res.lambda_la = kNaN;
  res.thrust = kNaN;

  const LpBlocks B = scale_blocks(model, res);
  // Newtons per LP force unit (per out_of_plane thickness as the model has it).
  const double newton = model.material.density * model.out_of_plane * gravity * B.area_ref;

  // Interfaces that touch a free block.
  const std::vector<Interface> found =
      options.interfaces ? std::vector<Interface>{} : find_interfaces(model, options.interface_tol);
  for (const Interface& f : options.interfaces ? *options.interfaces : found)
    if (!model.blocks[f.block_a].fixed || !model.blocks[f.block_b].fixed)
      res.interfaces.push_back(f);
  const Index ni = static_cast<Index>(res.interfaces.size());

  // Columns: 1 = lambda, then the cone edges.
  std::vector<EdgeColumn> cols;
  cols.reserve(4 * ni);
  for (Index k = 0; k < ni; ++k)
    for (int end = 0; end < 2; ++end) {
      cols.push_back({k, end, 1.0});
      if (mu > 0.0) cols.push_back({k, end, -1.0});
    }
  res.rows = 3 * res.free_blocks;
  res.columns = 1 + static_cast<int>(cols.size());

  std::unique_ptr<glp_prob, GlpDeleter> lp(glp_create_prob());
  glp_prob* P = lp.get();
  build_lp(P, model, mu, objective, B, cols, res);
  const int status = solve_lp(P, options, res);
  read_verdict(P, status, objective, newton, res);
  if (status == GLP_OPT || status == GLP_UNBND) read_forces(P, cols, mu, newton, res);
  if (!gravity_only && status == GLP_OPT) read_mechanism(P, B, options, res);

  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace

}  // namespace voussoir
