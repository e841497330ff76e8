// engine/dealer.hpp in one process (no mpirun): every cell not finished runs once, on the
// threads, with its input; every record is taken once; a failing take is rethrown after the
// other cells ran. The MPI path is tested through the program (ctest -L mpi,
// tests/python/mpi_ranks.py).

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "engine/dealer.hpp"

namespace voussoir {
namespace {

TEST(Dealer, OneProcessWithoutMpirun) {
  EXPECT_EQ(rank_index(), 0);
  EXPECT_EQ(rank_count(), 1);
  EXPECT_TRUE(is_dealer_rank());
  const nlohmann::json v = {{"lambda_star", 0.25}};
  EXPECT_EQ(share_from_dealer(v), v);
}

TEST(Dealer, RunsEveryUnfinishedCellOnceAndTakesItsRecord) {
  const std::size_t n = 10;
  std::vector<int> runs(n, 0), takes(n, 0);
  std::vector<nlohmann::json> records(n);
  CellWork work;
  work.cells = n;
  work.finished.assign(n, 0);
  work.finished[2] = work.finished[7] = 1;
  work.input = [](std::size_t c) { return nlohmann::json{{"given", 100 + c}}; };
  work.run = [&](std::size_t c, const nlohmann::json& input) {
    ++runs[c];  // one cell, one thread
    return nlohmann::json{{"cell", c}, {"square", c * c}, {"given", input.at("given")}};
  };
  work.take = [&](std::size_t c, const nlohmann::json& record) {
    ++takes[c];  // serialised by the dealer
    records[c] = record;
  };
  deal_cells(work, 3, true);
  for (std::size_t c = 0; c < n; ++c) {
    const int expected = work.finished[c] ? 0 : 1;
    EXPECT_EQ(runs[c], expected) << c;
    EXPECT_EQ(takes[c], expected) << c;
    if (!expected) continue;
    EXPECT_EQ(records[c].at("cell").get<std::size_t>(), c);
    EXPECT_EQ(records[c].at("square").get<std::size_t>(), c * c);
    EXPECT_EQ(records[c].at("given").get<std::size_t>(), 100 + c);
  }
}

TEST(Dealer, AFailingTakeIsRethrownAfterTheOtherCells) {
  const std::size_t n = 6;
  std::vector<int> takes(n, 0);
  CellWork work;
  work.cells = n;
  work.run = [](std::size_t c, const nlohmann::json&) { return nlohmann::json{{"cell", c}}; };
  work.take = [&](std::size_t c, const nlohmann::json&) {
    ++takes[c];
    if (c == 1) throw std::runtime_error("cannot write the journal");
  };
  EXPECT_THROW(deal_cells(work, 2, true), std::runtime_error);
  for (std::size_t c = 0; c < n; ++c) EXPECT_EQ(takes[c], 1) << c;
}

}  // namespace
}  // namespace voussoir
