// `import imscal`: the toolkit's readers and numerics on numpy arrays (README, "Python").
#include "python/bindings.hpp"

#include "core/version.hpp"

PYBIND11_MODULE(imscal, m) {
  m.doc() =
      "imscal: dynamic calibration of industrial robots with an inertial measurement system. "
      "Input the library cannot use raises imscal.InputError (file, line, field).";
  m.attr("__version__") = imscal::kVersion;
  imscal::python::bind_input_error(m);
  imscal::python::bind_ims(m);
  imscal::python::bind_calib(m);
  imscal::python::bind_eval(m);
  imscal::python::bind_ident(m);
}
