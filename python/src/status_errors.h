// How the bindings report failures to Python: the one mapping from absl::Status to Python
// exceptions, and the checks of numpy arguments.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace inscribe::python {

namespace py = pybind11;

// Raises the Python exception for a non-OK `status`, with its message unchanged:
// INVALID_ARGUMENT -> ValueError, NOT_FOUND -> FileNotFoundError (in-process, only paths are
// looked up; inscribe.Scene raises KeyError for its unknown ids itself), anything else ->
// inscribe.Error whose `.code` is the code's name
// ("FAILED_PRECONDITION"). Never returns.
[[noreturn]] void RaiseStatus(const absl::Status& status);

// The value of `result`, or RaiseStatus.
template <typename T>
T ValueOrRaise(absl::StatusOr<T> result) {
  if (!result.ok()) RaiseStatus(result.status());
  return std::move(*result);
}

inline void OkOrRaise(const absl::Status& status) {
  if (!status.ok()) RaiseStatus(status);
}

// `value` as a C-contiguous 2-D numpy array of dtype T with `cols` columns (any number of
// rows), without copying a numpy array that already is one. A numpy array of another dtype is
// refused with TypeError, a wrong shape or a non-contiguous array with ValueError, each naming
// `name` and what was given; a Python sequence (not a numpy array) is converted once.
template <typename T>
py::array_t<T> RequireMatrix(py::handle value, py::ssize_t cols, const char* name);

// `value` as a C-contiguous (N, cols) array of T (double or std::int32_t), converted once from a
// numpy array of any dtype of T's kind (floating for double; signed or unsigned integer for
// int32, every value checked to fit: ValueError naming the first that does not) and any layout,
// or from a Python sequence; no copy when `value` already is one. TypeError for another kind,
// ValueError for another shape, each naming `name` and what was given. Meshes' arrays only:
// everything else is taken as RequireMatrix takes it.
template <typename T>
py::array_t<T> ConvertMatrix(py::handle value, py::ssize_t cols, const char* name);

// A C-contiguous array of dtype T of shape (length,) or (N, length); same refusals as
// RequireMatrix. Returns it as 2-D (one row for a 1-D array), without copying.
template <typename T>
py::array_t<T> RequireRowOrMatrix(py::handle value, py::ssize_t length, const char* name);

// A read-only numpy view of `rows` x `cols` values of T at `data` (`rows` values when cols is
// 0: a 1-D view), row stride `row_bytes`, that keeps `owner` alive: no copy.
template <typename T>
py::array ReadOnlyView(const T* data, py::ssize_t rows, py::ssize_t cols, py::ssize_t row_bytes,
                       py::handle owner);

}  // namespace inscribe::python
