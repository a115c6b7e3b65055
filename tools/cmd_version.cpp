// `imscal version`: the version and the versions of the numerical libraries it was built with.
#include <GeographicLib/Config.h>
#include <ceres/version.h>
#include <fmt/format.h>

#include <Eigen/Core>
#include <iostream>

#include "core/version.hpp"
#include "tools/command_registry.hpp"

namespace {
imscal::tools::CommandRegistration registration{
    "version", "Print the version of imscal and of the libraries it uses", [](CLI::App& sub) {
      sub.callback([] {
        std::cout << fmt::format("imscal {}\nEigen {}.{}.{}\nCeres {}\nGeographicLib {}\n",
                                 imscal::kVersion, EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION,
                                 EIGEN_MINOR_VERSION, CERES_VERSION_STRING,
                                 GEOGRAPHICLIB_VERSION_STRING);
      });
    }};
}  // namespace
