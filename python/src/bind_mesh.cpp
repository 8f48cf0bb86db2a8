// Mesh files (OBJ, PLY) and the edge numbering of a mesh.
#include <fmt/format.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>

#include "arrays.hpp"
#include "bindings.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd::python {

void bind_mesh(py::module_& m) {
  m.def(
      "read_mesh",
      [](const std::filesystem::path& path) {
        TriangleMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = read_mesh(path);
        }
        return py::make_tuple(vertices_array(std::move(mesh.vertices)),
                              faces_array(std::move(mesh.faces)));
      },
      py::arg("path"),
      R"(Reads a triangle mesh from an OBJ or PLY file (chosen by the extension).

Returns (V, F): V float64 of shape (n, 3), F int32 of shape (m, 3) (0-based; OBJ polygons are
fan-triangulated). Raises ValueError naming the file and line (or element) on malformed input.)");

  m.def(
      "write_mesh",
      [](const std::filesystem::path& path, const ArrayLike& V, const ArrayLike& F) {
        TriangleMesh mesh;
        const Positions v = positions(V, "V");
        if (v.cols() != 3) {
          fail(fmt::format("V: expected a float array of shape (n, 3), got {} columns", v.cols()));
        }
        mesh.vertices.resize(static_cast<std::size_t>(v.rows()));
        for (Eigen::Index i = 0; i < v.rows(); ++i)
          mesh.vertices[i] = v.row(i).transpose();
        mesh.faces = faces(F, "F");
        py::gil_scoped_release release;
        // Checked first so that bad input leaves no file behind.
        validate_mesh(mesh, path.string());
        write_mesh(path, mesh);
      },
      py::arg("path"), py::arg("V"), py::arg("F"),
      R"(Writes a triangle mesh as OBJ (shortest round-trip decimals) or binary PLY (float64),
chosen by the extension; both read back bit-identical. The file is replaced atomically. Raises
ValueError for non-finite coordinates, face ids out of range or a face repeating a vertex.)");

  m.def(
      "mesh_edges",
      [](const ArrayLike& F, std::optional<int> num_vertices) {
        std::vector<Face> f = faces(F, "F");
        int n = 0;
        for (const Face& t : f)
          n = std::max({n, t[0] + 1, t[1] + 1, t[2] + 1});
        const Topology topo(std::move(f), num_vertices.value_or(n));
        return edges_array(topo.edges());
      },
      py::arg("F"), py::arg("num_vertices") = py::none(),
      R"(The unique undirected edges of a mesh, (e, 2) int32 with the smaller vertex id first,
sorted by (larger id, smaller id): the edge ids the detectors report.)");
}

}  // namespace clothcd::python
