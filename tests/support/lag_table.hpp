#pragma once
// A parameter table the online tests serve: every joint of a KR 16 the same first-order lag at
// 2 ms, q̂(k) = -a q̂(k-1) + b q_d(k-1), one cell for every speed; the caller sets form and preview.
#include <string>

#include "ident/parameter_table.hpp"

namespace imscal::test_support {

inline ident::ParameterTable lag_table(double a, double b) {
  ident::ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = 0.002;
  for (int j = 0; j < 6; ++j) {
    ident::JointParameters joint;
    joint.name = std::string(1, 'A').append(std::to_string(j + 1));
    joint.dimensions = {{ident::OperatingQuantity::kSpeed, {0.0, 100.0}}};
    ident::CellParameters cell;
    cell.bands = {0};
    cell.structure = {1, 1, 1};
    cell.a = {a};
    cell.b = {b};
    joint.cells = {cell};
    t.joints.push_back(joint);
  }
  return t;
}

}  // namespace imscal::test_support
