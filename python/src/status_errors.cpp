#include "status_errors.h"

#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>

#include "absl/strings/str_cat.h"

namespace inscribe::python {

void RaiseStatus(const absl::Status& status) {
  const std::string message(status.message());
  switch (status.code()) {
    case absl::StatusCode::kInvalidArgument:
      throw py::value_error(message);
    case absl::StatusCode::kNotFound:
      PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
      throw py::error_already_set();
    default: {
      // inscribe.Error lives in Python (inscribe/_errors.py) so that the service client raises
      // the same class.
      py::object error_type = py::module_::import("inscribe._errors").attr("Error");
      py::object error = error_type(message, absl::StatusCodeToString(status.code()));
      PyErr_SetObject(error_type.ptr(), error.ptr());
      throw py::error_already_set();
    }
  }
}

namespace {

std::string Describe(py::handle value) {
  if (py::isinstance<py::array>(value)) {
    py::array array = py::reinterpret_borrow<py::array>(value);
    std::string shape = "(";
    for (py::ssize_t i = 0; i < array.ndim(); ++i) {
      absl::StrAppend(&shape, i > 0 ? ", " : "", array.shape(i));
    }
    if (array.ndim() == 1) shape += ",";
    shape += ")";
    return absl::StrCat(std::string(py::str(array.dtype())), " array of shape ", shape);
  }
  return std::string(py::str(py::type::of(value).attr("__name__")));
}

template <typename T>
py::array_t<T> RequireArray(py::handle value, const char* name) {
  const std::string dtype_name = py::str(py::dtype::of<T>());
  if (py::isinstance<py::array>(value)) {
    if (!py::isinstance<py::array_t<T>>(value)) {
      throw py::type_error(absl::StrCat(name, " must be a ", dtype_name, " array, got a ",
                                        Describe(value), " (convert it with .astype(np.",
                                        dtype_name, "))"));
    }
    py::array_t<T> array = py::reinterpret_borrow<py::array_t<T>>(value);
    if (!(array.flags() & py::array::c_style)) {
      throw py::value_error(absl::StrCat(name, " must be C-contiguous, got a non-contiguous ",
                                         Describe(value), " (use np.ascontiguousarray)"));
    }
    return array;
  }
  // A list or tuple: one explicit conversion. Refuse what numpy cannot make numbers of.
  py::object converted = py::module_::import("numpy").attr("asarray")(value, py::dtype::of<T>());
  return py::reinterpret_borrow<py::array_t<T>>(converted);
}

}  // namespace

template <typename T>
py::array_t<T> RequireMatrix(py::handle value, py::ssize_t cols, const char* name) {
  py::array_t<T> array = RequireArray<T>(value, name);
  if (array.ndim() != 2 || array.shape(1) != cols) {
    throw py::value_error(
        absl::StrCat(name, " must have shape (N, ", cols, "), got a ", Describe(array)));
  }
  return array;
}

template <typename T>
py::array_t<T> ConvertMatrix(py::handle value, py::ssize_t cols, const char* name) {
  if (!py::isinstance<py::array>(value)) return RequireMatrix<T>(value, cols, name);
  py::array array = py::reinterpret_borrow<py::array>(value);
  if (array.ndim() != 2 || array.shape(1) != cols) {
    throw py::value_error(
        absl::StrCat(name, " must have shape (N, ", cols, "), got a ", Describe(array)));
  }
  const char kind = array.dtype().kind();
  if constexpr (std::is_floating_point_v<T>) {
    if (kind != 'f') {
      throw py::type_error(absl::StrCat(name, " must be a float array (float64, float32, ...), ",
                                        "got a ", Describe(array)));
    }
  } else {
    if (kind != 'i' && kind != 'u') {
      throw py::type_error(absl::StrCat(name, " must be an integer array (int32, int64, ...), ",
                                        "got a ", Describe(array)));
    }
    if (array.size() > 0 && !py::isinstance<py::array_t<T>>(array)) {
      const py::int_ lowest(std::numeric_limits<T>::min());
      const py::int_ highest(std::numeric_limits<T>::max());
      for (const char* extreme : {"min", "max"}) {
        const py::object bound = array.attr(extreme)().attr("item")();
        if (bound < lowest || bound > highest) {
          throw py::value_error(absl::StrCat(name, " holds ", std::string(py::str(bound)),
                                             ", which int32 cannot hold: indices must be in "
                                             "[0, 2^31)"));
        }
      }
    }
  }
  return py::reinterpret_borrow<py::array_t<T>>(
      py::module_::import("numpy").attr("ascontiguousarray")(array, py::dtype::of<T>()));
}

template <typename T>
py::array_t<T> RequireRowOrMatrix(py::handle value, py::ssize_t length, const char* name) {
  py::array_t<T> array = RequireArray<T>(value, name);
  if (array.ndim() == 1 && array.shape(0) == length) {
    return py::reinterpret_steal<py::array_t<T>>(array.attr("reshape")(1, length).release());
  }
  if (array.ndim() != 2 || array.shape(1) != length) {
    throw py::value_error(absl::StrCat(name, " must have shape (", length, ",) or (N, ", length,
                                       "), got a ", Describe(array)));
  }
  return array;
}

template <typename T>
py::array ReadOnlyView(const T* data, py::ssize_t rows, py::ssize_t cols, py::ssize_t row_bytes,
                       py::handle owner) {
  py::array view = cols == 0
                       ? py::array(py::dtype::of<T>(), {rows}, {row_bytes}, data, owner)
                       : py::array(py::dtype::of<T>(), {rows, cols},
                                   {row_bytes, static_cast<py::ssize_t>(sizeof(T))}, data, owner);
  view.attr("flags").attr("writeable") = false;
  return view;
}

template py::array_t<double> RequireMatrix<double>(py::handle, py::ssize_t, const char*);
template py::array_t<std::int32_t> RequireMatrix<std::int32_t>(py::handle, py::ssize_t,
                                                               const char*);
template py::array_t<double> ConvertMatrix<double>(py::handle, py::ssize_t, const char*);
template py::array_t<std::int32_t> ConvertMatrix<std::int32_t>(py::handle, py::ssize_t,
                                                               const char*);
template py::array_t<double> RequireRowOrMatrix<double>(py::handle, py::ssize_t, const char*);
template py::array ReadOnlyView<double>(const double*, py::ssize_t, py::ssize_t, py::ssize_t,
                                        py::handle);
template py::array ReadOnlyView<std::int32_t>(const std::int32_t*, py::ssize_t, py::ssize_t,
                                              py::ssize_t, py::handle);
template py::array ReadOnlyView<std::uint64_t>(const std::uint64_t*, py::ssize_t, py::ssize_t,
                                               py::ssize_t, py::handle);
template py::array ReadOnlyView<bool>(const bool*, py::ssize_t, py::ssize_t, py::ssize_t,
                                      py::handle);

}  // namespace inscribe::python
