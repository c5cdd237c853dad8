// Long core calls from Python: run without the GIL, report progress to a Python callable, and
// stop on Ctrl-C.
#pragma once

#include <pybind11/pybind11.h>

#include <functional>

#include "absl/status/status.h"
#include "inscribe/medial/medial_spheres.h"

namespace inscribe::python {

namespace py = pybind11;

// Runs `work` on a worker thread while the calling thread, without the GIL, waits for it. Every
// 50 ms (and once at the end) the calling thread takes the GIL, checks for signals
// (PyErr_CheckSignals: Ctrl-C raises KeyboardInterrupt there) and passes the latest progress
// fraction, when it changed, to `progress` (None: no callback; a progress bar such as tqdm's is
// advanced as inscribe._progress.progress_callback says). A signal, or an exception from
// `progress`, sets the control's cancel flag, waits for `work` to return (core polls the flag
// and returns CANCELLED promptly) and re-raises that exception. Otherwise returns what `work`
// returned. `work` must not touch Python objects.
absl::Status RunInterruptible(const py::object& progress,
                              const std::function<absl::Status(const GenerationControl&)>& work);

}  // namespace inscribe::python
