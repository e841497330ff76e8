// The stop request of engine/stop.hpp: an atomic flag, read with relaxed order at every step
// (a stop need not be seen at once, only within a step or two).

#include "engine/stop.hpp"

#include <atomic>

namespace voussoir {
namespace {
std::atomic<bool> g_stop{false};
}

void request_stop() {
  g_stop.store(true, std::memory_order_relaxed);
}

void clear_stop() {
  g_stop.store(false, std::memory_order_relaxed);
}

bool stop_requested() {
  return g_stop.load(std::memory_order_relaxed);
}

}  // namespace voussoir
