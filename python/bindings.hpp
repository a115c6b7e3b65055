#pragma once
// The parts of the Python module `imscal`, one per library folder (python/*_binding.cpp), and the
// numpy conversions they share. Arrays are float64, one row per sample; units in the key names.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace imscal::python {

namespace py = pybind11;

void bind_input_error(py::module_& m);
void bind_ims(py::module_& m);
void bind_calib(py::module_& m);
void bind_eval(py::module_& m);
void bind_ident(py::module_& m);

// rows x cols array filled by value(row, col).
template <typename Value>
py::array_t<double> matrix(std::size_t rows, std::size_t cols, Value value) {
  py::array_t<double> out({rows, cols});
  auto view = out.mutable_unchecked<2>();
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < cols; ++c) {
      view(static_cast<py::ssize_t>(r), static_cast<py::ssize_t>(c)) = value(r, c);
    }
  }
  return out;
}

inline py::array_t<double> vector_array(const std::vector<double>& values) {
  return py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data());
}

inline double quaternion_wxyz(const Eigen::Quaterniond& q, std::size_t i) {
  return i == 0 ? q.w() : q.vec()[static_cast<Eigen::Index>(i - 1)];
}

}  // namespace imscal::python
