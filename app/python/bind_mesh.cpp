// spinesim.Mesh, spinesim.read_mesh, spinesim.mesh_disc, spinesim.import_artisynth.
#include "bindings.hpp"
#include "flag_values.hpp"

#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/studies/data.hpp"
#include "spinesim/studies/mesh_disc.hpp"
#include "spinesim/studies/peer_disc.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <array>
#include <optional>

namespace spinesim::python {
namespace {

mesh::TetMesh mesh_disc(const std::string& level, const std::string& inferior,
                        const std::string& superior, double surface_mm_per_unit,
                        const std::string& up, bool structured,
                        const std::array<int, 3>& sectors_rings_layers, double cell_size_mm,
                        std::uint32_t seed, const std::string& out, py::dict* info) {
  studies::MeshDiscRequest rq;
  rq.level = level;
  rq.inferior = inferior;
  rq.superior = superior;
  rq.surface_mm_per_unit = surface_mm_per_unit;
  rq.up = cli::up_axis(up);
  rq.structured = structured;
  rq.structured_options.sectors = sectors_rings_layers[0];
  rq.structured_options.rings = sectors_rings_layers[1];
  rq.structured_options.layers = sectors_rings_layers[2];
  rq.cgal.cell_size_mm = cell_size_mm;
  rq.cgal.seed = seed;
  rq.out = out;
  studies::MeshDiscResult r;
  {
    py::gil_scoped_release release;
    r = studies::run_mesh_disc(rq, data_folder());
  }
  *info = to_python(studies::mesh_disc_json(r));
  return std::move(r.mesh);
}

/// A writable NumPy view of a mesh array (it lives as long as the mesh).
template <class M>
py::cpp_function view(M mesh::TetMesh::*member) {
  return py::cpp_function([member](mesh::TetMesh& t) -> M& { return t.*member; },
                          py::return_value_policy::reference_internal);
}

/// Replaces a mesh array (any array NumPy can convert to its shape and type).
template <class M>
py::cpp_function assign(M mesh::TetMesh::*member) {
  return py::cpp_function([member](mesh::TetMesh& t, const M& value) { t.*member = value; });
}

/// A family of the mesh's fibre paths as a NumPy copy, or None without paths.
py::object fibre_path(const mesh::TetMesh& t, int family) {
  if (t.fibre_paths.empty()) return py::none();
  return py::cast(Eigen::MatrixX3d(family == 0 ? t.fibre_paths.direction_1
                                               : t.fibre_paths.direction_2));
}

/// Sets a family of fibre paths (None clears both); validate() checks the pair.
void set_fibre_path(mesh::TetMesh& t, int family, const py::object& d) {
  if (d.is_none()) {
    t.fibre_paths = {};
    return;
  }
  (family == 0 ? t.fibre_paths.direction_1 : t.fibre_paths.direction_2) =
      d.cast<Eigen::MatrixX3d>();
}

/// spinesim.Mesh: the mesh's arrays as NumPy, its frame, fibre paths, checks and writing.
void bind_mesh_class(py::module_& m) {
  py::class_<mesh::TetMesh>(m, "Mesh", py::dynamic_attr(), R"(A tetrahedral disc mesh (mm).

nodes    (N, 3) float64 positions, mm; frame x lateral (the body's right is -x), y superior,
         z anterior
tets     (M, 4) int32 node indices, positively oriented
region   (M,) int32: 1 annulus, 2 nucleus
surface  (N,) int32: 0 interior, 1 inferior endplate (fixed), 2 superior endplate (the plate),
         3 outer wall
The arrays are views of the mesh: writing into them changes it.
fibre_path_direction_1/2  (M, 3) float64 or None: fibre directions the mesh brings (a peer's
         fibres), followed by fibre materials; copies, set them whole.)")
      .def(py::init<>())
      .def_property("nodes", view(&mesh::TetMesh::V), assign(&mesh::TetMesh::V))
      .def_property("tets", view(&mesh::TetMesh::T), assign(&mesh::TetMesh::T))
      .def_property("region", view(&mesh::TetMesh::region), assign(&mesh::TetMesh::region))
      .def_property("surface", view(&mesh::TetMesh::surface), assign(&mesh::TetMesh::surface))
      .def_readwrite("source", &mesh::TetMesh::source)
      .def_property(
          "frame_origin", [](const mesh::TetMesh& t) { return t.frame.origin_mm; },
          [](mesh::TetMesh& t, const Eigen::Vector3d& o) { t.frame.origin_mm = o; },
          "The disc frame's origin (mid-disc centre), mm")
      .def_property(
          "frame_axes", [](const mesh::TetMesh& t) { return t.frame.axes; },
          [](mesh::TetMesh& t, const Eigen::Matrix3d& a) { t.frame.axes = a; },
          "The disc frame's axes as columns (lateral, axial, anterior), in the global frame")
      .def_property(
          "fibre_path_direction_1",
          [](const mesh::TetMesh& t) -> py::object { return fibre_path(t, 0); },
          [](mesh::TetMesh& t, const py::object& d) { set_fibre_path(t, 0, d); },
          "(M, 3) fibre directions the mesh brings, family 1 (a peer's fibres), or None; a fibre "
          "material follows them instead of the annulus geometry")
      .def_property(
          "fibre_path_direction_2",
          [](const mesh::TetMesh& t) -> py::object { return fibre_path(t, 1); },
          [](mesh::TetMesh& t, const py::object& d) { set_fibre_path(t, 1, d); },
          "(M, 3) fibre directions the mesh brings, family 2, or None")
      .def_property_readonly("num_nodes", &mesh::TetMesh::num_vertices)
      .def_property_readonly("num_tets", &mesh::TetMesh::num_tets)
      .def_property_readonly("volume_mm3", [](const mesh::TetMesh& t) { return mesh::mesh_volume(t); })
      .def("validate", [](const mesh::TetMesh& t) { mesh::validate(t); },
           "Raises ValueError (one line) for an unusable mesh")
      .def(
          "write",
          [](const mesh::TetMesh& t, const std::string& path) {
            mesh::validate(t);
            mesh::write_vtu(path, t);
          },
          py::arg("path"), "Writes the mesh as a VTU file (with the provenance of the script)")
      .def("__repr__", [](const mesh::TetMesh& t) {
        return "<spinesim.Mesh " + std::to_string(t.num_vertices()) + " nodes, " +
               std::to_string(t.num_tets()) + " tets" +
               (t.source.empty() ? std::string() : ", " + t.source) + ">";
      });
}

}  // namespace

void bind_mesh(py::module_& m) {
  bind_mesh_class(m);

  m.def(
      "read_mesh", [](const std::string& path) { return mesh::read_tet_mesh(path); },
      py::arg("path"), "Reads a disc mesh: VTU (.vtu), legacy VTK (.vtk) or Medit (.mesh)");

  m.def(
      "mesh_disc",
      [](const std::string& level, const std::string& inferior, const std::string& superior,
         double surface_mm_per_unit, const std::string& up, bool structured, int sectors,
         int rings, int layers, double cell_size_mm, std::uint32_t seed, const std::string& out) {
        py::dict info;
        mesh::TetMesh t =
            mesh_disc(level, inferior, superior, surface_mm_per_unit, up, structured,
                      {sectors, rings, layers}, cell_size_mm, seed, out, &info);
        py::object o = py::cast(std::move(t));
        o.attr("info") = info;
        return o;
      },
      py::kw_only(), py::arg("level") = "", py::arg("inferior") = "", py::arg("superior") = "",
      py::arg("surface_mm_per_unit") = 1.0, py::arg("up") = "y", py::arg("structured") = false,
      py::arg("sectors") = mesh::StructuredDiscOptions().sectors,
      py::arg("rings") = mesh::StructuredDiscOptions().rings,
      py::arg("layers") = mesh::StructuredDiscOptions().layers,
      py::arg("cell_size_mm") = mesh::MeshOptions().cell_size_mm, py::arg("seed") = 0u,
      py::arg("out") = "");

  m.def(
      "import_artisynth",
      [](const std::string& folder, const std::string& level, const std::string& out,
         bool fibre_paths) {
        studies::PeerDiscRequest rq{folder, level, out, fibre_paths};
        studies::PeerDiscResult r;
        {
          py::gil_scoped_release release;
          r = studies::import_peer_disc(rq, data_folder());
        }
        const py::object info = to_python(studies::peer_disc_json(r, rq));
        py::object o = py::cast(std::move(r.mesh));
        o.attr("info") = info;
        return o;
      },
      py::arg("folder"), py::arg("level"), py::arg("out") = "", py::kw_only(),
      py::arg("fibre_paths") = true,
      "A peer model's disc: the ArtiSynth lumbosacral spine's hexahedral disc of `level` (L1-L2 … "
      "L5-S1) from its fe-discs `folder`, split into tets, labelled, in mm and our frame; "
      "`info` has its quality and its fibres beside ours. With `fibre_paths` the peer's fibres "
      "are the mesh's fibre_path_direction_1/2, which a fibre material follows. Writes `out` "
      "(VTU) when given.");
}

}  // namespace spinesim::python
