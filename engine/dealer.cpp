// Dealing cells to threads and ranks (contract in dealer.hpp). The MPI code of the program is
// this file: a build without MPI (VOUSSOIR_MPI off) keeps only the one-process loop.
//
// Messages (MPI_COMM_WORLD, every payload JSON text):
//   kTagAsk   rank r -> 0  {} (a thread's first ask) or {"cell": c, "record": ...} (its last
//                          cell's result); one thread of a rank at a time (it then waits for the
//                          answer, so answers reach the thread that asked)
//   kTagCell  0 -> rank r  {"cell": c, "input": ...}, or {"cell": -1}: nothing left, stop
//   kTagDone  rank r -> 0  every thread of rank r has stopped; what its cells added to the
//                          contact solver's record (engine/solver_report.hpp)
//   kTagShare 0 -> rank r  share_from_dealer's value
//   kTagExit  0 -> rank r  rank 0 is at its end: MPI_Finalize (a collective) may start
// Every receive polls with MPI_Iprobe and sleeps 1 ms between empty polls instead of blocking:
// Open MPI's blocking receives and collectives spin a core, which a rank waiting for rank 0
// (its capacity search, its limit-analysis checks, its writing of the outputs) would take
// from the ranks that compute. A cell lasts seconds; the 1 ms is nothing against it.

#include "engine/dealer.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <thread>

#include "core/schema.hpp"
#include "engine/solver_report.hpp"
#include "engine/stop.hpp"
#include "voussoir/config.hpp"

#if VOUSSOIR_MPI
#include <mpi.h>
#endif

namespace voussoir {
namespace {

int g_rank = 0, g_size = 1;
#if VOUSSOIR_MPI
bool g_mpi = false;         // MPI_Init done (and MPI_Finalize owed)
bool g_serialized = false;  // MPI_THREAD_SERIALIZED provided: several threads of a rank ask
bool g_exit_seen = false;   // ranks 1 to N-1: rank 0's kTagExit has arrived
#endif

// The number of ranks the launcher announces (Open MPI's mpirun, PMI of srun/MPICH), 0 when
// the process was not launched by one.
int launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  if (std::getenv("PMIX_RANK")) return 1;  // PMIx announces the rank only; the size is MPI's
  return 0;
}

bool is_finished(const CellWork& w, std::size_t c) {
  return c < w.finished.size() && w.finished[c];
}

// One process: the threads take the cells in order, one at a time (a dynamic schedule), then
// help the cells still running (CellWork::idle).
void deal_here(const CellWork& w, int threads) {
  const long n = static_cast<long>(w.cells);
  const long asked = threads > 0 ? threads : omp_get_max_threads();
  const int nthreads = static_cast<int>(std::max(1L, w.idle ? asked : std::min(n, asked)));
  std::exception_ptr failure;
  std::atomic<long> next{0};
#pragma omp parallel num_threads(nthreads)
  {
    for (long c = next++; c < n; c = next++) {
      // After a stop request (engine/stop.hpp) no cell starts, and a cell cut short is not
      // taken: its record would journal the interruption as the cell's result.
      if (is_finished(w, c) || stop_requested()) continue;
      nlohmann::json input;
      if (w.input) {
#pragma omp critical(voussoir_deal)
        input = w.input(c);
      }
      const nlohmann::json record = w.run(c, input);
      if (stop_requested()) continue;
#pragma omp critical(voussoir_deal)
      try {
        w.take(c, record);
      } catch (...) {
        if (!failure) failure = std::current_exception();
      }
    }
    if (w.idle) w.idle();
  }
  if (failure) std::rethrow_exception(failure);
  throw_if_stopped();
}

#if VOUSSOIR_MPI

constexpr int kTagAsk = 1, kTagCell = 2, kTagDone = 3, kTagShare = 4, kTagExit = 5;

void send_text(const std::string& text, int to, int tag) {
  MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, to, tag, MPI_COMM_WORLD);
}

// Waits for a message by polling (header comment) and returns its text, and its source and tag
// when asked (`from` and `tag` may be MPI_ANY_SOURCE and MPI_ANY_TAG).
std::string receive_text(int from, int tag, MPI_Status* got = nullptr) {
  MPI_Status status;
  for (int ready = 0;;) {
    MPI_Iprobe(from, tag, MPI_COMM_WORLD, &ready, &status);
    if (ready) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  int count = 0;
  MPI_Get_count(&status, MPI_CHAR, &count);
  std::string text(count, '\0');
  MPI_Recv(text.data(), count, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  if (got) *got = status;
  return text;
}

// Ranks 1 to N-1: rank 0's message of this tag, or false when rank 0 has ended first (its
// kTagExit: it failed before dealing, say on a journal of another deck), and from then on.
bool receive_from_dealer(int tag, std::string& text) {
  if (g_exit_seen) return false;
  MPI_Status status;
  text = receive_text(0, MPI_ANY_TAG, &status);
  g_exit_seen = status.MPI_TAG == kTagExit;
  return status.MPI_TAG == tag;
}

// Rank 0: its main thread answers the other ranks, its other threads run cells.
void deal_as_dealer(const CellWork& w, int threads) {
  std::vector<long> todo;
  for (std::size_t c = 0; c < w.cells; ++c)
    if (!is_finished(w, c)) todo.push_back(static_cast<long>(c));
  std::size_t next = 0;
  auto next_cell = [&] {
    long c = -1;
#pragma omp critical(voussoir_next)
    if (next < todo.size()) c = todo[next++];
    return c;
  };
  std::exception_ptr failure;
  auto take = [&](long c, const nlohmann::json& record) {
#pragma omp critical(voussoir_deal)
    try {
      w.take(c, record);
    } catch (...) {
      if (!failure) failure = std::current_exception();
    }
  };
  auto input_of = [&](long c) {
    nlohmann::json input;
    if (w.input && c >= 0) {
#pragma omp critical(voussoir_deal)
      input = w.input(c);
    }
    return input;
  };
#pragma omp parallel num_threads(threads + 1)
  {
    if (omp_get_thread_num() == 0) {
      for (int done = 0; done < g_size - 1;) {
        MPI_Status status;
        const std::string text = receive_text(MPI_ANY_SOURCE, MPI_ANY_TAG, &status);
        if (status.MPI_TAG == kTagDone) {
          note_solver_runs(nlohmann::json::parse(text));
          ++done;
          continue;
        }
        const nlohmann::json ask = nlohmann::json::parse(text);
        if (ask.contains("cell")) take(ask["cell"].get<long>(), ask["record"]);
        const long c = next_cell();
        send_text(nlohmann::json{{"cell", c}, {"input", input_of(c)}}.dump(), status.MPI_SOURCE,
                  kTagCell);
      }
    } else {
      for (long c = next_cell(); c >= 0; c = next_cell()) take(c, w.run(c, input_of(c)));
    }
  }
  if (failure) std::rethrow_exception(failure);
}

// Ranks 1 to N-1: each thread asks rank 0 for a cell, runs it, sends its record with the next
// ask, until rank 0 has no cell left.
void deal_as_worker(const CellWork& w, int threads) {
  const NscdStats solver_start = solver_record();
#pragma omp parallel num_threads(g_serialized ? threads : 1)
  {
    nlohmann::json ask = nlohmann::json::object();
    for (;;) {
      std::string answer;
      bool dealt = false;
#pragma omp critical(voussoir_mpi)
      if (!g_exit_seen) {
        send_text(ask.dump(), 0, kTagAsk);
        dealt = receive_from_dealer(kTagCell, answer);
      }
      if (!dealt) break;
      const nlohmann::json deal = nlohmann::json::parse(answer);
      const long c = deal.at("cell").get<long>();
      if (c < 0) break;
      ask = {{"cell", c}, {"record", w.run(c, deal["input"])}};
    }
  }
  send_text(solver_runs_since(solver_start).dump(), 0, kTagDone);
}

#endif  // VOUSSOIR_MPI

}  // namespace

Ranks::Ranks(int& argc, char**& argv) {
  const int launched = launched_ranks();
  if (launched == 0) return;
#if VOUSSOIR_MPI
  int provided = 0;
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
    throw RunError(
        "MPI could not start (MPI_Init_thread failed): check the Open MPI runtime "
        "(scripts/install-deps installs it) or run without mpirun (docs/mpi.md)");
  g_mpi = true;
  g_serialized = provided >= MPI_THREAD_SERIALIZED;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
#else
  if (launched > 1) {
    // The launcher's rank, so that one copy says it (main() prints on rank 0 only).
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK"})
      if (const char* v = std::getenv(name)) g_rank = std::atoi(v);
    throw RunError(
        "this voussoir was built without MPI (CMake option VOUSSOIR_MPI off), so "
        "each of the " +
        std::to_string(launched) +
        " copies mpirun started would run the whole study: run it without mpirun, "
        "or install Open MPI (scripts/install-deps) and build again (docs/mpi.md)");
  }
#endif
}

Ranks::~Ranks() {
#if VOUSSOIR_MPI
  if (!g_mpi) return;
  if (g_rank == 0)
    for (int r = 1; r < g_size; ++r) send_text("", r, kTagExit);
  else if (!g_exit_seen)
    receive_text(0, kTagExit);
  MPI_Finalize();
#endif
}

int rank_index() {
  return g_rank;
}
int rank_count() {
  return g_size;
}

nlohmann::json share_from_dealer(const nlohmann::json& value) {
#if VOUSSOIR_MPI
  if (g_size > 1) {
    std::string text;
    if (g_rank != 0)
      return receive_from_dealer(kTagShare, text) ? nlohmann::json::parse(text) : nlohmann::json();
    text = value.dump();
    for (int r = 1; r < g_size; ++r) send_text(text, r, kTagShare);
  }
#endif
  return value;
}

void deal_cells(const CellWork& w, int threads, bool quiet) {
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();
  if (g_rank == 0 && !quiet) {
    const std::size_t kept = std::count(w.finished.begin(), w.finished.end(), char(1));
    if (kept > 0)
      std::fprintf(stderr, "%zu of %zu cells finished in the journal (not run again)\n", kept,
                   w.cells);
    if (g_size > 1)
      std::fprintf(stderr, "%zu cells dealt to %d ranks (%d OpenMP threads each)\n", w.cells - kept,
                   g_size, nthreads);
  }
#if VOUSSOIR_MPI
  if (g_size > 1) {
    if (g_rank == 0)
      deal_as_dealer(w, nthreads);
    else
      deal_as_worker(w, nthreads);
    return;
  }
#endif
  deal_here(w, nthreads);
}

}  // namespace voussoir
