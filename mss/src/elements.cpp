// Element energies of the tetrahedral mass-spring disc, with exact and projected Hessians; the
// equations, units and sign conventions are in elements.hpp. These are the hot kernels (about
// 50k calls per time step): fixed-size Eigen types, no allocation, the Hessian only when asked.
#include "spinesim/mss/elements.hpp"
#include "spinesim/common/skew.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace spinesim::mss {

namespace {

// Below kMinLength_mm (elements.hpp) a direction (edge, radial arm, probe normal, angle arm) is
// undefined. Meshes are validated upstream (edges ~1 mm), so this only catches coincident points.
// The comparisons are written so that a NaN input falls through and propagates, not hidden.
// Below this sin(theta) the arms are collinear and the angle's gradient direction undefined.
constexpr double kMinSin = 1e-12;

// Adds scale * T to H, where T is the Hessian with respect to N arms x_i - x0 (i = 1..N) and H
// the Hessian with respect to (x0, x1, ..., xN): d/dx_i = d/d(arm_i), d/dx0 = -sum_i d/d(arm_i).
// T must be symmetric.
template <int N>
void add_arm_hessian(const Eigen::Matrix<double, 3 * N, 3 * N>& T, double scale,
                     Eigen::Matrix<double, 3 * N + 3, 3 * N + 3>& H) {
  H.template bottomRightCorner<3 * N, 3 * N>() += scale * T;
  Eigen::Matrix3d apex = Eigen::Matrix3d::Zero();
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix3d column_sum = Eigen::Matrix3d::Zero();
    for (int i = 0; i < N; ++i) column_sum += T.template block<3, 3>(3 * i, 3 * j);
    H.template block<3, 3>(0, 3 + 3 * j) -= scale * column_sum;
    H.template block<3, 3>(3 + 3 * j, 0) -= scale * column_sum.transpose();
    apex += column_sum;
  }
  H.template topLeftCorner<3, 3>() += scale * apex;
}

// Hessian of a two-point term whose 3x3 block with respect to x1 is K: [K -K; -K K].
void set_pair_hessian(const Eigen::Matrix3d& K, Matrix6d& H) {
  H.topLeftCorner<3, 3>() = K;
  H.bottomRightCorner<3, 3>() = K;
  H.topRightCorner<3, 3>() = -K;
  H.bottomLeftCorner<3, 3>() = -K;
}

// Stretch stiffness of a penalty |d| -> 1/2 k (|d| - L0)^2 along unit u: k[t I + (1 - t) uu^T],
// t = 1 - L0/|d| (the transverse part), clamped at 0 for the projected Hessian.
Eigen::Matrix3d stretch_stiffness(const Eigen::Vector3d& u, double k, double t, HessianMode mode) {
  if (mode == HessianMode::projected) t = std::max(0.0, t);
  Eigen::Matrix3d K = (k * (1.0 - t)) * (u * u.transpose());
  K.diagonal().array() += k * t;
  return K;
}

}  // namespace

double edge_spring(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, double k_n_per_mm,
                   double rest_length_mm, Vector6d* grad, Matrix6d* hess, HessianMode mode) {
  const Eigen::Vector3d d = x1 - x0;
  const double l = d.norm();
  const double stretch = l - rest_length_mm;
  const double energy = 0.5 * k_n_per_mm * stretch * stretch;
  if (!grad && !hess) return energy;

  if (l < kMinLength_mm) {
    // Coincident ends: no direction to push along, so zero force; the stiffness is k/3 I, the
    // isotropic mean of k uu^T, so the Hessian stays PSD and an implicit step still feels it.
    if (grad) grad->setZero();
    if (hess) set_pair_hessian(Eigen::Matrix3d::Identity() * (k_n_per_mm / 3.0), *hess);
    return energy;
  }
  const Eigen::Vector3d u = d / l;
  if (grad) {
    const Eigen::Vector3d g1 = (k_n_per_mm * stretch) * u;
    grad->head<3>() = -g1;
    grad->tail<3>() = g1;
  }
  if (hess)
    set_pair_hessian(stretch_stiffness(u, k_n_per_mm, 1.0 - rest_length_mm / l, mode), *hess);
  return energy;
}

double radial_springs(const TetPoints& x, double k_s_n_per_mm, double rest_sum_mm, Vector12d* grad,
                      Matrix12d* hess, HessianMode mode) {
  const Eigen::Vector3d barycentre = 0.25 * x.rowwise().sum();
  TetPoints u;  // unit radial directions u_j, columns
  double r[4];  // radial lengths |x_j - x_B|, mm
  double S = 0.0;
  for (int j = 0; j < 4; ++j) {
    const Eigen::Vector3d rj = x.col(j) - barycentre;
    r[j] = rj.norm();
    S += r[j];
    // A vertex at the barycentre (flat tet) has no radial direction: take the zero
    // subgradient of |.| there, and drop its (unbounded) curvature below.
    if (r[j] < kMinLength_mm)
      u.col(j).setZero();
    else
      u.col(j) = rj / r[j];
  }
  const double excess = S - rest_sum_mm;
  const double energy = 0.5 * k_s_n_per_mm * excess * excess;
  if (!grad && !hess) return energy;

  // dS/dx_i = u_i - (1/4) sum_j u_j: the vertex's own arm plus the barycentre's reaction.
  const Eigen::Vector3d u_mean = 0.25 * u.rowwise().sum();
  Vector12d grad_S;
  for (int i = 0; i < 4; ++i) grad_S.segment<3>(3 * i) = u.col(i) - u_mean;
  if (grad) *grad = (k_s_n_per_mm * excess) * grad_S;
  if (hess) {
    *hess = k_s_n_per_mm * (grad_S * grad_S.transpose());
    const double t = mode == HessianMode::projected ? std::max(0.0, excess) : excess;
    if (t != 0.0) {
      // H_S = sum_j P_j^T A_j P_j with r_j = P_j x (P = I - 1/4 ones) and A_j = (I - u_j
      // u_j^T)/r_j the Hessian of |r_j|; block (i, m) = d_im A_i - (A_i + A_m)/4 + sum A / 16.
      Eigen::Matrix3d A[4];
      Eigen::Matrix3d A_sum = Eigen::Matrix3d::Zero();
      for (int j = 0; j < 4; ++j) {
        if (r[j] < kMinLength_mm) {
          A[j].setZero();
        } else {
          A[j] = (Eigen::Matrix3d::Identity() - u.col(j) * u.col(j).transpose()) / r[j];
        }
        A_sum += A[j];
      }
      const double kt = k_s_n_per_mm * t;
      const Eigen::Matrix3d common = (kt / 16.0) * A_sum;
      for (int i = 0; i < 4; ++i) {
        for (int m = 0; m < 4; ++m) {
          auto block = hess->block<3, 3>(3 * i, 3 * m);
          block += common - (0.25 * kt) * (A[i] + A[m]);
          if (i == m) block += kt * A[i];
        }
      }
    }
  }
  return energy;
}

double angle_at(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  const Eigen::Vector3d a = x1 - x0;
  const Eigen::Vector3d b = x2 - x0;
  // atan2 keeps full relative accuracy near 0 and pi, where acos of the cosine loses it.
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

namespace {

// The angle at the apex and its gradient with respect to the two arms a, b (rad/mm).
struct ArmAngle {
  double theta;
  bool degenerate;                   // an arm of zero length or collinear arms: direction undefined
  double dot, cross_norm, la2, lb2;  // a.b, |a x b|, |a|^2, |b|^2
  Eigen::Vector3d dtheta_da, dtheta_db;
};

ArmAngle arm_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  ArmAngle g;
  g.dot = a.dot(b);
  g.cross_norm = a.cross(b).norm();
  g.la2 = a.squaredNorm();
  g.lb2 = b.squaredNorm();
  g.theta = std::atan2(g.cross_norm, g.dot);
  constexpr double min_l2 = kMinLength_mm * kMinLength_mm;
  g.degenerate = g.la2 < min_l2 || g.lb2 < min_l2 ||
                 g.cross_norm * g.cross_norm < kMinSin * kMinSin * g.la2 * g.lb2;
  if (g.degenerate) return g;
  // d theta/da = ((a.b)/|a|^2 a - b)/|a x b|, and the same with a and b swapped: one square
  // root (|a x b|, shared with theta) and three divisions.
  const double inv_cross = 1.0 / g.cross_norm;
  g.dtheta_da = (g.dot / g.la2 * a - b) * inv_cross;
  g.dtheta_db = (g.dot / g.lb2 * b - a) * inv_cross;
  return g;
}

}  // namespace

double angle_spring(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                    double k_t_nmm_per_rad, double rest_angle_rad, Vector9d* grad, Matrix9d* hess,
                    HessianMode mode) {
  const Eigen::Vector3d a = x1 - x0;
  const Eigen::Vector3d b = x2 - x0;
  if (!grad && !hess) {
    const double dtheta = std::atan2(a.cross(b).norm(), a.dot(b)) - rest_angle_rad;
    return 0.5 * k_t_nmm_per_rad * dtheta * dtheta;
  }
  const ArmAngle g = arm_angle(a, b);
  const double dtheta = g.theta - rest_angle_rad;
  const double energy = 0.5 * k_t_nmm_per_rad * dtheta * dtheta;

  if (g.degenerate) {
    // Collinear arms (or a zero-length arm): theta has a kink there and no direction to turn
    // in, so zero force and zero stiffness. Only a flat (invalid) triangle gets here.
    if (grad) grad->setZero();
    if (hess) hess->setZero();
    return energy;
  }
  Vector9d grad_theta;
  grad_theta.segment<3>(0) = -(g.dtheta_da + g.dtheta_db);
  grad_theta.segment<3>(3) = g.dtheta_da;
  grad_theta.segment<3>(6) = g.dtheta_db;
  if (grad) *grad = (k_t_nmm_per_rad * dtheta) * grad_theta;
  if (hess) {
    *hess = k_t_nmm_per_rad * (grad_theta * grad_theta.transpose());
    if (mode == HessianMode::exact && dtheta != 0.0) {
      // theta = acos c, c = a.b/(|a||b|):  H_theta = -(H_c + c grad_theta grad_theta^T)/sin
      // (from -(1/sin) H_c - (cos/sin^3) grad_c grad_c^T with grad_c = -sin grad_theta), and
      //   H_c,aa = -(b^ a^T + a^ b^T + c (I - 3 a^ a^T))/|a|^2,  H_c,bb likewise,
      //   H_c,ab = (I - a^ a^T - b^ b^T + c a^ b^T)/(|a||b|)      (a^ = a/|a|, rows a).
      const double la = std::sqrt(g.la2);
      const double lb = std::sqrt(g.lb2);
      const Eigen::Vector3d a_hat = a / la;
      const Eigen::Vector3d b_hat = b / lb;
      const double c = g.dot / (la * lb);
      const double sin_theta = g.cross_norm / (la * lb);
      const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
      const Eigen::Matrix3d aa = a_hat * a_hat.transpose();
      const Eigen::Matrix3d bb = b_hat * b_hat.transpose();
      const Eigen::Matrix3d ab = a_hat * b_hat.transpose();
      const Eigen::Matrix3d ab_sym = ab + ab.transpose();
      Matrix6d T;  // H_c + c grad_theta grad_theta^T with respect to the arms (a, b)
      T.topLeftCorner<3, 3>() =
          -(ab_sym + c * (I - 3.0 * aa)) / g.la2 + c * g.dtheta_da * g.dtheta_da.transpose();
      T.bottomRightCorner<3, 3>() =
          -(ab_sym + c * (I - 3.0 * bb)) / g.lb2 + c * g.dtheta_db * g.dtheta_db.transpose();
      T.topRightCorner<3, 3>() =
          (I - aa - bb + c * ab) / (la * lb) + c * g.dtheta_da * g.dtheta_db.transpose();
      T.bottomLeftCorner<3, 3>() = T.topRightCorner<3, 3>().transpose();
      add_arm_hessian<2>(T, -k_t_nmm_per_rad * dtheta / sin_theta, *hess);
    }
  }
  return energy;
}

Vector6d thesis_torsion_force(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                              const Eigen::Vector3d& x2, double k_t_nmm_per_rad,
                              double rest_angle_rad) {
  // (5.13) per arm l with Axis = l x (other arm):
  //   f_l = -(Axis x l)/|Axis x l| k_t (theta_r - theta)/|l|.
  // Axis x l lies in the plane, normal to l, towards the other arm, so an over-opened angle
  // pulls both arm ends together. Orienting Axis per arm is what makes the two arms agree.
  const Eigen::Vector3d a = x1 - x0;
  const Eigen::Vector3d b = x2 - x0;
  const ArmAngle g = arm_angle(a, b);
  Vector6d f = Vector6d::Zero();
  if (g.degenerate) return f;  // same choice as angle_spring: no direction, no force
  const double moment = k_t_nmm_per_rad * (rest_angle_rad - g.theta);
  const Eigen::Vector3d toward_b = a.cross(b).cross(a);
  const Eigen::Vector3d toward_a = b.cross(a).cross(b);
  f.head<3>() = -toward_b.normalized() * (moment / a.norm());
  f.tail<3>() = -toward_a.normalized() * (moment / b.norm());
  return f;
}

namespace {

// a.(b x c)/6 for arms a, b, c from x0; given b x c, so that tet_signed_volume and
// volume_penalty round identically (volume_penalty is exactly zero at V = V0). Written per
// coefficient: a packed a.dot() re-reads the cross product just stored as scalars and stalls.
double volume_from_arms(const Eigen::Vector3d& a, const Eigen::Vector3d& b_cross_c) {
  return (a.x() * b_cross_c.x() + a.y() * b_cross_c.y() + a.z() * b_cross_c.z()) / 6.0;
}

}  // namespace

double tet_signed_volume(const TetPoints& x) {
  const Eigen::Vector3d a = x.col(1) - x.col(0);
  const Eigen::Vector3d b = x.col(2) - x.col(0);
  const Eigen::Vector3d c = x.col(3) - x.col(0);
  return volume_from_arms(a, b.cross(c));
}

double volume_penalty(const TetPoints& x, double k_v_n_per_mm5, double rest_volume_mm3,
                      Vector12d* grad, Matrix12d* hess, HessianMode mode) {
  const Eigen::Vector3d a = x.col(1) - x.col(0);
  const Eigen::Vector3d b = x.col(2) - x.col(0);
  const Eigen::Vector3d c = x.col(3) - x.col(0);
  const Eigen::Vector3d b_cross_c = b.cross(c);
  const double V = volume_from_arms(a, b_cross_c);
  const double excess = V - rest_volume_mm3;
  const double energy = 0.5 * k_v_n_per_mm5 * excess * excess;
  if (!grad && !hess) return energy;

  // 6 dV/dx_i is twice the area vector of the face opposite x_i (pointing towards x_i); the 1/6
  // goes into one scale factor.
  const Eigen::Vector3d c_cross_a = c.cross(a);
  const Eigen::Vector3d a_cross_b = a.cross(b);
  if (grad) {
    // Per coefficient, straight into *grad: staging a 12-vector and scaling it, or packed
    // reads of the cross products, made this 2-3x slower (stores re-read at another width).
    const double scale = k_v_n_per_mm5 * excess / 6.0;
    for (int d = 0; d < 3; ++d) {
      (*grad)(3 + d) = scale * b_cross_c(d);
      (*grad)(6 + d) = scale * c_cross_a(d);
      (*grad)(9 + d) = scale * a_cross_b(d);
      (*grad)(d) = -((*grad)(3 + d) + (*grad)(6 + d) + (*grad)(9 + d));
    }
  }
  if (hess) {
    Vector12d grad_6V;
    grad_6V.segment<3>(0) = -(b_cross_c + c_cross_a + a_cross_b);
    grad_6V.segment<3>(3) = b_cross_c;
    grad_6V.segment<3>(6) = c_cross_a;
    grad_6V.segment<3>(9) = a_cross_b;
    *hess = (k_v_n_per_mm5 / 36.0) * (grad_6V * grad_6V.transpose());
    if (mode == HessianMode::exact && excess != 0.0) {
      // V = a.(b x c)/6 is trilinear in the arms; T = 6 d2V/d(a,b,c)^2 has zero diagonal
      // blocks and 6 d2V/da db = -[c]x, 6 d2V/da dc = [b]x, 6 d2V/db dc = -[a]x.
      const Eigen::Matrix3d Sa = skew(a);
      const Eigen::Matrix3d Sb = skew(b);
      const Eigen::Matrix3d Sc = skew(c);
      Eigen::Matrix<double, 9, 9> T;
      T << Eigen::Matrix3d::Zero(), -Sc, Sb,  //
          Sc, Eigen::Matrix3d::Zero(), -Sa,   //
          -Sb, Sa, Eigen::Matrix3d::Zero();
      add_arm_hessian<3>(T, k_v_n_per_mm5 * excess / 6.0, *hess);
    }
  }
  return energy;
}

double probe_contact(const Eigen::Vector3d& x, const Eigen::Vector3d& center_mm, double radius_mm,
                     double k_p_n_per_mm, Eigen::Vector3d* grad, Eigen::Matrix3d* hess,
                     HessianMode mode) {
  const Eigen::Vector3d d = x - center_mm;
  const double dist = d.norm();
  const double penetration = radius_mm - dist;
  if (penetration <= 0.0) {  // outside (written so that NaN takes the other branch)
    if (grad) grad->setZero();
    if (hess) hess->setZero();
    return 0.0;
  }
  const double energy = 0.5 * k_p_n_per_mm * penetration * penetration;
  if (!grad && !hess) return energy;

  if (dist < kMinLength_mm) {
    // Node at the probe centre: no outward direction, so zero force; stiffness k/3 I (the
    // isotropic mean of k nn^T), as for a zero-length edge.
    if (grad) grad->setZero();
    if (hess) *hess = Eigen::Matrix3d::Identity() * (k_p_n_per_mm / 3.0);
    return energy;
  }
  const Eigen::Vector3d n = d / dist;
  if (grad) *grad = (-k_p_n_per_mm * penetration) * n;
  // E = 1/2 k (dist - r)^2 is an edge spring of rest length r to the centre, always compressed
  // inside: the projected Hessian is k nn^T.
  if (hess) *hess = stretch_stiffness(n, k_p_n_per_mm, 1.0 - radius_mm / dist, mode);
  return energy;
}

Eigen::Vector4d fibre_coefficients(const TetPoints& rest, const Eigen::Vector3d& direction) {
  Eigen::Matrix3d D;
  for (int k = 0; k < 3; ++k) D.col(k) = rest.col(k + 1) - rest.col(0);
  const double det = D.determinant();
  if (!(std::abs(det) > 1e-300) || !std::isfinite(det))
    throw std::invalid_argument("mss: fibre spring in a degenerate tetrahedron");
  // Barycentric coordinates 1..3 are D^{-1} (X - x0): their gradients are the rows of D^{-1}.
  const Eigen::Vector3d tail = D.inverse() * direction;
  Eigen::Vector4d c;
  c << -tail.sum(), tail;
  return c;
}

double fibre_law(double excess, double k1, double k2, double& psi1, double& psi2) {
  psi1 = psi2 = 0.0;
  if (!(excess > 0.0)) return excess == excess ? 0.0 : excess;
  const double e = std::exp(k2 * excess * excess);
  psi1 = k1 * excess * e;
  psi2 = k1 * e * (1.0 + 2.0 * k2 * excess * excess);
  return k2 > 0.0 ? k1 / (2.0 * k2) * (e - 1.0) : 0.5 * k1 * excess * excess;
}

namespace {

/// det[a, b, c] of the arms a = x1 − x0, b = x2 − x0, c = x3 − x0, its gradient (12) and Hessian
/// (12×12): ∂/∂a = b × c, ∂/∂b = c × a, ∂/∂c = a × b; ∂²/∂a∂b = −[c]×, ∂²/∂a∂c = [b]×,
/// ∂²/∂b∂c = −[a]×; x0 takes minus the sum of the arms' rows and columns.
double arm_determinant_derivatives(const TetPoints& x, Vector12d& grad, Matrix12d* hess) {
  const Eigen::Vector3d a = x.col(1) - x.col(0), b = x.col(2) - x.col(0), c = x.col(3) - x.col(0);
  const Eigen::Vector3d ga = b.cross(c), gb = c.cross(a), gc = a.cross(b);
  grad << -(ga + gb + gc), ga, gb, gc;
  if (hess) {
    Eigen::Matrix<double, 9, 9> arms = Eigen::Matrix<double, 9, 9>::Zero();
    arms.block<3, 3>(0, 3) = -skew(c), arms.block<3, 3>(0, 6) = skew(b);
    arms.block<3, 3>(3, 6) = -skew(a);
    arms.block<3, 3>(3, 0) = arms.block<3, 3>(0, 3).transpose();
    arms.block<3, 3>(6, 0) = arms.block<3, 3>(0, 6).transpose();
    arms.block<3, 3>(6, 3) = arms.block<3, 3>(3, 6).transpose();
    // x = (x0, arms + x0): H = Pᵀ arms P with P = [−I −I −I; I 0 0; 0 I 0; 0 0 I]ᵀ blocks.
    Eigen::Matrix<double, 9, 12> P = Eigen::Matrix<double, 9, 12>::Zero();
    for (int k = 0; k < 3; ++k) {
      P.block<3, 3>(3 * k, 0) = -Eigen::Matrix3d::Identity();
      P.block<3, 3>(3 * k, 3 * (k + 1)) = Eigen::Matrix3d::Identity();
    }
    *hess = P.transpose() * arms * P;
  }
  return a.dot(ga);
}

}  // namespace

double arm_determinant(const TetPoints& x) {
  Vector12d unused;
  return arm_determinant_derivatives(x, unused, nullptr);
}

double isochoric_fibre(const TetPoints& x, const Eigen::Vector4d& c, double V0, double k1,
                       double k2, double rest_det, Vector12d* grad, Matrix12d* hess, double rest_i4,
                       HessianMode mode) {
  if (grad) grad->setZero();
  if (hess) hess->setZero();
  Vector12d gJ;
  Matrix12d hJ;
  const double J =
      arm_determinant_derivatives(x, gJ, hess && mode == HessianMode::exact ? &hJ : nullptr) /
      rest_det;
  if (!(J > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d d = x * c;
  const double i4 = d.squaredNorm() / rest_i4;
  // A slack fibre (Ī4 = J^(-2/3) I4 <= 1, i.e. I4³ <= J²) has no energy, force or stiffness:
  // decided without the cube root, which is most of a slack fibre's cost (about half the fibres
  // of a loaded disc, and all of them at rest). A NaN I4 goes on and propagates.
  if (i4 * i4 * i4 <= J * J) return 0.0;
  gJ /= rest_det;
  const double cbrt_J = std::cbrt(J), j23 = 1.0 / (cbrt_J * cbrt_J), bar = j23 * i4;
  double psi1 = 0, psi2 = 0;
  const double energy = V0 * fibre_law(bar - 1.0, k1, k2, psi1, psi2);
  if (!(psi1 > 0.0) || (!grad && !hess)) return energy;
  Vector12d gI4;  // ∇I4 = 2 c_i d / rest_i4
  for (int i = 0; i < 4; ++i) gI4.segment<3>(3 * i) = (2.0 * c(i) / rest_i4) * d;
  const Vector12d gBar = j23 * gI4 - (2.0 / 3.0) * (bar / J) * gJ;
  if (grad) *grad = (V0 * psi1) * gBar;
  if (hess) {
    Matrix12d hI4 = Matrix12d::Zero();  // ∇²I4 = 2 c_i c_j I / rest_i4
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        hI4.block<3, 3>(3 * i, 3 * j) = (2.0 * c(i) * c(j) / rest_i4) * Eigen::Matrix3d::Identity();
    Matrix12d hBar = j23 * hI4;
    if (mode == HessianMode::exact) {
      hBar += -(2.0 / 3.0) * j23 / J * (gI4 * gJ.transpose() + gJ * gI4.transpose()) +
              (10.0 / 9.0) * bar / (J * J) * gJ * gJ.transpose() -
              (2.0 / 3.0) * (bar / J) * (hJ / rest_det);
    }
    *hess = V0 * (psi2 * gBar * gBar.transpose() + psi1 * hBar);
  }
  return energy;
}

Matrix12d fibre_rest_tangent(const TetPoints& X, const Eigen::Vector4d& c, double V0, double k1,
                             double rest_det, double rest_i4, bool isochoric) {
  const Eigen::Vector3d d = X * c;
  Vector12d g;  // ∇I4 = 2 c_i d / rest_i4
  for (int i = 0; i < 4; ++i) g.segment<3>(3 * i) = (2.0 * c(i) / rest_i4) * d;
  if (isochoric) {  // ∇Ī4 = J^(-2/3) ∇I4 - (2/3) (Ī4 / J) ∇J, with J and Ī4 as computed at rest
    Vector12d gJ;
    const double J = arm_determinant_derivatives(X, gJ, nullptr) / rest_det;
    gJ /= rest_det;
    const double j23 = std::pow(J, -2.0 / 3.0), bar = j23 * d.squaredNorm() / rest_i4;
    g = j23 * g - (2.0 / 3.0) * (bar / J) * gJ;
  }
  return (V0 * k1) * g * g.transpose();
}

double fibre_spring(const TetPoints& x, const Eigen::Vector4d& c, double V0, double k1, double k2,
                    Vector12d* grad, Matrix12d* hess, double rest_i4) {
  // I4 = |d|^2 / rest_i4: dividing by the rest value as rounded puts the rest state exactly at
  // the kink (|X c|^2 = 1 only to round-off, and half the springs would be "in tension").
  const Eigen::Vector3d d = x * c;
  const double excess = (d.squaredNorm() - rest_i4) / rest_i4;  // I4 - 1
  if (grad) grad->setZero();
  if (hess) hess->setZero();
  if (!(excess > 0.0)) return excess == excess ? 0.0 : excess;  // compression; NaN propagates
  const double e = std::exp(k2 * excess * excess);
  const double energy =
      k2 > 0.0 ? V0 * k1 / (2.0 * k2) * (e - 1.0) : 0.5 * V0 * k1 * excess * excess;
  if (!grad && !hess) return energy;
  // Derivatives of I4 carry 1/rest_i4: folded into psi' and psi''.
  const double psi1 = k1 * excess * e / rest_i4,
               psi2 = k1 * e * (1.0 + 2.0 * k2 * excess * excess) / (rest_i4 * rest_i4);
  if (grad)
    for (int i = 0; i < 4; ++i) grad->segment<3>(3 * i) = (2.0 * V0 * psi1 * c(i)) * d;
  if (hess) {
    const Eigen::Matrix3d block =
        4.0 * V0 * psi2 * d * d.transpose() + 2.0 * V0 * psi1 * Eigen::Matrix3d::Identity();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) hess->block<3, 3>(3 * i, 3 * j) = (c(i) * c(j)) * block;
  }
  return energy;
}

}  // namespace spinesim::mss
