#pragma once
// Two capacity searches that must be one and the same: lambda*, the bracket and every trial
// (lambda, verdict, steps, largest displacement) bit for bit, in the same order; and a quiet
// search with a fresh journal, for the tests that resume one.

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdio>
#include <string>

#include "commands/capacity.hpp"

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

// A quiet search writing its journal to `name` in the test's temp dir, emptied first.
inline CapacitySearch journalled_search(const std::string& name) {
  CapacitySearch search;
  search.quiet = true;
  search.journal = ::testing::TempDir() + name;
  std::remove(search.journal.c_str());
  return search;
}

}  // namespace voussoir
