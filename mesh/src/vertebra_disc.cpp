// Disc between two user-supplied vertebrae; the construction is described in vertebra_disc.hpp.
// CGAL AABB trees answer the ray queries; the meshing itself goes through mesh_labeled_body.
#include "spinesim/mesh/vertebra_disc.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace spinesim::mesh {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using TriangleIt = std::vector<K::Triangle_3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriangleIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

void check_surface(const TriSurface& s, const char* which) {
  if (s.V.rows() == 0 || s.F.rows() == 0)
    throw std::invalid_argument(std::string(which) + " vertebra surface is empty (no triangles)");
  if (!s.V.allFinite())
    throw std::invalid_argument(std::string(which) +
                                " vertebra surface has non-finite coordinates");
  if (s.F.minCoeff() < 0 || s.F.maxCoeff() >= s.V.rows())
    throw std::invalid_argument(std::string(which) +
                                " vertebra surface has a vertex index out of range");
}

// One surface in the local frame with an AABB tree for ray shooting.
struct RayTarget {
  std::vector<K::Triangle_3> tris;
  std::vector<double> abs_cos;  // |normal . y| per triangle
  double y_min = 1e300, y_max = -1e300;
  Tree tree;

  RayTarget(const TriSurface& s, const Eigen::Vector3d& origin, const Eigen::Matrix3d& axes) {
    const Eigen::MatrixX3d L = (s.V.rowwise() - origin.transpose()) * axes;  // local coords
    for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
      const Eigen::Vector3d a = L.row(s.F(f, 0)), b = L.row(s.F(f, 1)), c = L.row(s.F(f, 2));
      const Eigen::Vector3d n = (b - a).cross(c - a);
      if (!(n.norm() > 1e-14)) continue;  // degenerate triangle
      tris.emplace_back(K::Point_3(a.x(), a.y(), a.z()), K::Point_3(b.x(), b.y(), b.z()),
                        K::Point_3(c.x(), c.y(), c.z()));
      abs_cos.push_back(std::abs(n.normalized().y()));
      y_min = std::min({y_min, a.y(), b.y(), c.y()});
      y_max = std::max({y_max, a.y(), b.y(), c.y()});
    }
    tree.insert(tris.begin(), tris.end());
    tree.build();
  }

  // First hit of the vertical ray from (u, y0, v) in direction dir_y = ±1: (height, |cos|).
  std::pair<double, double> first_hit(double u, double v, double y0, double dir_y) const {
    const K::Ray_3 ray(K::Point_3(u, y0, v), K::Vector_3(0, dir_y, 0));
    const auto hit = tree.first_intersection(ray);
    if (!hit) return {kNaN, 0.0};
    const std::size_t id = std::size_t(hit->second - tris.begin());
    double y = kNaN;
    if (const K::Point_3* p = boost::get<K::Point_3>(&hit->first))
      y = p->y();
    else if (const K::Segment_3* sg = boost::get<K::Segment_3>(&hit->first))
      y = dir_y < 0 ? std::max(sg->source().y(), sg->target().y())
                    : std::min(sg->source().y(), sg->target().y());
    return {y, abs_cos[id]};
  }
};

// Star-shaped closed curve about c0, radius tabulated at n equally spaced angles.
struct PolarOutline {
  Eigen::Vector2d c0 = Eigen::Vector2d::Zero();
  std::vector<double> R;

  double angle_step() const { return 2 * kPi / double(R.size()); }
  double radius(double phi) const {
    double t = phi / angle_step();
    t -= std::floor(t / double(R.size())) * double(R.size());
    const std::size_t i = std::size_t(t) % R.size();
    const double w = t - std::floor(t);
    return (1 - w) * R[i] + w * R[(i + 1) % R.size()];
  }
  Eigen::Vector2d point(double phi) const {
    return c0 + radius(phi) * Eigen::Vector2d(std::cos(phi), std::sin(phi));
  }
  bool contains(const Eigen::Vector2d& q) const {
    const Eigen::Vector2d d = q - c0;
    const double rho = d.norm();
    return rho == 0.0 || rho <= radius(std::atan2(d.y(), d.x()));
  }
  double radial_distance(const Eigen::Vector2d& q) const {
    const Eigen::Vector2d d = q - c0;
    return std::abs(d.norm() - radius(std::atan2(d.y(), d.x())));
  }
  double area() const {  // polar integral 1/2 ∫ R^2 dφ
    double a = 0;
    for (double r : R) a += 0.5 * r * r;
    return a * angle_step();
  }
  Eigen::Vector2d centroid() const {  // 1/3 ∫ R^3 (cos, sin) dφ / area
    Eigen::Vector2d m = Eigen::Vector2d::Zero();
    for (std::size_t k = 0; k < R.size(); ++k) {
      const double phi = double(k) * angle_step();
      m += R[k] * R[k] * R[k] / 3.0 * Eigen::Vector2d(std::cos(phi), std::sin(phi));
    }
    return c0 + m * angle_step() / area();
  }
};

// Truncated Fourier series of a periodic sample sequence.
std::vector<double> low_pass(const std::vector<double>& f, int harmonics) {
  const std::size_t n = f.size();
  std::vector<double> out(n, 0.0);
  for (int m = 0; m <= harmonics; ++m) {
    double a = 0, b = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const double t = 2 * kPi * double(m) * double(k) / double(n);
      a += f[k] * std::cos(t);
      b += f[k] * std::sin(t);
    }
    const double scale = (m == 0 ? 1.0 : 2.0) / double(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double t = 2 * kPi * double(m) * double(k) / double(n);
      out[k] += scale * (a * std::cos(t) + b * std::sin(t));
    }
  }
  return out;
}

// The disc body in the local frame (y = axis): footprint outline and endplate height fields.
class DiscBetween {
 public:
  DiscBetween(const TriSurface& inf, const TriSurface& sup, const VertebraDiscOptions& opt);

  int label(const Eigen::Vector3d& p) const {
    const Eigen::Vector2d q(p.x(), p.z());
    if (!outline_.contains(q)) return 0;
    const double lo = height(s_inf_, q), hi = height(s_sup_, q);
    if (!(p.y() >= lo && p.y() <= hi)) return 0;  // also false for NaN
    return outline_.contains(nucleus_center_ + (q - nucleus_center_) / nucleus_scale_)
               ? int(Region::nucleus)
               : int(Region::annulus);
  }

  Surface classify_facet(const Eigen::Vector3d& c, const Eigen::Vector3d& n) const {
    const Eigen::Vector2d q(c.x(), c.z());
    const double lo = height(s_inf_, q), hi = height(s_sup_, q);
    const double d_wall = outline_.radial_distance(q);
    const double d_bot = std::isnan(lo) ? 1e300 : std::abs(c.y() - lo);
    const double d_top = std::isnan(hi) ? 1e300 : std::abs(c.y() - hi);
    if (d_bot <= d_top && d_bot < d_wall && n.y() < -0.3) return Surface::inferior_endplate;
    if (d_top < d_bot && d_top < d_wall && n.y() > 0.3) return Surface::superior_endplate;
    return Surface::outer_wall;
  }

  std::vector<std::vector<Eigen::Vector3d>> feature_polylines(double spacing_mm) const;

  const VertebraDiscInfo& info() const { return info_; }
  Eigen::Vector3d local_center() const { return local_center_; }
  double bounding_radius() const { return bounding_radius_; }
  const Eigen::Vector3d& local_origin() const { return origin_; }
  const Eigen::Matrix3d& axes() const { return axes_; }

 private:
  // The steps of the constructor, in order.
  void set_frame(const TriSurface& inf, const TriSurface& sup);
  std::vector<char> height_fields(const TriSurface& inf, const TriSurface& sup,
                                  const VertebraDiscOptions& opt);
  void fill_holes(const std::vector<char>& facing, const std::vector<char>& mask);
  std::vector<char> facing_region(const std::vector<char>& facing, const VertebraDiscOptions& opt,
                                  Eigen::Vector2d& c0);
  void set_outline(const std::vector<char>& mask, const Eigen::Vector2d& c0,
                   const VertebraDiscOptions& opt);
  void measure();
  // Bilinear interpolation of a grid field; NaN when a corner is missing or q is off the grid.
  double height(const std::vector<double>& f, const Eigen::Vector2d& q) const {
    const double fu = (q.x() - u0_) / step_, fv = (q.y() - v0_) / step_;
    if (!(fu >= 0 && fv >= 0 && fu <= nu_ - 1 && fv <= nv_ - 1)) return kNaN;
    const int i = std::min(int(fu), nu_ - 2), j = std::min(int(fv), nv_ - 2);
    const double a = fu - i, b = fv - j;
    return (1 - a) * (1 - b) * f[idx(i, j)] + a * (1 - b) * f[idx(i + 1, j)] +
           (1 - a) * b * f[idx(i, j + 1)] + a * b * f[idx(i + 1, j + 1)];
  }
  std::size_t idx(int i, int j) const { return std::size_t(j) * std::size_t(nu_) + std::size_t(i); }

  Eigen::Vector3d origin_;  // global position of the local origin
  Eigen::Matrix3d axes_;    // columns: local x, y (disc axis), z in global coordinates
  double u0_ = 0, v0_ = 0, step_ = 0.25;
  int nu_ = 0, nv_ = 0;
  std::vector<double> s_inf_, s_sup_;  // endplate heights per grid node (local y), NaN = none
  PolarOutline outline_;
  Eigen::Vector2d nucleus_center_;
  double nucleus_scale_ = 1;
  Eigen::Vector3d local_center_;
  double bounding_radius_ = 0;
  VertebraDiscInfo info_;
};

DiscBetween::DiscBetween(const TriSurface& inf, const TriSurface& sup,
                         const VertebraDiscOptions& opt) {
  check_surface(inf, "inferior");
  check_surface(sup, "superior");
  if (!(opt.grid_step_mm > 0) || !(opt.max_gap_mm > 0) ||
      !(opt.facing_angle_deg > 0 && opt.facing_angle_deg < 90) ||
      !(opt.nucleus_area_fraction > 0 && opt.nucleus_area_fraction < 1) ||
      opt.outline_harmonics < 1)
    throw std::invalid_argument("vertebra disc options out of range");

  set_frame(inf, sup);
  const std::vector<char> facing = height_fields(inf, sup, opt);
  Eigen::Vector2d c0;
  const std::vector<char> mask = facing_region(facing, opt, c0);
  fill_holes(facing, mask);
  set_outline(mask, c0, opt);
  measure();
}

// 1. Axis and local frame: y from the inferior to the superior centroid, x the global lateral
//    axis made orthogonal to it.
void DiscBetween::set_frame(const TriSurface& inf, const TriSurface& sup) {
  const Eigen::Vector3d c_inf = surface_centroid(inf), c_sup = surface_centroid(sup);
  const Eigen::Vector3d d = c_sup - c_inf;
  if (d.norm() < 1.0)
    throw std::invalid_argument("the vertebrae do not face each other: their centroids coincide (" +
                                fmt(d.norm()) +
                                " mm apart; the same vertebra twice, or the wrong --units?)");
  const Eigen::Vector3d y = d.normalized();
  if (y.y() < std::cos(60.0 * kRadPerDeg))
    throw std::invalid_argument(
        "the vertebrae do not face each other: the superior vertebra is not above the inferior one "
        "(centroid direction " +
        fmt(y.x()) + ", " + fmt(y.y()) + ", " + fmt(y.z()) +
        "; swapped order or wrong --up axis?)");
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - y.x() * y;
  x.normalize();
  axes_.col(0) = x;
  axes_.col(1) = y;
  axes_.col(2) = x.cross(y);
  origin_ = 0.5 * (c_inf + c_sup);
}

// 2. Height fields over the overlap of the two projections; returns the grid nodes where both
//    endplates face each other with a gap in (0, max_gap].
std::vector<char> DiscBetween::height_fields(const TriSurface& inf, const TriSurface& sup,
                                             const VertebraDiscOptions& opt) {
  const RayTarget lower(inf, origin_, axes_), upper(sup, origin_, axes_);
  auto extent = [&](const TriSurface& s, int col, double& lo, double& hi) {
    const Eigen::VectorXd t = (s.V.rowwise() - origin_.transpose()) * axes_.col(col);
    lo = t.minCoeff();
    hi = t.maxCoeff();
  };
  double ul1, uh1, ul2, uh2, vl1, vh1, vl2, vh2;
  extent(inf, 0, ul1, uh1);
  extent(sup, 0, ul2, uh2);
  extent(inf, 2, vl1, vh1);
  extent(sup, 2, vl2, vh2);
  const double ulo = std::max(ul1, ul2), uhi = std::min(uh1, uh2);
  const double vlo = std::max(vl1, vl2), vhi = std::min(vh1, vh2);
  if (!(uhi - ulo > 2 * opt.grid_step_mm && vhi - vlo > 2 * opt.grid_step_mm))
    throw std::invalid_argument(
        "the vertebrae do not face each other: their footprints along the axis do not overlap");
  // A vertebral body is 30-60 mm across: a footprint of metres is a surface in the wrong units,
  // and its height-field grid would not fit in memory.
  if (uhi - ulo > opt.max_footprint_mm || vhi - vlo > opt.max_footprint_mm) {
    std::ostringstream os;
    os << std::setprecision(3) << "the vertebrae face each other over " << (uhi - ulo) << " x "
       << (vhi - vlo) << " mm, more than the " << opt.max_footprint_mm
       << " mm any vertebral body spans: a surface in the wrong units (--units)?";
    throw std::invalid_argument(os.str());
  }
  step_ = opt.grid_step_mm;
  u0_ = ulo;
  v0_ = vlo;
  nu_ = int(std::floor((uhi - ulo) / step_)) + 1;
  nv_ = int(std::floor((vhi - vlo) / step_)) + 1;
  s_inf_.assign(std::size_t(nu_) * std::size_t(nv_), kNaN);
  s_sup_ = s_inf_;
  std::vector<char> facing(s_inf_.size(), 0);
  const double cos_facing = std::cos(opt.facing_angle_deg * kRadPerDeg);
  int both_facing = 0, gap_positive = 0;
  for (int j = 0; j < nv_; ++j)
    for (int i = 0; i < nu_; ++i) {
      const double u = u0_ + i * step_, v = v0_ + j * step_;
      const auto [lo, cos_lo] = lower.first_hit(u, v, lower.y_max + 1.0, -1.0);
      const auto [hi, cos_hi] = upper.first_hit(u, v, upper.y_min - 1.0, +1.0);
      s_inf_[idx(i, j)] = lo;
      s_sup_[idx(i, j)] = hi;
      if (std::isnan(lo) || std::isnan(hi) || cos_lo < cos_facing || cos_hi < cos_facing) continue;
      ++both_facing;
      if (hi - lo > 0) ++gap_positive;
      if (hi - lo > 0 && hi - lo <= opt.max_gap_mm) facing[idx(i, j)] = 1;
    }
  if (both_facing == 0)
    throw std::invalid_argument(
        "the vertebrae do not face each other: no upward-facing part of the inferior "
        "surface lies below a downward-facing part of the superior one");
  if (gap_positive == 0)
    throw std::invalid_argument(
        "the vertebrae do not face each other: the endplates overlap (gap <= 0 mm everywhere)");

  return facing;
}

// 3b. Holes in an endplate (a missing triangle of a segmented surface, a defect): inside the
//     footprint, columns where a ray missed the endplate or hit the far side of the vertebra get
//     heights interpolated from their facing neighbours (Laplace fill), so the disc surface and
//     its rims stay on the endplates instead of dipping into the hole (where CGAL's protection of
//     the rims never finished). info().filled_columns says how many.
void DiscBetween::fill_holes(const std::vector<char>& facing, const std::vector<char>& mask) {
  std::vector<std::size_t> holes;
  for (std::size_t k = 0; k < mask.size(); ++k)
    if (mask[k] && !facing[k]) holes.push_back(k);
  info_.filled_columns = long(holes.size());
  info_.filled_area_mm2 = double(holes.size()) * step_ * step_;
  if (holes.empty()) return;
  for (std::vector<double>* field : {&s_inf_, &s_sup_}) {
    std::vector<double>& f = *field;
    std::vector<char> known(f.size(), 0);
    for (std::size_t k = 0; k < f.size(); ++k) known[k] = facing[k] && std::isfinite(f[k]);
    // Start each hole column from the mean of its known neighbours (grown inwards), then relax.
    for (int sweep = 0; sweep < 500; ++sweep) {
      double change = 0;
      bool unset = false;
      for (const std::size_t k : holes) {
        const int i = int(k % std::size_t(nu_)), j = int(k / std::size_t(nu_));
        double sum = 0;
        int n = 0;
        const int nb[4][2] = {{i + 1, j}, {i - 1, j}, {i, j + 1}, {i, j - 1}};
        for (const auto& q : nb) {
          if (q[0] < 0 || q[1] < 0 || q[0] >= nu_ || q[1] >= nv_) continue;
          const std::size_t m = idx(q[0], q[1]);
          if (known[m]) sum += f[m], ++n;
        }
        if (n == 0) {
          unset = unset || !known[k];
          continue;
        }
        const double value = sum / n;
        change = std::max(change, known[k] ? std::abs(value - f[k]) : INFINITY);
        f[k] = value;
        known[k] = 1;
      }
      if (!unset && change < 1e-6) break;
    }
  }
}

// 3. Largest 4-connected facing component, holes filled; c0 its centroid.
std::vector<char> DiscBetween::facing_region(const std::vector<char>& facing,
                                             const VertebraDiscOptions& opt, Eigen::Vector2d& c0) {
  std::vector<int> comp(facing.size(), -1);
  int best = -1;
  std::size_t best_size = 0;
  std::vector<std::pair<int, int>> stack;
  for (int j0 = 0; j0 < nv_; ++j0)
    for (int i0 = 0; i0 < nu_; ++i0) {
      if (!facing[idx(i0, j0)] || comp[idx(i0, j0)] >= 0) continue;
      const int id = int(idx(i0, j0));
      std::size_t size = 0;
      stack.assign(1, {i0, j0});
      comp[idx(i0, j0)] = id;
      while (!stack.empty()) {
        const auto [i, j] = stack.back();
        stack.pop_back();
        ++size;
        const int nb[4][2] = {{i + 1, j}, {i - 1, j}, {i, j + 1}, {i, j - 1}};
        for (const auto& n : nb)
          if (n[0] >= 0 && n[1] >= 0 && n[0] < nu_ && n[1] < nv_ && facing[idx(n[0], n[1])] &&
              comp[idx(n[0], n[1])] < 0) {
            comp[idx(n[0], n[1])] = id;
            stack.push_back({n[0], n[1]});
          }
      }
      if (size > best_size) {
        best_size = size;
        best = id;
      }
    }
  if (best < 0 || double(best_size) * step_ * step_ < 50.0)
    throw std::invalid_argument(
        "the vertebrae do not face each other: no facing endplates with a gap in (0, " +
        fmt(opt.max_gap_mm) + "] mm (gap absurd or no overlap)");
  std::vector<char> mask(facing.size(), 0), outside(facing.size(), 0);
  for (std::size_t k = 0; k < mask.size(); ++k) mask[k] = comp[k] == best;
  stack.clear();  // flood the complement from the grid border; what it misses are holes
  for (int i = 0; i < nu_; ++i)
    for (int j : {0, nv_ - 1}) stack.push_back({i, j});
  for (int j = 0; j < nv_; ++j)
    for (int i : {0, nu_ - 1}) stack.push_back({i, j});
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (i < 0 || j < 0 || i >= nu_ || j >= nv_ || mask[idx(i, j)] || outside[idx(i, j)]) continue;
    outside[idx(i, j)] = 1;
    stack.push_back({i + 1, j});
    stack.push_back({i - 1, j});
    stack.push_back({i, j + 1});
    stack.push_back({i, j - 1});
  }
  c0 = Eigen::Vector2d::Zero();
  std::size_t count = 0;
  for (int j = 0; j < nv_; ++j)
    for (int i = 0; i < nu_; ++i)
      if (!outside[idx(i, j)]) {
        mask[idx(i, j)] = 1;
        c0 += Eigen::Vector2d(u0_ + i * step_, v0_ + j * step_);
        ++count;
      }
  c0 /= double(count);
  auto in_mask = [&](const Eigen::Vector2d& q) {
    const int i = int(std::lround((q.x() - u0_) / step_)),
              j = int(std::lround((q.y() - v0_) / step_));
    return i >= 0 && j >= 0 && i < nu_ && j < nv_ && mask[idx(i, j)];
  };
  if (!in_mask(c0))
    throw std::invalid_argument(
        "the facing endplate region is not star-shaped about its centre; cannot build a disc");

  return mask;
}

// 4. Smoothed polar outline, moved rim_margin inwards; the nucleus scale.
void DiscBetween::set_outline(const std::vector<char>& mask, const Eigen::Vector2d& c0,
                              const VertebraDiscOptions& opt) {
  auto in_mask = [&](const Eigen::Vector2d& q) {
    const int i = int(std::lround((q.x() - u0_) / step_)),
              j = int(std::lround((q.y() - v0_) / step_));
    return i >= 0 && j >= 0 && i < nu_ && j < nv_ && mask[idx(i, j)];
  };
  const std::size_t n_dir = 1024;
  std::vector<double> r_exit(n_dir);
  for (std::size_t k = 0; k < n_dir; ++k) {
    const Eigen::Vector2d dir(std::cos(2 * kPi * double(k) / n_dir),
                              std::sin(2 * kPi * double(k) / n_dir));
    double r = 0;
    while (in_mask(c0 + (r + 0.25 * step_) * dir)) r += 0.25 * step_;
    r_exit[k] = r;
  }
  std::vector<double> r_smooth = low_pass(r_exit, opt.outline_harmonics);
  for (std::size_t k = 0; k < n_dir; ++k) r_smooth[k] = std::min(r_smooth[k], r_exit[k]);
  r_smooth = low_pass(r_smooth, opt.outline_harmonics);
  for (double& r : r_smooth) {
    r -= opt.rim_margin_mm;
    if (!(r > 2.0))
      throw std::invalid_argument(
          "the facing endplate region is too small or too irregular for a disc");
  }
  outline_.c0 = c0;
  outline_.R = r_smooth;
  nucleus_center_ = outline_.centroid();
  nucleus_scale_ = std::sqrt(opt.nucleus_area_fraction);
}

// 5. Report: area, heights, volume (midpoint rule on a half-step grid), extents, frame.
void DiscBetween::measure() {
  const std::size_t n_dir = outline_.R.size();
  info_.footprint_area_mm2 = outline_.area();
  const double h0 = height(s_sup_, nucleus_center_) - height(s_inf_, nucleus_center_);
  if (!(h0 > 0)) throw std::invalid_argument("the endplate gap at the disc centre is not positive");
  info_.center_height_mm = h0;
  const double mid = 0.5 * (height(s_sup_, nucleus_center_) + height(s_inf_, nucleus_center_));
  local_center_ = Eigen::Vector3d(nucleus_center_.x(), mid, nucleus_center_.y());
  info_.min_height_mm = 1e300;
  info_.max_height_mm = 0;
  double y_lo = 1e300, y_hi = -1e300, x_lo = 1e300, x_hi = -1e300, z_lo = 1e300, z_hi = -1e300;
  const double h = 0.5 * step_;
  for (double u = u0_ + 0.5 * h; u < u0_ + (nu_ - 1) * step_; u += h)
    for (double v = v0_ + 0.5 * h; v < v0_ + (nv_ - 1) * step_; v += h) {
      const Eigen::Vector2d q(u, v);
      if (!outline_.contains(q)) continue;
      const double lo = height(s_inf_, q), hi = height(s_sup_, q);
      if (std::isnan(lo) || std::isnan(hi)) continue;
      info_.volume_mm3 += (hi - lo) * h * h;
      info_.min_height_mm = std::min(info_.min_height_mm, hi - lo);
      info_.max_height_mm = std::max(info_.max_height_mm, hi - lo);
      y_lo = std::min(y_lo, lo);
      y_hi = std::max(y_hi, hi);
    }
  if (!(info_.min_height_mm > 0))
    throw std::invalid_argument(
        "the vertebrae do not face each other: the endplates touch or overlap inside the footprint "
        "(gap " +
        fmt(info_.min_height_mm) + " mm)");
  for (std::size_t k = 0; k < n_dir; ++k) {
    const Eigen::Vector2d p = outline_.point(double(k) * outline_.angle_step());
    x_lo = std::min(x_lo, p.x());
    x_hi = std::max(x_hi, p.x());
    z_lo = std::min(z_lo, p.y());
    z_hi = std::max(z_hi, p.y());
  }
  info_.width_mm = x_hi - x_lo;
  info_.depth_mm = z_hi - z_lo;
  info_.frame.axes = axes_;
  info_.frame.origin_mm = origin_ + axes_ * local_center_;
  double r_max = 0;
  for (double r : outline_.R) r_max = std::max(r_max, r + (outline_.c0 - nucleus_center_).norm());
  const double half_h = std::max(std::abs(y_lo - mid), std::abs(y_hi - mid));
  bounding_radius_ = 1.1 * std::sqrt(r_max * r_max + half_h * half_h) + 1.0;
}

std::vector<std::vector<Eigen::Vector3d>> DiscBetween::feature_polylines(double spacing_mm) const {
  std::vector<std::vector<Eigen::Vector3d>> lines;
  double perimeter = 0;
  for (std::size_t k = 0; k < outline_.R.size(); ++k)
    perimeter += (outline_.point(double(k + 1) * outline_.angle_step()) -
                  outline_.point(double(k) * outline_.angle_step()))
                     .norm();
  const int n = std::max(64, int(std::ceil(perimeter / std::max(spacing_mm, 1e-3))));
  for (double scale : {1.0, nucleus_scale_})
    for (const std::vector<double>* field : {&s_inf_, &s_sup_}) {
      std::vector<Eigen::Vector3d> line;
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector2d q =
            nucleus_center_ + scale * (outline_.point(2 * kPi * k / n) - nucleus_center_);
        line.emplace_back(q.x(), height(*field, q), q.y());
      }
      line.push_back(line.front());
      lines.push_back(std::move(line));
    }
  return lines;
}

}  // namespace

namespace {

/// The rims CGAL protects must lie on smooth endplates: a rim that is not finite or drops by more
/// than its own length between neighbouring samples runs into a hole or a broken part of the
/// surface, and CGAL's edge protection never finishes on it. Refused, saying where.
void check_rims(const std::vector<std::vector<Eigen::Vector3d>>& rims) {
  for (const auto& rim : rims)
    for (std::size_t k = 1; k < rim.size(); ++k) {
      const Eigen::Vector3d &a = rim[k - 1], &b = rim[k];
      const double run = std::hypot(b.x() - a.x(), b.z() - a.z()), rise = std::abs(b.y() - a.y());
      if (!a.allFinite() || !b.allFinite() || rise > run + 0.05) {
        std::ostringstream os;
        os << std::setprecision(3) << "the endplate surface is open or broken under the disc's rim "
           << "near (" << a.x() << ", " << a.z() << ") mm in the disc frame (the rim "
           << (a.allFinite() && b.allFinite() ? "drops by " + std::to_string(rise) + " mm"
                                              : "finds no endplate")
           << "): close the surface's holes there";
        throw std::invalid_argument(os.str());
      }
    }
}

}  // namespace

VertebraDiscInfo analyse_vertebra_pair(const TriSurface& inferior_vertebra,
                                       const TriSurface& superior_vertebra,
                                       const VertebraDiscOptions& opt) {
  return DiscBetween(inferior_vertebra, superior_vertebra, opt).info();
}

TetMesh mesh_disc_between_vertebrae(const TriSurface& inferior_vertebra,
                                    const TriSurface& superior_vertebra,
                                    const MeshOptions& mesh_opt, const VertebraDiscOptions& opt,
                                    VertebraDiscInfo* info) {
  const auto disc = std::make_shared<const DiscBetween>(inferior_vertebra, superior_vertebra, opt);
  LabeledBody body;
  body.label = [disc](const Eigen::Vector3d& p) { return disc->label(p); };
  body.classify_facet = [disc](const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
    return disc->classify_facet(c, n);
  };
  body.center_mm = disc->local_center();
  body.bounding_radius_mm = disc->bounding_radius();
  body.exact_volume_mm3 = disc->info().volume_mm3;
  body.features = disc->feature_polylines(std::min(0.25, 0.1 * mesh_opt.cell_size_mm));
  check_rims(body.features);
  body.name = "disc between vertebrae";
  TetMesh m = mesh_labeled_body(body, mesh_opt);
  // Local (upright) -> global: x = origin + axes x_local; a rotation keeps tet orientation.
  m.V = (m.V * disc->axes().transpose()).rowwise() + disc->local_origin().transpose();
  m.frame = disc->info().frame;
  if (info) *info = disc->info();
  return m;
}

}  // namespace spinesim::mesh
