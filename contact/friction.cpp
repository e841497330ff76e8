#include "contact/friction.hpp"

namespace voussoir {

void carry_friction_history(const std::vector<IndexPair>& prev, const std::vector<double>& prev_sx,
                            const std::vector<double>& prev_sy, const std::vector<IndexPair>& next,
                            std::vector<double>& next_sx, std::vector<double>& next_sy) {
  next_sx.assign(next.size(), 0.0);
  next_sy.assign(next.size(), 0.0);
  auto less = [](const IndexPair& p, const IndexPair& q) {
    return p.a < q.a || (p.a == q.a && p.b < q.b);
  };
  std::size_t i = 0;
  for (std::size_t k = 0; k < next.size(); ++k) {
    while (i < prev.size() && less(prev[i], next[k])) ++i;
    if (i < prev.size() && prev[i] == next[k]) {
      next_sx[k] = prev_sx[i];
      next_sy[k] = prev_sy[i];
    }
  }
}

}  // namespace voussoir
