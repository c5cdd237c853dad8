#include "interruptible.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "absl/strings/str_cat.h"

namespace inscribe::python {

absl::Status RunInterruptible(const py::object& progress,
                              const std::function<absl::Status(const GenerationControl&)>& work) {
  const py::object report =
      py::module_::import("inscribe._progress").attr("progress_callback")(progress);
  std::atomic<bool> cancel{false};
  std::atomic<double> fraction{-1.0};
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  absl::Status status;

  GenerationControl control;
  control.cancel = &cancel;
  control.on_progress = [&fraction](double f) { fraction.store(f, std::memory_order_relaxed); };

  std::thread worker([&] {
    absl::Status result;
    try {
      result = work(control);
    } catch (const std::exception& e) {
      result = absl::InternalError(absl::StrCat("unexpected exception: ", e.what()));
    }
    std::lock_guard<std::mutex> lock(mutex);
    status = std::move(result);
    done = true;
    finished.notify_all();
  });

  std::optional<py::error_already_set> raised;
  double reported = -1.0;
  for (bool last = false; !last;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex);
      finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; });
      last = done;
    }
    if (raised) continue;  // cancelled: wait for the worker only
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      const double now = fraction.load(std::memory_order_relaxed);
      if (!report.is_none() && now >= 0.0 && now != reported) {
        reported = now;
        report(now);
      }
    } catch (py::error_already_set& error) {
      raised.emplace(std::move(error));
      cancel.store(true);
    }
  }
  worker.join();
  if (raised) throw std::move(*raised);
  return status;
}

}  // namespace inscribe::python
