#pragma once
// Dealing independent cells to the threads of one process or to the ranks of an MPI run
// (`voussoir sweep`, `stability`, `pulse --curve` and `ida`; docs/mpi.md).
//
// A study is N independent cells (a sweep's or a map's grid cells, a curve's frequencies). The
// command gives deal_cells() what one cell is (`run`: cell c -> its journal record) and what to
// do with a finished one (`take`); the dealer decides where each cell runs:
//   - one process (no mpirun, `mpirun -n 1`, or a build without MPI): the cells are an OpenMP
//     loop with a dynamic schedule over `threads` threads;
//   - `mpirun -n N` (N > 1): rank 0 deals. Its main thread answers the other ranks (a rank that
//     finishes a cell sends its record and gets the next cell index, so uneven cells idle no
//     one) and its other `threads` threads take cells themselves; every other rank runs its
//     `threads` threads, each asking rank 0 for one cell at a time.
// `take` runs on rank 0 only, one record at a time, in the order the cells finish: the command
// journals the record, stores it by cell index and prints progress there, so the journal and
// the gathering share one code path and the outputs do not depend on which rank ran which cell.
// Records cross ranks as JSON text (nlohmann dump, doubles to the shortest exact digits).
//
// MPI starts only when the process was launched by mpirun or srun (their environment
// variables); a plain `build/voussoir` never touches MPI. Other commands run on rank 0 alone.

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace voussoir {

// Starts MPI for the life of the program when launched by mpirun/srun (main() holds one).
// Throws RunError with a clear message when MPI cannot start, or when this build has no MPI
// and was launched as several ranks (each would run the whole study).
class Ranks {
 public:
  Ranks(int& argc, char**& argv);
  ~Ranks();
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;
};

// This process's rank and the number of ranks (0 and 1 without MPI).
int rank_index();
int rank_count();
// Rank 0: the one that deals, gathers, writes the outputs and prints.
inline bool is_dealer_rank() {
  return rank_index() == 0;
}

// Rank 0's value on every rank (every rank calls it at the same point; null on the others when
// rank 0 has ended without it). A no-op in one process.
nlohmann::json share_from_dealer(const nlohmann::json& value);

struct CellWork {
  std::size_t cells = 0;
  // Rank 0: cells already finished (a --resume journal), not dealt; empty = none.
  std::vector<char> finished;
  // Rank 0 (optional): what cell c's run needs beyond its index, sent with the cell.
  std::function<nlohmann::json(std::size_t)> input;
  // Any rank: runs cell c and returns its record. Must not throw: a failing cell is a record
  // that says so (the commands' "error" field), and the other cells go on.
  std::function<nlohmann::json(std::size_t, const nlohmann::json& input)> run;
  // Rank 0: a finished cell's record, one at a time, in the order the cells finish.
  std::function<void(std::size_t, const nlohmann::json& record)> take;
  // One process (optional): a thread with no cell left to start helps the cells still running
  // (`pulse --curve` and `ida` run their searches' next runs ahead, engine/runs_ahead.hpp) and
  // returns when there is nothing left to help with. Must not throw. With it every thread
  // starts, even when there are fewer cells than threads.
  std::function<void()> idle;
};

// Runs every cell not finished (header comment) on `threads` OpenMP threads per rank (0: the
// OpenMP default). Returns when every cell has been taken on rank 0 and every rank is done.
// Prints on stderr, unless quiet, how many cells a journal held and on how many ranks the
// others run (only when there is a journal's cell or more than one rank).
void deal_cells(const CellWork& work, int threads, bool quiet);

}  // namespace voussoir
