// Runs the `manisoft` module's Python half (manisoft_vec.py: the spaces Box, Dict, Text, Sequence,
// the environments' action_space / observation_space, make_vec_env) in the module's namespace when
// the module loads. The build compiles the file in as text (examples/CMakeLists.txt).
#include <pybind11/eval.h>
#include <pybind11/pybind11.h>

namespace py = pybind11;

namespace manisoft_py {

void add_python_side(py::module_& m) {
  static const char* const source =
#include "manisoft_vec_py.inc"
      ;
  py::exec(source, m.attr("__dict__"));
}

}  // namespace manisoft_py
