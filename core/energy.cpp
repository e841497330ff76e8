#include "core/energy.hpp"

#include <algorithm>
#include <cmath>

namespace voussoir {

double EnergyLedger::balance_error() const {
  if (max_energy <= 0.0) return 0.0;
  return std::abs(external_work - stored() - dissipated()) / max_energy;
}

void EnergyLedger::update_max() {
  max_energy = std::max({max_energy, std::abs(external_work), kinetic, strain, contact,
                         dissipated()});
}

}  // namespace voussoir
