// Full explicit step on a large structure (bench/wall.hpp: a running-bond wall, by default
// 20 courses x 20 blocks, 102912 triangles), 1 and 2 OpenMP threads, and the memory per
// triangle. A small harness rather than Google Benchmark: the figure of merit needs wall time
// (two threads), process CPU time and the load average side by side.
//
// Run: build-*/bench_wall [courses per_course [steps [cells_x cells_y [runs]]]]
// (runs: the thread count of each timed run, default "1212").
// Prints, per run: threads, wall s, process CPU s, the main thread's CPU s, triangle-steps
// per wall second, the stage times (wall) and the load average before and after. Every run
// starts from a copy of the same settled state; the final states are compared bit for bit.
// With OMP_WAIT_POLICY=passive a waiting thread sleeps: the main thread's CPU time is then the
// serial work plus its share of the parallel work (docs/benchmarks.md uses per-thread
// instruction counts for the same purpose, being independent of the load).
// Memory: VmRSS (/proc/self/status) before building, after building and after 100 steps on
// two threads (contact pairs and the threaded element workspace allocated), divided by the
// triangle count. Use OMP_WAIT_POLICY=passive on a shared machine (docs/benchmarks.md).

#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <string>

#include "bench/wall.hpp"

using namespace voussoir;

namespace {

double vm_rss_kib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6);
  return 0.0;
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

double cpu_seconds(clockid_t clock) {
  timespec t;
  clock_gettime(clock, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  const int courses = argc > 1 ? std::atoi(argv[1]) : 20;
  const int per_course = argc > 2 ? std::atoi(argv[2]) : 20;
  const int steps = argc > 3 ? std::atoi(argv[3]) : 200;
  const int cells_x = argc > 5 ? std::atoi(argv[4]) : 16;
  const int cells_y = argc > 5 ? std::atoi(argv[5]) : 8;
  const std::string runs = argc > 6 ? argv[6] : "1212";  // thread count of each timed run

  omp_set_num_threads(1);
  const double rss0 = vm_rss_kib();
  Simulation settled = bench::wall_simulation(courses, per_course, cells_x, cells_y);
  const double rss1 = vm_rss_kib();
  omp_set_num_threads(2);  // so that the threaded element workspace is allocated (and counted)
  for (int k = 0; k < 100; ++k) advance(settled);  // joints close; contact pairs allocated
  const double rss2 = vm_rss_kib();
  const double tris = double(settled.model.tris.size());
  std::printf(
      "wall %d x %d blocks of %d x %d cells: %.0f triangles, %d nodes, %zu candidate "
      "pairs, dt %.3e s\n",
      courses, per_course, cells_x, cells_y, tris, settled.model.nodes.size(),
      settled.contact.candidate_pairs(), settled.ctx.dt);
  std::printf(
      "memory: model + contact setup %.0f B/triangle, + step state (pairs, viscous buffer, "
      "element workspace) %.0f "
      "B/triangle (VmRSS %.0f -> %.0f -> %.0f KiB)\n",
      1024.0 * (rss1 - rss0) / tris, 1024.0 * (rss2 - rss0) / tris, rss0, rss1, rss2);

  std::vector<double> reference_x;
  for (const char run : runs) {
    const int threads = run - '0';
    Simulation sim = settled;
    sim.timers = StageTimers{};
    sim.timers.enabled = true;
    omp_set_num_threads(threads);
    const std::string load_before = load_average();
    const double cpu0 = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
    const double main0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) advance(sim);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu0;
    const double main_cpu = cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - main0;
    const StageTimers& t = sim.timers;
    const double ms = 1e3 / steps;
    std::printf(
        "threads %d: %d steps, wall %.3f s, CPU %.3f s (main thread %.3f s), %.3g "
        "tri-steps/wall s (per step ms: broad %.3f elements %.3f contact %.3f loads %.3f "
        "integrate %.3f), load %s -> %s\n",
        threads, steps, wall, cpu, main_cpu, tris * steps / wall, t.broad * ms, t.elements * ms,
        t.contact * ms, t.loads * ms, t.integrate * ms, load_before.c_str(),
        load_average().c_str());
    if (reference_x.empty()) {
      reference_x = sim.model.nodes.x;
    } else if (std::memcmp(reference_x.data(), sim.model.nodes.x.data(),
                           reference_x.size() * sizeof(double)) != 0) {
      std::printf("ERROR: final positions differ from the first run\n");
      return 1;
    }
  }
  std::printf("final positions identical for all runs\n");
  return 0;
}
