// imscal.InputError: the library's InputError as a Python exception (a ValueError) that keeps
// the file, line and field apart, as the command line prints them.
#include <exception>

#include "core/input_error.hpp"
#include "python/bindings.hpp"

namespace imscal::python {

void bind_input_error(py::module_& m) {
  // Lives as long as the interpreter (pybind11's pattern for exception types).
  static py::exception<InputError> type(m, "InputError", PyExc_ValueError);
  type.doc() =
      "Input imscal cannot use. Attributes: file, line (1-based; 0: the whole file), field "
      "(column or key; may be empty), problem; str() is the command line's message.";
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const InputError& e) {
      py::object instance = py::handle(type.ptr())(e.what());  // the class called, not raised
      instance.attr("file") = e.file();
      instance.attr("line") = e.line();
      instance.attr("field") = e.field();
      instance.attr("problem") = e.problem();
      PyErr_SetObject(type.ptr(), instance.ptr());
    }
  });
}

}  // namespace imscal::python
