// The scoliotic rest posture (scoliosis.hpp).
#include "spinesim/spine/scoliosis.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/spine/kinematics.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>

namespace spinesim::spine {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr int kVertebrae = 17;  // T1 … L5; the sacrum is body 17 of the chain

std::string fixed1(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", x);
  return b;
}

/// The half-sine weight of joint k (between vertebrae k and k+1) on the stretch of vertebrae
/// [from, to] with its peak at `peak` (from < peak < to).
double sine_weight(int k, double from, double peak, double to) {
  const double p = k + 0.5;
  if (p <= from || p >= to) return 0;
  const double s =
      p <= peak ? 0.5 * (p - from) / (peak - from) : 0.5 + 0.5 * (p - peak) / (to - peak);
  return std::sin(M_PI * s);
}

/// Each joint's weights in the primary curve and the two compensatory ones.
struct Shapes {
  VectorXd primary, above, below, turn;  // per joint (turn: the torsion per unit apical rotation)
};

Shapes shapes(const ScoliosisCurve& c) {
  const int u = vertebra_index(c.upper_end), a = vertebra_index(c.apex),
            l = vertebra_index(c.lower_end);
  Shapes s;
  s.primary = s.above = s.below = s.turn = VectorXd::Zero(kVertebrae);
  // A vertebra's turn: 0 at the ends, 1 at the apex, linear between.
  auto turn_of = [&](int v) {
    if (v <= u || v >= l) return 0.0;
    return v <= a ? double(v - u) / double(a - u) : double(l - v) / double(l - a);
  };
  for (int k = 0; k < kVertebrae; ++k) {
    s.primary[k] = sine_weight(k, u, a, l);
    if (u > 0) s.above[k] = sine_weight(k, 0, 0.5 * u, u);
    if (l < kVertebrae) s.below[k] = sine_weight(k, l, 0.5 * (l + kVertebrae), kVertebrae);
    s.turn[k] = turn_of(k) - turn_of(k + 1);  // vertebra k against the one below
  }
  return s;
}

/// The posture for a primary amplitude `bend` (rad per unit weight) and compensations.
VectorXd posture(const Shapes& s, double side, double bend, double above, double below,
                 double turn_rad) {
  VectorXd theta = VectorXd::Zero(3 * kVertebrae);
  for (int k = 0; k < kVertebrae; ++k) {
    // +θ_z turns the spine above toward −x, so a run of them bulges toward +x: the convexity
    // is on the side of the primary bends' sign.
    theta[3 * k + 2] = side * (bend * s.primary[k] - above * s.above[k] - below * s.below[k]);
    // +θ_y turns the anterior face toward +x: each vertebra of the curve toward the convexity.
    theta[3 * k + 1] = side * turn_rad * s.turn[k];
  }
  return theta;
}

/// T1's residual: its frontal tilt (rad) and its lateral offset from the sacrum's vertical (in
/// units of 100 mm).
Eigen::Vector2d balance(const SpineModel& m, const VectorXd& theta) {
  const std::vector<Pose> P = vertebra_poses(m, theta);
  const Vector3d c = P[0].apply(m.vertebrae[0].centre_mm);
  return {frontal_tilt_deg(P[0].R) * kRadPerDeg, (c.x() - m.vertebrae[0].centre_mm.x()) / 100};
}

/// Each joint's closing angle: tan θ = 2 h / w of its disc (mid height, mean width).
std::vector<double> closing_angles(const SpineModel& m) {
  std::vector<double> out;
  for (const Joint& j : m.joints) out.push_back(std::atan(2 * j.disc_height_mm / j.disc_width_mm));
  return out;
}

}  // namespace

double frontal_tilt_deg(const Eigen::Matrix3d& R) {
  // The endplate's line on an AP radiograph: the lateral axis projected onto the frontal plane.
  // A turn about z by +φ takes it to (cos φ, sin φ) and the long axis toward −x: tilt −φ.
  const Vector3d x = R.col(0);
  return std::atan2(-x.y(), x.x()) / kRadPerDeg;
}

const std::vector<std::string>& scoliosis_curve_types() {
  static const std::vector<std::string> types{"thoracic", "thoracolumbar", "lumbar"};
  return types;
}

ScoliosisCurve scoliosis_curve(const std::string& type, double cobb_deg) {
  ScoliosisCurve c;
  c.type = type;
  c.cobb_deg = cobb_deg;
  if (type == "thoracic") {
    c.upper_end = "T5", c.apex = "T8", c.lower_end = "T11", c.convex_right = true;
  } else if (type == "thoracolumbar") {
    c.upper_end = "T10", c.apex = "T12", c.lower_end = "L2", c.convex_right = true;
  } else if (type == "lumbar") {
    c.upper_end = "T12", c.apex = "L2", c.lower_end = "L4", c.convex_right = false;
  } else {
    throw std::invalid_argument("scoliosis: unknown curve type '" + type +
                                "' (thoracic, thoracolumbar or lumbar)");
  }
  return c;
}

void check_scoliosis_curve(const ScoliosisCurve& c) {
  if (!(c.cobb_deg > 0 && c.cobb_deg <= 120))
    throw std::invalid_argument("scoliosis: the Cobb angle must lie within 0 … 120 deg");
  if (!(std::abs(c.apical_rotation_deg) <= 45))
    throw std::invalid_argument("scoliosis: the apical rotation must lie within ±45 deg");
  const int u = vertebra_index(c.upper_end), a = vertebra_index(c.apex),
            l = vertebra_index(c.lower_end);
  if (l - u < 2)
    throw std::invalid_argument("scoliosis: the upper end vertebra (" + c.upper_end +
                                ") must lie at least two levels above the lower one (" +
                                c.lower_end + ")");
  if (!(u < a && a < l))
    throw std::invalid_argument("scoliosis: the apex " + c.apex + " must lie between " +
                                c.upper_end + " and " + c.lower_end);
}

ScoliosisPosture scoliotic_posture(const SpineModel& m, const ScoliosisCurve& c) {
  check_scoliosis_curve(c);
  if (m.joints.size() != std::size_t(kVertebrae))
    throw std::invalid_argument("scoliosis: the model must have its 17 joints");
  const Shapes s = shapes(c);
  const double side = c.convex_right ? -1.0 : 1.0;
  const double turn = c.apical_rotation_deg * kRadPerDeg;
  const int u = vertebra_index(c.upper_end), a = vertebra_index(c.apex),
            l = vertebra_index(c.lower_end);
  double bend = c.cobb_deg * kRadPerDeg / s.primary.sum();
  double above = 0, below = 0;
  VectorXd theta;
  // Outer: scale the primary bends to the measured Cobb angle; inner: Gauss–Newton on T1's
  // balance over the compensatory amplitudes there are (none, one or two).
  for (int outer = 0; outer < 6; ++outer) {
    for (int inner = 0; inner < 8; ++inner) {
      theta = posture(s, side, bend, above, below, turn);
      const Eigen::Vector2d r = balance(m, theta);
      if (r.norm() < 1e-12) break;
      Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, 2);  // dynamic: GCC warns on the fixed 2×2
      const double h = 1e-6;
      if (u > 0) J.col(0) = (balance(m, posture(s, side, bend, above + h, below, turn)) - r) / h;
      if (l < kVertebrae)
        J.col(1) = (balance(m, posture(s, side, bend, above, below + h, turn)) - r) / h;
      const VectorXd step = J.completeOrthogonalDecomposition().solve(VectorXd(-r));
      above += step[0];
      below += step[1];
    }
    theta = posture(s, side, bend, above, below, turn);
    const std::vector<Pose> P = vertebra_poses(m, theta);
    const double measured =
        std::abs(frontal_tilt_deg(P[std::size_t(u)].R) - frontal_tilt_deg(P[std::size_t(l)].R));
    if (std::abs(measured - c.cobb_deg) < 1e-9 * c.cobb_deg) break;
    bend *= c.cobb_deg / measured;
  }

  ScoliosisPosture out;
  out.theta = theta;
  const std::vector<Pose> P = vertebra_poses(m, theta);
  out.cobb_deg =
      std::abs(frontal_tilt_deg(P[std::size_t(u)].R) - frontal_tilt_deg(P[std::size_t(l)].R));
  auto centre = [&](int v) {
    return P[std::size_t(v)].apply(m.vertebrae[std::size_t(v)].centre_mm);
  };
  const Vector3d cu = centre(u), cl = centre(l), ca = centre(a);
  const double f = (ca.y() - cl.y()) / (cu.y() - cl.y());
  out.apex_offset_mm = ca.x() - (cl.x() + f * (cu.x() - cl.x()));
  auto yaw = [&](int v) {
    const Vector3d z = P[std::size_t(v)].R.col(2);
    return std::atan2(z.x(), z.z()) / kRadPerDeg;
  };
  out.apical_rotation_deg = side * (yaw(a) - 0.5 * (yaw(u) + yaw(l)));
  const Eigen::Vector2d r = balance(m, theta);
  out.t1_tilt_deg = r[0] / kRadPerDeg;
  out.t1_offset_mm = 100 * r[1];
  const std::vector<double> closing = closing_angles(m);
  for (std::size_t k = 0; k < m.joints.size(); ++k) {
    const double share = std::abs(theta[3 * Eigen::Index(k) + 2]) / closing[k];
    if (share > out.largest_share) {
      out.largest_share = share;
      out.largest_share_joint = m.joints[k].name;
    }
  }
  if (out.largest_share > 1) {
    const std::size_t k = std::size_t(joint_index(out.largest_share_joint));
    throw std::invalid_argument(
        "scoliosis: a Cobb angle of " + fixed1(c.cobb_deg) + " deg bends " +
        out.largest_share_joint + " by " +
        fixed1(std::abs(theta[3 * Eigen::Index(k) + 2]) / kRadPerDeg) + " deg, beyond the " +
        fixed1(closing[k] / kRadPerDeg) +
        " deg that closes its disc's concave side: the model cannot pose it");
  }
  return out;
}

}  // namespace spinesim::spine
