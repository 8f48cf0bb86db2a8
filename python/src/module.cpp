// The `clothcd._clothcd` extension: the C++ library's detector, kernels, cones, mesh files and
// simulator on NumPy arrays. The package's __init__.py re-exports it; _clothcd.pyi types it.
#include <fmt/format.h>

#include <stdexcept>

#include "bindings.hpp"
#include "clothcd/core/error.hpp"

namespace clothcd::python {

Workers::Workers(int threads) : threads_(threads) {
  if (threads < 0)
    throw std::invalid_argument(fmt::format("threads must be >= 0, got {}", threads));
  if (threads > 0) arena_ = std::make_unique<tbb::task_arena>(threads);
}

}  // namespace clothcd::python

PYBIND11_MODULE(_clothcd, m) {
  namespace py = pybind11;
  m.doc() = "Collision detection for thin deformable objects (cloth): NumPy bindings";
  m.attr("__version__") = CLOTHCD_VERSION;
  // The library's bad-input error keeps its message and is a ValueError to Python.
  py::register_exception<clothcd::InputError>(m, "InputError", PyExc_ValueError);
  clothcd::python::bind_mesh(m);
  clothcd::python::bind_detect(m);
  clothcd::python::bind_ccd(m);
  clothcd::python::bind_cone(m);
  clothcd::python::bind_sim(m);
  clothcd::python::bind_view(m);
}
