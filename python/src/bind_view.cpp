// The viewer page, as `clothcd view` writes it: a simulation folder or a detection step.
#include <fmt/format.h>
#include <pybind11/stl/filesystem.h>

#include <optional>

#include "bindings.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/view/page.hpp"

namespace clothcd::python {

namespace py = pybind11;
using Path = std::optional<std::filesystem::path>;

void bind_view(py::module_& m) {
  m.def(
      "view",
      [](const Path& dir, const std::filesystem::path& out, const Path& t0, const Path& t1,
         const Path& json, int first, std::optional<int> last, int step, double contact_distance,
         bool no_body, bool no_contact) {
        const bool step_mode = t0 || t1 || json;
        if (step_mode == dir.has_value()) {
          throw InputError(
              "view: give either a simulation folder (view(dir, out=...)) or a detection step "
              "(view(t0=..., t1=..., json=..., out=...))");
        }
        if (step_mode && !(t0 && t1 && json))
          throw InputError("view: a detection step needs t0, t1 and json");
        if (first < 0 || step < 1 || contact_distance < 0) {
          throw InputError(fmt::format(
              "view: first must be >= 0, step >= 1 and contact_distance >= 0 (got {}, {}, {})",
              first, step, contact_distance));
        }
        view::PageSummary s;
        {
          py::gil_scoped_release release;
          if (step_mode) {
            s = view::write_detection_page(*t0, *t1, *json, out);
          } else {
            view::SequenceOptions opt;
            opt.first = first;
            opt.last = last.value_or(-1);
            opt.step = step;
            opt.body = !no_body;
            opt.contact = !no_contact;
            opt.contact_distance = contact_distance;
            s = view::write_sequence_page(*dir, out, opt);
          }
        }
        py::dict d;
        d["bytes"] = s.bytes;
        d["data_bytes"] = s.data_bytes;
        d["packed_bytes"] = s.packed_bytes;
        d["frames"] = s.frames;
        d["hits"] = s.hits;
        d["body"] = s.body;
        d["strain"] = s.strain;
        d["contact"] = s.contact;
        d["notes"] = s.notes;
        return d;
      },
      py::arg("dir") = py::none(), py::kw_only(), py::arg("out"), py::arg("t0") = py::none(),
      py::arg("t1") = py::none(), py::arg("json") = py::none(), py::arg("first") = 0,
      py::arg("last") = py::none(), py::arg("step") = 1, py::arg("contact_distance") = 0.0,
      py::arg("no_body") = false, py::arg("no_contact") = false,
      R"(Writes one self-contained HTML page (opens offline in a browser), as `clothcd view` does,
with the same arguments: view(dir, out=...) for the output folder of `clothcd simulate` (the
cloth and the body frame by frame, colour by strain or contact; first, last, step choose the
frames), or view(t0=..., t1=..., json=..., out=...) for a `clothcd detect --json` result and its
two frames (the hits highlighted and listed). Returns what the page holds: its size in bytes
(bytes; data_bytes and packed_bytes: the geometry before and after compression), frames, hits,
whether it has the body, strain and contact colouring, and notes on what it leaves out. Bad input
raises InputError (nothing is written); an unwritable `out` raises RuntimeError.)");
}

}  // namespace clothcd::python
