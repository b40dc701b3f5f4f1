// Kidney-shaped disc cross-section and the lofted parametric disc (see disc_geometry.hpp).
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace spinesim::mesh {
namespace {

// Base curve before scaling: polar ellipse (a = 1, b = 0.75) with a posterior notch.
constexpr double kA = 1.0, kB = 0.75, kNotchDepth = 0.3;
constexpr int kNotchPower = 16;

double base_radius(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  const double ellipse = kA * kB / std::sqrt(kB * kB * c * c + kA * kA * s * s);
  const double g = std::pow(0.5 * (1.0 - s), kNotchPower);  // 1 at θ = -π/2, smooth, periodic
  return ellipse * (1.0 - kNotchDepth * g);
}

// Extents, area and centroid of the base curve, computed once.
struct BaseShape {
  double x_max = 0, z_max = 0, z_min = 0;  // x_min = -x_max (mirror symmetric)
  double area = 0, centroid_z = 0;
};

// Maximises f on [a, b] by golden-section search (f unimodal there).
template <class F>
double golden_max(F f, double a, double b) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int it = 0; it < 200 && b - a > 1e-15; ++it) {
    if (fc > fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  return f(0.5 * (a + b));
}

// Extreme of f over the circle: dense scan, then golden-section refinement around the best.
template <class F>
double circle_max(F f) {
  const int n = 4096;
  int best = 0;
  double fbest = -1e300;
  for (int k = 0; k < n; ++k) {
    const double v = f(2 * kPi * k / n);
    if (v > fbest) {
      fbest = v;
      best = k;
    }
  }
  const double h = 2 * kPi / n;
  return golden_max(f, 2 * kPi * best / n - h, 2 * kPi * best / n + h);
}

// Trapezoid rule on a smooth periodic integrand converges geometrically; 2^14 nodes are far
// beyond convergence (checked against 2^13 below).
BaseShape compute_base_shape() {
  BaseShape b;
  b.x_max = circle_max([](double t) { return base_radius(t) * std::cos(t); });
  b.z_max = circle_max([](double t) { return base_radius(t) * std::sin(t); });
  b.z_min = -circle_max([](double t) { return -base_radius(t) * std::sin(t); });
  auto integrate = [](int n, double& area, double& mz) {
    area = mz = 0;
    for (int k = 0; k < n; ++k) {
      const double t = 2 * kPi * k / n, r = base_radius(t);
      area += 0.5 * r * r;
      mz += r * r * r * std::sin(t) / 3.0;
    }
    area *= 2 * kPi / n;
    mz *= 2 * kPi / n;
  };
  double a1, m1, a2, m2;
  integrate(1 << 13, a1, m1);
  integrate(1 << 14, a2, m2);
  assert(std::abs(a1 - a2) < 1e-12 && std::abs(m1 - m2) < 1e-12);
  b.area = a2;
  b.centroid_z = m2 / a2;
  return b;
}

const BaseShape& base_shape() {
  static const BaseShape b = compute_base_shape();
  return b;
}

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

}  // namespace

// ----------------------------------------------------------------------------- KidneyOutline

KidneyOutline::KidneyOutline(double width_mm, double depth_mm)
    : width_(width_mm), depth_(depth_mm) {
  if (!(width_mm > 0) || !(depth_mm > 0) || !std::isfinite(width_mm) || !std::isfinite(depth_mm))
    throw std::invalid_argument("disc outline: width and depth must be finite and > 0 mm (got " +
                                fmt(width_mm) + " x " + fmt(depth_mm) + ")");
  const BaseShape& b = base_shape();
  sx_ = width_mm / (2 * b.x_max);
  sz_ = depth_mm / (b.z_max - b.z_min);
  shift_ = sz_ * b.centroid_z;
}

Eigen::Vector2d KidneyOutline::point(double theta) const {
  const double r = base_radius(theta);
  return {sx_ * r * std::cos(theta), sz_ * r * std::sin(theta) - shift_};
}

bool KidneyOutline::contains(const Eigen::Vector2d& xz) const {
  const double X = xz.x() / sx_, Z = (xz.y() + shift_) / sz_;
  const double rho2 = X * X + Z * Z;
  if (rho2 == 0.0) return true;
  const double r = base_radius(std::atan2(Z, X));
  return rho2 <= r * r;
}

bool KidneyOutline::nucleus_contains(const Eigen::Vector2d& xz) const {
  // The centroid is the origin, so scaling about it is a plain division.
  return contains(xz / std::sqrt(kNucleusAreaFraction));
}

double KidneyOutline::signed_curvature(double theta) const {
  const double h = 1e-4;
  const Eigen::Vector2d p0 = point(theta - h), p1 = point(theta), p2 = point(theta + h);
  const Eigen::Vector2d d1 = (p2 - p0) / (2 * h), d2 = (p2 - 2 * p1 + p0) / (h * h);
  const double speed = d1.norm();
  return (d1.x() * d2.y() - d1.y() * d2.x()) / (speed * speed * speed);
}

double KidneyOutline::area_mm2() const { return sx_ * sz_ * base_shape().area; }

Eigen::Vector2d KidneyOutline::centroid_mm() const {
  return {0.0, sz_ * base_shape().centroid_z - shift_};
}

double KidneyOutline::min_z_mm() const { return sz_ * base_shape().z_min - shift_; }

std::vector<Eigen::Vector2d> KidneyOutline::sample(int n, double scale) const {
  std::vector<Eigen::Vector2d> pts(static_cast<std::size_t>(std::max(n, 3)));
  const Eigen::Vector2d c = centroid_mm();
  for (std::size_t k = 0; k < pts.size(); ++k)
    pts[k] = c + scale * (point(2 * kPi * double(k) / double(pts.size())) - c);
  return pts;
}

// ---------------------------------------------------------------------------- ParametricDisc

ParametricDisc::ParametricDisc(const DiscDimensions& d) : dims_(d) {
  for (double v :
       {d.lower_width_mm, d.lower_depth_mm, d.upper_width_mm, d.upper_depth_mm, d.height_mm})
    if (!(v > 0) || !std::isfinite(v))
      throw std::invalid_argument("disc '" + d.level +
                                  "': widths, depths and height must be finite and > 0 mm");
}

KidneyOutline ParametricDisc::outline_at(double y_mm) const {
  const double t = std::clamp(y_mm / dims_.height_mm + 0.5, 0.0, 1.0);
  return KidneyOutline((1 - t) * dims_.lower_width_mm + t * dims_.upper_width_mm,
                       (1 - t) * dims_.lower_depth_mm + t * dims_.upper_depth_mm);
}

int ParametricDisc::label(const Eigen::Vector3d& p) const {
  const double half = 0.5 * dims_.height_mm;
  if (p.y() < -half || p.y() > half) return 0;
  const KidneyOutline o = outline_at(p.y());
  const Eigen::Vector2d xz(p.x(), p.z());
  if (!o.contains(xz)) return 0;
  return o.nucleus_contains(xz) ? int(Region::nucleus) : int(Region::annulus);
}

Surface ParametricDisc::classify_facet(const Eigen::Vector3d& c, const Eigen::Vector3d& n) const {
  const double half = 0.5 * dims_.height_mm;
  const double d_bottom = std::abs(c.y() + half), d_top = std::abs(c.y() - half);
  // Distance to the wall, measured radially from the axis at the centroid's height (an upper
  // bound of the true distance, good enough to rank against the planes).
  const KidneyOutline o = outline_at(c.y());
  const Eigen::Vector2d q(c.x(), c.z());
  double d_wall = 0.0;
  if (q.norm() > 1e-12) {
    // Bisection for the boundary point along the ray from the centroid through q.
    double lo = 0.0, hi = 2.0;
    while (o.contains(hi * q)) hi *= 2;
    for (int it = 0; it < 50; ++it) {
      const double mid = 0.5 * (lo + hi);
      (o.contains(mid * q) ? lo : hi) = mid;
    }
    d_wall = std::abs(1.0 - lo) * q.norm();
  } else {
    d_wall = 1e300;
  }
  if (d_bottom <= d_top && d_bottom < d_wall && n.y() < -0.5) return Surface::inferior_endplate;
  if (d_top < d_bottom && d_top < d_wall && n.y() > 0.5) return Surface::superior_endplate;
  return Surface::outer_wall;
}

double ParametricDisc::volume_mm3() const {
  const double w0 = dims_.lower_width_mm, d0 = dims_.lower_depth_mm;
  const double dw = dims_.upper_width_mm - w0, dd = dims_.upper_depth_mm - d0;
  const double unit_area = KidneyOutline(1.0, 1.0).area_mm2();
  return dims_.height_mm * unit_area * (w0 * d0 + 0.5 * (w0 * dd + d0 * dw) + dw * dd / 3.0);
}

std::vector<std::vector<Eigen::Vector3d>> ParametricDisc::feature_polylines(
    double spacing_mm) const {
  std::vector<std::vector<Eigen::Vector3d>> lines;
  const double half = 0.5 * dims_.height_mm;
  for (double y : {-half, half}) {
    const KidneyOutline o = outline_at(y);
    for (double scale : {1.0, std::sqrt(kNucleusAreaFraction)}) {
      // Perimeter < π (W + D); sample densely enough for ~spacing_mm chords.
      const double perimeter = kPi * (o.width_mm() + o.depth_mm()) * scale;
      const int n = std::max(64, int(std::ceil(perimeter / std::max(spacing_mm, 1e-3))));
      std::vector<Eigen::Vector3d> line;
      line.reserve(std::size_t(n) + 1);
      for (const Eigen::Vector2d& q : o.sample(n, scale)) line.emplace_back(q.x(), y, q.y());
      line.push_back(line.front());
      lines.push_back(std::move(line));
    }
  }
  return lines;
}

double parametric_disc_volume(const DiscDimensions& dims) {
  return ParametricDisc(dims).volume_mm3();
}

}  // namespace spinesim::mesh
