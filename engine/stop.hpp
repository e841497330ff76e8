#pragma once
// Stopping a long computation from outside it: the Python module's Ctrl-C (docs/guide/python.md)
// asks for a stop, every run of the engine checks the request at each step and ends with
// Interrupted, and the cells not yet started are not run. One flag for the process: a stop
// ends every computation in progress.

#include "core/schema.hpp"

namespace voussoir {

// A computation ended by request_stop(). A RunError, so that whatever turns a failed run into a
// record or a message treats it as a failure; the caller that asked for the stop reports it.
struct Interrupted : RunError {
  Interrupted() : RunError("stopped on request (interrupted)") {}
};

void request_stop();
void clear_stop();
bool stop_requested();

// Throws Interrupted when a stop was asked for.
inline void throw_if_stopped() {
  if (stop_requested()) throw Interrupted();
}

}  // namespace voussoir
