# OpenCV's calib3d module (Debian: libopencv-calib3d-dev), used only by tests and benchmarks as a
# peer implementation of hand-eye calibration. Debian ships no OpenCVConfig.cmake without the
# full libopencv-dev, so the headers and the two libraries are located directly.
# Defines the imported target OpenCVCalib3d::OpenCVCalib3d.
find_path(OpenCVCalib3d_INCLUDE_DIR opencv2/calib3d.hpp PATH_SUFFIXES opencv4)
find_library(OpenCVCalib3d_CALIB3D_LIBRARY opencv_calib3d)
find_library(OpenCVCalib3d_CORE_LIBRARY opencv_core)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCVCalib3d REQUIRED_VARS OpenCVCalib3d_INCLUDE_DIR
                                  OpenCVCalib3d_CALIB3D_LIBRARY OpenCVCalib3d_CORE_LIBRARY)
if(OpenCVCalib3d_FOUND AND NOT TARGET OpenCVCalib3d::OpenCVCalib3d)
  add_library(OpenCVCalib3d::OpenCVCalib3d INTERFACE IMPORTED)
  target_include_directories(OpenCVCalib3d::OpenCVCalib3d SYSTEM INTERFACE ${OpenCVCalib3d_INCLUDE_DIR})
  target_link_libraries(OpenCVCalib3d::OpenCVCalib3d INTERFACE ${OpenCVCalib3d_CALIB3D_LIBRARY}
                        ${OpenCVCalib3d_CORE_LIBRARY})
endif()
