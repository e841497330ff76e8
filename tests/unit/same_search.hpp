#pragma once
// Two capacity searches that must be one and the same: lambda*, the bracket and every trial
// (lambda, verdict, steps, largest displacement) bit for bit, in the same order.

#include <gtest/gtest.h>

#include <cstddef>

#include "drivers/capacity.hpp"

namespace voussoir {

inline void expect_same_search(const CapacityResult& a, const CapacityResult& b) {
  EXPECT_EQ(a.lambda_star, b.lambda_star);
  EXPECT_EQ(a.lo, b.lo);
  EXPECT_EQ(a.hi, b.hi);
  ASSERT_EQ(a.trials.size(), b.trials.size());
  for (std::size_t i = 0; i < a.trials.size(); ++i) {
    EXPECT_EQ(a.trials[i].lambda, b.trials[i].lambda) << "trial " << i;
    EXPECT_EQ(a.trials[i].collapsed, b.trials[i].collapsed) << "trial " << i;
    EXPECT_EQ(a.trials[i].steps, b.trials[i].steps) << "trial " << i;
    EXPECT_EQ(a.trials[i].max_displacement, b.trials[i].max_displacement) << "trial " << i;
  }
}

}  // namespace voussoir
