// `voussoir run DECK`: one simulation to `output.file` (HDF5 + XDMF) and a JSON summary.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/cst.hpp"
#include "drivers/commands.hpp"
#include "drivers/run.hpp"
#include "drivers/setup.hpp"
#include "io/hdf5_output.hpp"
#include "io/json.hpp"

namespace voussoir {
namespace {

// Cauchy stress (sxx, syy, sxy) of every triangle, interleaved, for snapshots.
std::vector<double> triangle_stresses(const Simulation& sim) {
  const CstLaw law{sim.ctx.lame_lambda, sim.ctx.shear_modulus, sim.ctx.eta};
  std::vector<double> s(3 * static_cast<size_t>(sim.model.tris.size()));
  for (Index e = 0; e < sim.model.tris.size(); ++e) {
    const Stress2 st = triangle_cauchy_stress(sim.model, e, law);
    s[3 * e] = st.xx;
    s[3 * e + 1] = st.yy;
    s[3 * e + 2] = st.xy;
  }
  return s;
}

SeriesRecord series_record(const Simulation& sim) {
  const EnergyLedger& l = sim.ledger;
  SeriesRecord r;
  r.time = sim.ctx.time;
  r.kinetic = l.kinetic;
  r.strain = l.strain;
  r.contact = l.contact;
  r.damping_dissipated = l.damping_dissipated;
  r.friction_dissipated = l.friction_dissipated;
  r.external_work = l.external_work;
  r.max_displacement = max_free_displacement(sim.model);
  r.active_contacts = sim.contact.active_pairs();
  r.energy_balance_error = l.balance_error();
  return r;
}

}  // namespace

int command_run(const Config& config, const CommonOptions& common, const RunOptions& opts) {
  SetupInfo info;
  Simulation sim = make_simulation(config, &info);
  const std::string out_path = opts.output.empty() ? config.output.file : opts.output;
  const bool write = !out_path.empty();
  const bool want_stress = std::find(config.output.fields.begin(), config.output.fields.end(),
                                     "stress") != config.output.fields.end();

  RunWriter writer;
  if (write) writer.open(out_path, sim.model, config.output.fields);

  // Series every 1/10 of the snapshot interval (at least every step); snapshots every
  // output.every of simulated time.
  const double snap_every = config.output.every;
  const double series_every = std::max(info.dt, snap_every / 10.0);
  double next_snapshot = 0.0;
  double max_energy_error = 0.0;
  auto sample = [&](const Simulation& s) {
    max_energy_error = std::max(max_energy_error, s.ledger.balance_error());
    if (!write) return true;
    writer.append_series(series_record(s));
    if (s.ctx.time >= next_snapshot - 0.5 * info.dt) {
      writer.write_snapshot(s.ctx.time, s.model,
                            want_stress ? triangle_stresses(s) : std::vector<double>{});
      next_snapshot += snap_every;
    }
    return true;
  };

  LoopStats stats;
  try {
    stats = run_loop(sim, config.solver.end_time, series_every, sample, common.quiet, "run");
    if (write) writer.close_complete();
  } catch (const std::exception& e) {
    if (write) writer.close_incomplete(e.what());
    throw;
  }

  const double dmax = max_free_displacement(sim.model);
  std::printf("%lld steps of %.4g s to t = %.4g s on %d triangles in %.2f s wall (%.3g "
              "triangle-steps/s)\n",
              stats.steps, info.dt, sim.ctx.time, sim.model.tris.size(), stats.wall_s,
              stats.steps * double(sim.model.tris.size()) / std::max(stats.wall_s, 1e-9));
  std::printf("final kinetic energy %.4g J, max displacement %.4g m, energy balance error "
              "%.2e, contacts %lld (max %lld)\n",
              sim.ledger.kinetic, dmax, sim.ledger.balance_error(),
              static_cast<long long>(sim.contact.active_pairs()),
              static_cast<long long>(stats.max_active_pairs));
  if (write) std::printf("output %s (+ %s)\n", out_path.c_str(), writer.xdmf_path().c_str());

  if (!common.json_path.empty()) {
    nlohmann::json j = {{"steps", stats.steps},
                        {"triangles", sim.model.tris.size()},
                        {"dt", info.dt},
                        {"dt_stable", info.dt_stable},
                        {"end_time", sim.ctx.time},
                        {"wall_s", stats.wall_s},
                        {"final_kinetic_energy", sim.ledger.kinetic},
                        {"max_displacement", dmax},
                        {"energy_balance_error", sim.ledger.balance_error()},
                        {"max_energy_balance_error", max_energy_error},
                        {"energy",
                         {{"kinetic", sim.ledger.kinetic},
                          {"strain", sim.ledger.strain},
                          {"contact", sim.ledger.contact},
                          {"damping_dissipated", sim.ledger.damping_dissipated},
                          {"friction_dissipated", sim.ledger.friction_dissipated},
                          {"external_work", sim.ledger.external_work}}},
                        {"active_contacts", sim.contact.active_pairs()},
                        {"max_active_contacts", stats.max_active_pairs},
                        {"output", out_path}};
    write_json(j, common.json_path);
  }
  return 0;
}

}  // namespace voussoir
