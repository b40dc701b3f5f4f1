// CGAL Mesh_3 tetrahedralisation of labelled bodies — the project's only Mesh_3 translation
// unit (it is the slowest file of the build to compile).
//
// Domain: CGAL::Labeled_mesh_domain_3 over the body's labelling function (0 outside), wrapped
// in Mesh_domain_with_polyline_features_3 so that sharp rims can be protected as 1D features.
// Optimisers run after refinement in CGAL's own order (ODT, Lloyd, perturb, exude), without
// time limits so that a given seed always gives the same mesh.
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/common/constants.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_domain_with_polyline_features_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/make_mesh_3.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iomanip>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace spinesim::mesh {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Domain_base = CGAL::Labeled_mesh_domain_3<K>;
using Domain = CGAL::Mesh_domain_with_polyline_features_3<Domain_base>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;
namespace params = CGAL::parameters;

Eigen::Vector3d to_eigen(const Tr::Vertex_handle& v) {
  const auto& p = v->point().point();
  return {p.x(), p.y(), p.z()};
}

// Copies the cells of the complex into a TetMesh and labels the boundary nodes.
TetMesh to_tet_mesh(const C3t3& c3t3, const LabeledBody& body) {
  std::unordered_map<Tr::Vertex_handle, int> index;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 4>> tets;
  std::vector<int> regions;
  auto vertex_index = [&](const Tr::Vertex_handle& v) {
    auto [it, inserted] = index.emplace(v, int(points.size()));
    if (inserted) points.push_back(to_eigen(v));
    return it->second;
  };
  // Boundary facets: (vertex indices, label); a facet is on the boundary when the cell across
  // it is not in the complex.
  std::vector<std::pair<std::array<int, 3>, Surface>> boundary;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    std::array<int, 4> t;
    for (int i = 0; i < 4; ++i) t[std::size_t(i)] = vertex_index(c->vertex(i));
    const Eigen::Vector3d a = points[t[0]], b = points[t[1]], cc = points[t[2]], d = points[t[3]];
    if ((b - a).dot((cc - a).cross(d - a)) < 0) std::swap(t[1], t[2]);
    tets.push_back(t);
    regions.push_back(int(c3t3.subdomain_index(c)));
    for (int i = 0; i < 4; ++i) {
      if (c3t3.is_in_complex(c->neighbor(i))) continue;
      std::array<int, 3> f;
      for (int k = 0; k < 3; ++k) f[std::size_t(k)] = vertex_index(c->vertex((i + 1 + k) % 4));
      const Eigen::Vector3d p0 = points[f[0]], p1 = points[f[1]], p2 = points[f[2]];
      const Eigen::Vector3d opposite = to_eigen(c->vertex(i));
      const Eigen::Vector3d centroid = (p0 + p1 + p2) / 3.0;
      Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
      if (n.dot(centroid - opposite) < 0) n = -n;
      n.normalize();
      const Surface s =
          body.classify_facet ? body.classify_facet(centroid, n) : Surface::outer_wall;
      boundary.push_back({f, s});
    }
  }
  if (tets.empty())
    throw std::runtime_error("CGAL Mesh_3 produced no tetrahedra for " + body.name +
                             " (is the labelling function positive inside the bounding sphere?)");

  TetMesh m;
  m.V.resize(Eigen::Index(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) m.V.row(Eigen::Index(i)) = points[i].transpose();
  m.T.resize(Eigen::Index(tets.size()), 4);
  m.region.resize(Eigen::Index(tets.size()));
  for (std::size_t t = 0; t < tets.size(); ++t) {
    for (int k = 0; k < 4; ++k) m.T(Eigen::Index(t), k) = tets[t][std::size_t(k)];
    m.region(Eigen::Index(t)) = regions[t];
  }
  // Node labels by priority: superior endplate > inferior endplate > wall > interior, so that
  // rim nodes carry the endplate label (docs/units-and-frame.md).
  auto priority = [](int s) {
    switch (Surface(s)) {
      case Surface::superior_endplate:
        return 3;
      case Surface::inferior_endplate:
        return 2;
      case Surface::outer_wall:
        return 1;
      default:
        return 0;
    }
  };
  m.surface = Eigen::VectorXi::Zero(m.V.rows());
  for (const auto& [f, s] : boundary)
    for (int v : f)
      if (priority(int(s)) > priority(m.surface(v))) m.surface(v) = int(s);
  m.source = body.name;
  return m;
}

}  // namespace

double expected_elements(double volume_mm3, double bounding_radius_mm, const MeshOptions& opt) {
  const double r = opt.cell_size_mm, R = bounding_radius_mm;
  const double facet = opt.facet_size_mm > 0 ? opt.facet_size_mm : r;
  const double e = std::min(facet, std::sqrt(8.0 * R * opt.facet_distance_mm));
  const double area = 6.0 * std::pow(volume_mm3, 2.0 / 3.0);  // a cube's: a disc has a bit more
  return 6.0 * volume_mm3 / (r * r * r) + area / (0.43 * e * e);
}

TetMesh mesh_labeled_body(const LabeledBody& body, const MeshOptions& opt) {
  if (!body.label) throw std::invalid_argument("mesh_labeled_body: no labelling function");
  if (!(body.bounding_radius_mm > 0))
    throw std::invalid_argument("mesh_labeled_body: bounding radius must be > 0 mm");
  if (!(opt.cell_size_mm > 0) || !(opt.facet_distance_mm > 0) || !(opt.facet_angle_deg > 0) ||
      opt.facet_angle_deg > 30 || !(opt.radius_edge_ratio >= 2.0))
    throw std::invalid_argument(
        "mesh options: need cell size > 0, facet distance > 0, facet angle in (0, 30] deg and "
        "radius-edge ratio >= 2 (CGAL's termination bounds)");

  // Size before work: CGAL would allocate until the machine runs out (cm read as m, 1e-6 mm).
  const double volume = body.exact_volume_mm3 > 0
                            ? body.exact_volume_mm3
                            : 4.0 / 3.0 * kPi * std::pow(body.bounding_radius_mm, 3);
  const double expected = expected_elements(volume, body.bounding_radius_mm, opt);
  if (!(expected <= opt.max_elements)) {
    std::ostringstream os;
    os << "meshing " << body.name << " would make about " << std::setprecision(2) << expected
       << " elements (volume " << std::setprecision(3) << volume << " mm^3, cell size "
       << opt.cell_size_mm << " mm, facet distance " << opt.facet_distance_mm
       << " mm), more than the limit of " << opt.max_elements
       << ": coarser options, a surface in the right units, or a higher --max-elements";
    throw std::invalid_argument(os.str());
  }

  // CGAL looks for the surface with random rays from the centre and never gives up; make sure
  // there is a body to find (probe a 24^3 lattice of the bounding cube).
  bool found = false;
  for (int i = 0; i < 24 && !found; ++i)
    for (int j = 0; j < 24 && !found; ++j)
      for (int k = 0; k < 24 && !found; ++k) {
        const Eigen::Vector3d q =
            body.center_mm +
            body.bounding_radius_mm * (Eigen::Vector3d(i, j, k) / 11.5 - Eigen::Vector3d::Ones());
        found = body.label(q) > 0;
      }
  if (!found)
    throw std::runtime_error(
        "CGAL Mesh_3 cannot mesh " + body.name +
        ": the labelling function is 0 everywhere in its bounding sphere (no tetrahedra)");

  CGAL::Random rng(opt.seed);
  CGAL::get_default_random() = CGAL::Random(opt.seed);  // the perturber draws from it

  auto label = [&body](const Point& p) { return body.label(Eigen::Vector3d(p.x(), p.y(), p.z())); };
  const Eigen::Vector3d& c = body.center_mm;
  const double r = body.bounding_radius_mm;
  const K::Sphere_3 bounding(Point(c.x(), c.y(), c.z()), r * r);
  // Surface points are located by bisection to 1e-6 of the bounding box size.
  Domain domain(std::function<int(const Point&)>(label), bounding, K::FT(1e-6),
                std::function<bool(int)>(CGAL::Null_subdomain_index()), &rng);

  std::vector<std::vector<Point>> polylines;
  for (const auto& line : body.features) {
    if (line.size() < 2) continue;
    std::vector<Point> pl;
    pl.reserve(line.size());
    for (const auto& q : line) pl.emplace_back(q.x(), q.y(), q.z());
    polylines.push_back(std::move(pl));
  }
  if (!polylines.empty()) domain.add_features(polylines.begin(), polylines.end());

  const double facet_size = opt.facet_size_mm > 0 ? opt.facet_size_mm : opt.cell_size_mm;
  const double edge_size = opt.edge_size_mm > 0 ? opt.edge_size_mm : opt.cell_size_mm;
  const Criteria criteria(
      params::edge_size = edge_size, params::facet_angle = opt.facet_angle_deg,
      params::facet_size = facet_size, params::facet_distance = opt.facet_distance_mm,
      params::cell_radius_edge_ratio = opt.radius_edge_ratio, params::cell_size = opt.cell_size_mm);

  C3t3 c3t3 = polylines.empty()
                  ? CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_features(),
                                            params::no_perturb(), params::no_exude())
                  : CGAL::make_mesh_3<C3t3>(domain, criteria, params::features(domain),
                                            params::no_perturb(), params::no_exude());
  if (opt.odt) CGAL::odt_optimize_mesh_3(c3t3, domain, params::max_iteration_number = 20);
  if (opt.lloyd) CGAL::lloyd_optimize_mesh_3(c3t3, domain, params::max_iteration_number = 20);
  if (opt.perturb) CGAL::perturb_mesh_3(c3t3, domain, params::sliver_bound = 12.0);
  if (opt.exude) CGAL::exude_mesh_3(c3t3, params::sliver_bound = 12.0);
  return to_tet_mesh(c3t3, body);
}

TetMesh mesh_parametric_disc(const DiscDimensions& dims, const MeshOptions& opt,
                             const DiscFrame& placement) {
  const auto disc = std::make_shared<const ParametricDisc>(dims);
  LabeledBody body;
  body.label = [disc](const Eigen::Vector3d& p) { return disc->label(p); };
  body.classify_facet = [disc](const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
    return disc->classify_facet(c, n);
  };
  const double half_w = 0.5 * std::max(dims.lower_width_mm, dims.upper_width_mm);
  const double depth = std::max(dims.lower_depth_mm, dims.upper_depth_mm);
  body.bounding_radius_mm =
      1.1 * std::sqrt(half_w * half_w + depth * depth + 0.25 * dims.height_mm * dims.height_mm);
  body.exact_volume_mm3 = disc->volume_mm3();
  // Feature geometry is sampled much finer than the mesh; protection balls follow edge_size.
  const double cell = opt.cell_size_mm > 0 ? opt.cell_size_mm : 1.0;
  body.features = disc->feature_polylines(std::min(0.2, 0.1 * cell));
  body.name = "parametric disc " + dims.level;

  TetMesh m = mesh_labeled_body(body, opt);
  // Placement: x' = origin + axes x (a rigid motion keeps the orientation of every tet).
  m.V = (m.V * placement.axes.transpose()).rowwise() + placement.origin_mm.transpose();
  if (placement.axes.determinant() < 0) m.T.col(1).swap(m.T.col(2));  // mirrored frame
  m.frame = placement;
  return m;
}

}  // namespace spinesim::mesh
