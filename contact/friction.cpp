#include "contact/friction.hpp"

#include <algorithm>
#include <cstddef>

namespace voussoir {

namespace {

// Calls copy(i, k) for every pair next[k] (sorted) that was also prev[i] (sorted): linear merge.
template <class Copy>
void for_each_kept(const std::vector<IndexPair>& prev, const std::vector<IndexPair>& next,
                   Copy copy) {
  std::size_t i = 0;
  for (std::size_t k = 0; k < next.size(); ++k) {
    while (i < prev.size() &&
           (prev[i].a < next[k].a || (prev[i].a == next[k].a && prev[i].b < next[k].b)))
      ++i;
    if (i < prev.size() && prev[i] == next[k]) copy(i, k);
  }
}

}  // namespace

void carry_friction_history(const std::vector<IndexPair>& prev, const std::vector<double>& prev_sx,
                            const std::vector<double>& prev_sy, const std::vector<IndexPair>& next,
                            std::vector<double>& next_sx, std::vector<double>& next_sy) {
  next_sx.assign(next.size(), 0.0);
  next_sy.assign(next.size(), 0.0);
  for_each_kept(prev, next, [&](std::size_t i, std::size_t k) {
    next_sx[k] = prev_sx[i];
    next_sy[k] = prev_sy[i];
  });
}

void carry_pair_values(const std::vector<IndexPair>& prev, const std::vector<double>& prev_values,
                       std::size_t width, const std::vector<IndexPair>& next,
                       std::vector<double>& next_values) {
  next_values.assign(width * next.size(), 0.0);
  for_each_kept(prev, next, [&](std::size_t i, std::size_t k) {
    std::copy_n(prev_values.begin() + std::ptrdiff_t(width * i), width,
                next_values.begin() + std::ptrdiff_t(width * k));
  });
}

}  // namespace voussoir
