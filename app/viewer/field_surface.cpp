#include "field_surface.hpp"

#include "spinesim/mesh/tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::viewer {

DiscField disc_field(const std::string& name) {
  for (int i = 0; i < 3; ++i)
    if (name == kDiscFieldNames[i]) return DiscField(i);
  throw std::invalid_argument("--field " + name +
                              ": give displacement, spring_strain or volume_change");
}

FieldSurface::FieldSurface(const Eigen::MatrixXi& T) { F_ = mesh::boundary_faces(T, &owner_); }

Eigen::VectorXd FieldSurface::from_points(const Eigen::VectorXd& p) const {
  Eigen::VectorXd out(F_.rows());
  for (Eigen::Index f = 0; f < F_.rows(); ++f)
    out(f) = (p(F_(f, 0)) + p(F_(f, 1)) + p(F_(f, 2))) / 3;
  return out;
}

Eigen::VectorXd FieldSurface::from_cells(const Eigen::VectorXd& c) const {
  Eigen::VectorXd out(F_.rows());
  for (Eigen::Index f = 0; f < F_.rows(); ++f) out(f) = c(owner_(f));
  return out;
}

void FieldSurface::point_range(const Eigen::VectorXd& p, double floor, double& lo,
                               double& hi) const {
  Eigen::VectorXd corners(F_.size());
  for (Eigen::Index f = 0; f < F_.rows(); ++f)
    for (int k = 0; k < 3; ++k) corners(3 * f + k) = p(F_(f, k));
  range(corners, floor, lo, hi);
}

void FieldSurface::range(const Eigen::VectorXd& v, double floor, double& lo, double& hi) {
  // Non-finite values mean "no data" (a fibre field's nucleus): they are drawn grey and take no
  // part in the range.
  double a = 0, b = 0;
  bool any = false;
  for (double x : v)
    if (std::isfinite(x)) {
      a = any ? std::min(a, x) : x;
      b = any ? std::max(b, x) : x;
      any = true;
    }
  if (a < 0) {
    hi = std::max({std::abs(a), std::abs(b), floor});
    lo = -hi;
  } else {
    lo = 0;
    hi = std::max(b, floor);
  }
}

void FieldSurface::fill(Body& body, const Eigen::MatrixX3d& V, const Eigen::VectorXd& values,
                        double lo, double hi) const {
  body.V = V;
  body.F = F_;
  body.face_colors.resize(F_.rows(), 3);
  for (Eigen::Index f = 0; f < F_.rows(); ++f)
    body.face_colors.row(f) = colormap(values(f), lo, hi).transpose();
  ++body.revision;
}

}  // namespace spinesim::viewer
