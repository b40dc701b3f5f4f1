// Quasi-static equilibrium of the spine (equilibrium.hpp): total potential energy over the joint
// coordinates, its analytic gradient by accumulating every element's force on the vertebrae
// above each joint, and a modified Newton method with a finite-difference Hessian.
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/spine/rib_cage.hpp"

#include "spinesim/common/timer.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace spinesim::spine {
namespace {
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kThesisForceLimitN = 600.0;  // thesis 3.3.5: the largest force it validated

/// Forces and couples on each vertebra, accumulated as the resultant force and the moment about
/// the origin (so the moment about any joint point c is M0 − c × F).
struct BodyLoads {
  std::vector<Vector3d> force, moment0;
  explicit BodyLoads(std::size_t n) : force(n, Vector3d::Zero()), moment0(n, Vector3d::Zero()) {}
  void add(int body, const Vector3d& x, const Vector3d& f) {
    if (body == kGround) return;
    force[std::size_t(body)] += f;
    moment0[std::size_t(body)] += x.cross(f);
  }
  void couple(int body, const Vector3d& tau) {
    if (body != kGround) moment0[std::size_t(body)] += tau;
  }
};

/// Energy of the range-of-motion bump per unit stiffness, h(s) for s = overshoot ≥ 0, and h'(s):
/// its stiffness h'' ramps linearly from 0 to 1 over the onset width w, so Π stays C² (a bump
/// that switched on at once made Newton bounce across the limit: L2 −x 50 N stalled at
/// 0.014 N·mm after 200 iterations).
double bump_energy(double s, double w, double& ds) {
  if (s <= 0) {
    ds = 0;
    return 0;
  }
  if (s < w) {
    ds = s * s / (2 * w);
    return s * s * s / (6 * w);
  }
  ds = s - 0.5 * w;
  return 0.5 * s * s - 0.5 * w * s + w * w / 6;
}

// Where the stiffness changes — flexion to extension at θ = 0, a ligament going taut — a C¹
// energy makes Newton stall on the kink (two database solves stopped at 0.010–0.012 N·mm after
// 200 iterations). The new stiffness ramps in over a band this narrow instead (so beyond it the
// spring acts as if its zero were w/2 further on: 0.025° or 0.025 mm, below anything measured);
// nothing changes at rest.
constexpr double kFlexExtBlendRad = 0.05 * kRadPerDeg;  // 0.05°
constexpr double kLigamentToeMm = 0.05;

/// ½ max(x, 0)² made C²: its second derivative ramps from 0 at x = 0 to 1 at x = w.
double smooth_half_square(double x, double w, double& dx) { return bump_energy(x, w, dx); }

/// Spring with stiffness k_pos for x > 0 and k_neg for x < 0, and a stiff bump beyond the limits.
double axis_energy(double x, double k_pos, double k_neg, double lim_pos, double lim_neg,
                   double bump, double onset, double& dE) {
  double dq = 0;
  double E = 0.5 * k_neg * x * x + (k_pos - k_neg) * smooth_half_square(x, kFlexExtBlendRad, dq),
         ds = 0;
  dE = k_neg * x + (k_pos - k_neg) * dq;
  if (x > lim_pos) {
    E += bump * k_pos * bump_energy(x - lim_pos, onset, ds);
    dE += bump * k_pos * ds;
  } else if (x < -lim_neg) {
    E += bump * k_neg * bump_energy(-x - lim_neg, onset, ds);
    dE -= bump * k_neg * ds;
  }
  return E;
}

/// Joint spring energy and its gradient in θ (x flexion/extension, y torsion, z lateral bending):
/// the diagonal springs with their range-of-motion bumps, plus a disc's off-diagonal coupling.
double joint_energy(const SpineModel& m, const Joint& j, const Vector3d& th, Vector3d& dE) {
  const double b = m.rom_bump_factor, w = m.rom_bump_onset;
  const double E =
      axis_energy(th.x(), j.k_flexion, j.k_extension, j.rom_flexion, j.rom_extension, b, w,
                  dE.x()) +
      axis_energy(th.y(), j.k_torsion, j.k_torsion, j.rom_torsion, j.rom_torsion, b, w, dE.y()) +
      axis_energy(th.z(), j.k_lateral, j.k_lateral, j.rom_lateral, j.rom_lateral, b, w, dE.z());
  const Vector3d coupled = j.coupling * th;
  dE += coupled;
  return E + 0.5 * th.dot(coupled);
}

Vector3d load_point(const SpineModel& m, const ExternalLoad& l) {
  return l.has_point ? l.point_mm : m.vertebrae[std::size_t(l.vertebra)].centre_mm;
}

/// Everything the energy, the gradient and the report need at one posture.
struct State {
  double energy = 0;
  std::vector<Pose> poses;
  BodyLoads loads;
  VectorXd ligament_t, muscle_t;
  Eigen::Matrix<double, 6, 1> bushing = Eigen::Matrix<double, 6, 1>::Zero();
  std::vector<Vector3d> contact_f, contact_x;
  explicit State(std::size_t n) : loads(n) {}
};

/// The back's contact points: springs on the contact surface, or — when `dead` is given (one force
/// per point) — those forces as dead loads (what the recruitment assumes the chair supplies).
void add_contacts(const SpineModel& m, const std::vector<Vector3d>* dead, State& s) {
  const auto& P = s.poses;
  s.contact_f.assign(m.contacts.size(), Vector3d::Zero());
  s.contact_x.assign(m.contacts.size(), Vector3d::Zero());
  for (std::size_t i = 0; i < m.contacts.size(); ++i) {
    const ContactPoint& c = m.contacts[i];
    const Vector3d x = place(P, c.body, c.point_mm);
    s.contact_x[i] = x;
    if (dead) {
      s.contact_f[i] = (*dead)[i];
      s.energy -= (*dead)[i].dot(x - c.point_mm);
      s.loads.add(c.body, x, (*dead)[i]);
      continue;
    }
    if (!m.contact_surface) continue;
    Vector3d grad;
    const double depth = -m.contact_surface->level(x, grad);
    if (!(depth > 0)) continue;
    double dq = 0;
    s.energy += c.k_n_per_mm * smooth_half_square(depth, kContactToeMm, dq);
    s.contact_f[i] = c.k_n_per_mm * dq * grad;
    s.loads.add(c.body, x, s.contact_f[i]);
  }
}

State evaluate(const SpineModel& m, const std::vector<ExternalLoad>& ext, const VectorXd& F,
               const VectorXd& theta, const std::vector<Vector3d>* dead_contacts = nullptr) {
  const std::size_t n = m.joints.size();
  State s(n);
  s.poses = vertebra_poses(m, theta);
  const auto& P = s.poses;
  for (std::size_t k = 0; k < n; ++k) {
    Vector3d dE;
    s.energy += joint_energy(m, m.joints[k],
                             theta.segment<3>(3 * Eigen::Index(k)) - m.joints[k].rest_rad, dE);
  }
  // Dead loads: Π = −f·(x − X).
  for (const auto& w : m.weights) {
    const Vector3d x = place(P, w.body, w.point_mm);
    s.energy -= w.force_n.dot(x - w.point_mm);
    s.loads.add(w.body, x, w.force_n);
  }
  for (const auto& l : ext) {
    const Vector3d X = load_point(m, l), x = place(P, l.vertebra, X);
    s.energy -= l.force_n.dot(x - X);
    s.loads.add(l.vertebra, x, l.force_n);
    if (!l.moment_nmm.isZero()) {  // Π = −M·φ_b; its torque is J_l^{-T}(φ_b) M
      const Vector3d phi = rotation_log(P[std::size_t(l.vertebra)].R);
      s.energy -= l.moment_nmm.dot(phi);
      s.loads.couple(l.vertebra, left_jacobian_inverse(phi).transpose() * l.moment_nmm);
    }
  }
  // Tension-only ligaments: Π = ½ k (L − L0)₊² (taut over a 0.05 mm toe, see above).
  s.ligament_t = VectorXd::Zero(Eigen::Index(m.ligaments.size()));
  for (std::size_t i = 0; i < m.ligaments.size(); ++i) {
    const Ligament& l = m.ligaments[i];
    const Vector3d xa = place(P, l.body_a, l.a_mm), xb = place(P, l.body_b, l.b_mm);
    const double L = (xa - xb).norm(), stretch = L - l.rest_length_mm;
    if (stretch <= 0) continue;
    double dq = 0;
    s.energy += l.k_n_per_mm * smooth_half_square(stretch, kLigamentToeMm, dq);
    const double T = l.k_n_per_mm * dq;
    const Vector3d u = (xa - xb) / L;
    s.loads.add(l.body_a, xa, -T * u);
    s.loads.add(l.body_b, xb, T * u);
    s.ligament_t[Eigen::Index(i)] = T;
  }
  // Muscles: T = F (1 + q (L − L0)/L0), tension only; Π = F s + ½ (qF/L0) s², s = L − L0.
  s.muscle_t = VectorXd::Zero(Eigen::Index(m.muscles.size()));
  if (F.size() == Eigen::Index(m.muscles.size())) {
    for (std::size_t i = 0; i < m.muscles.size(); ++i) {
      const double f = F[Eigen::Index(i)];
      if (!(f > 0)) continue;
      const Muscle& mu = m.muscles[i];
      const Vector3d xa = place(P, mu.body_a, mu.a_mm), xb = place(P, mu.body_b, mu.b_mm);
      const double L = (xa - xb).norm(), L0 = mu.rest_length_mm, s_mm = L - L0;
      const double k = m.muscle_q * f / L0;
      if (s_mm <= -L0 / m.muscle_q) {
        s.energy -= f * L0 / (2 * m.muscle_q);
        continue;
      }
      const double T = f + k * s_mm;
      s.energy += f * s_mm + 0.5 * k * s_mm * s_mm;
      const Vector3d u = (xa - xb) / L;
      s.loads.add(mu.body_a, xa, -T * u);
      s.loads.add(mu.body_b, xb, T * u);
      s.muscle_t[Eigen::Index(i)] = T;
    }
  }
  // IAP bushing (ribs to pelvis): ½ dᵀ K_t d + ½ φᵀ K_r φ from its rest pose, world axes.
  if (m.has_bushing) {
    const Bushing& b = m.bushing;
    const Pose& pose = P[std::size_t(b.body)];
    const Vector3d x = pose.apply(b.point_mm);
    const Vector3d d = x - (b.rest_rotation * b.point_mm + b.rest_translation_mm);
    const Vector3d f = -b.k_translation_n_per_mm.cwiseProduct(d);
    // Rotation from the rest pose: R R_restᵀ = exp(φ), so δφ is the world spin as before.
    const Vector3d phi = rotation_log(pose.R * b.rest_rotation.transpose());
    const Vector3d Kphi = b.k_rotation_nmm_per_rad.cwiseProduct(phi);
    s.energy += 0.5 * d.dot(-f) + 0.5 * phi.dot(Kphi);
    s.loads.add(b.body, x, f);
    const Vector3d tau = -left_jacobian_inverse(phi).transpose() * Kphi;
    s.loads.couple(b.body, tau);
    s.bushing << f, tau;
  }
  if (m.rib_cage) {
    std::vector<Vector3d> force, couple;
    s.energy += rib_cage_energy(*m.rib_cage, m.vertebrae, P, force, couple);
    for (std::size_t v = 0; v < n; ++v) {
      if (force[v].isZero() && couple[v].isZero()) continue;
      s.loads.add(int(v), P[v].apply(m.vertebrae[v].centre_mm), force[v]);
      s.loads.couple(int(v), couple[v]);
    }
  }
  add_contacts(m, dead_contacts, s);
  return s;
}

/// World position of joint k's point (it moves with the vertebra below).
Vector3d joint_point(const SpineModel& m, const std::vector<Pose>& P, std::size_t k) {
  const Vector3d& J = m.joints[k].point_mm;
  return k + 1 < P.size() ? P[k + 1].apply(J) : J;
}

/// For every joint: the resultant force on, and moment about the joint of, everything above it.
void resultants_above(const SpineModel& m, const State& s, std::vector<Vector3d>& force,
                      std::vector<Vector3d>& moment) {
  const std::size_t n = m.joints.size();
  force.assign(n, Vector3d::Zero());
  moment.assign(n, Vector3d::Zero());
  Vector3d F = Vector3d::Zero(), M0 = Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    F += s.loads.force[k];
    M0 += s.loads.moment0[k];
    force[k] = F;
    moment[k] = M0 - joint_point(m, s.poses, k).cross(F);
  }
}

VectorXd gradient_of(const SpineModel& m, const State& s, const VectorXd& theta) {
  std::vector<Vector3d> F, M;
  resultants_above(m, s, F, M);
  VectorXd g(theta.size());
  for (std::size_t k = 0; k < m.joints.size(); ++k) {
    const Eigen::Index o = 3 * Eigen::Index(k);
    if (m.joints[k].fused) {
      g.segment<3>(o).setZero();
      continue;
    }
    const Vector3d th = theta.segment<3>(o);
    Vector3d dE;
    joint_energy(m, m.joints[k], th - m.joints[k].rest_rad, dE);
    // δx = (R_k J_r δθ) × (x − c_k) for every point above joint k.
    g.segment<3>(o) = dE - right_jacobian(th).transpose() * s.poses[k].R.transpose() * M[k];
  }
  return g;
}

void check_loads(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                 std::vector<std::string>* warnings) {
  for (const auto& l : loads) {
    if (l.vertebra < 0 || l.vertebra >= int(m.vertebrae.size()))
      throw std::invalid_argument("external load on vertebra index " + std::to_string(l.vertebra) +
                                  " (valid: 0.." + std::to_string(m.vertebrae.size() - 1) +
                                  ", T1..L5)");
    if (!l.force_n.allFinite() || !l.moment_nmm.allFinite() ||
        (l.has_point && !l.point_mm.allFinite()))
      throw std::invalid_argument("external load on " + m.vertebrae[std::size_t(l.vertebra)].name +
                                  " is not finite");
    // Beyond these no body is loaded, and the solvers would run on numbers they cannot resolve
    // (a 1e155 N force overflows its norm): refused, naming the limit.
    const std::string& name = m.vertebrae[std::size_t(l.vertebra)].name;
    if (!(l.force_n.norm() <= kMaxForceN))
      throw std::invalid_argument(
          "force on " + name + " is beyond " + std::to_string(int(kMaxForceN)) +
          " N, outside any physical load (the model is validated to 600 N)");
    if (!(l.moment_nmm.norm() <= kMaxMomentNmm))
      throw std::invalid_argument("couple on " + name + " is beyond " +
                                  std::to_string(int(kMaxMomentNmm / 1000)) + " N·m");
    if (l.has_point && !(l.point_mm.norm() <= kMaxPointMm))
      throw std::invalid_argument("load point on " + name + " is more than " +
                                  std::to_string(int(kMaxPointMm)) + " mm from the origin");
    if (warnings && l.force_n.norm() > kThesisForceLimitN) {
      std::ostringstream w;
      w << "force of " << l.force_n.norm() << " N on " << m.vertebrae[std::size_t(l.vertebra)].name
        << " exceeds the 600 N the thesis validated (3.3.5)";
      warnings->push_back(w.str());
    }
  }
}

const char* const kAxisNames[] = {"flexion/extension", "torsion", "lateral bending"};

/// The potential over the free (non-fused) joint coordinates for fixed muscle forces: energy,
/// gradient, finite-difference tangent stiffness, and the modified Newton method on them.
class Newton {
 public:
  /// `sagittal_only`: flexion/extension coordinates only (a symmetric model under sagittal loads).
  Newton(const SpineModel& m, const std::vector<ExternalLoad>& loads, const VectorXd& F,
         const SolveOptions& o, bool sagittal_only)
      : m_(m), loads_(loads), F_(F), o_(o) {
    for (std::size_t k = 0; k < m.joints.size(); ++k)
      if (!m.joints[k].fused)
        for (int a = 0; a < (sagittal_only ? 1 : 3); ++a) free_.push_back(3 * Eigen::Index(k) + a);
  }

  double energy_grad(const VectorXd& th, VectorXd& g) const {
    const State s = evaluate(m_, loads_, F_, th);
    g = gradient_of(m_, s, th);
    return s.energy;
  }

  /// Central differences of the analytic gradient over the free coordinates, symmetrised.
  Eigen::MatrixXd hessian(const VectorXd& th) const {
    const Eigen::Index nf = size();
    Eigen::MatrixXd H(nf, nf);
    VectorXd gp, gm;
    for (Eigen::Index c = 0; c < nf; ++c) {
      VectorXd tp = th, tm = th;
      tp[free_[std::size_t(c)]] += o_.fd_step;
      tm[free_[std::size_t(c)]] -= o_.fd_step;
      energy_grad(tp, gp);
      energy_grad(tm, gm);
      for (Eigen::Index r = 0; r < nf; ++r)
        H(r, c) = (gp[free_[std::size_t(r)]] - gm[free_[std::size_t(r)]]) / (2 * o_.fd_step);
    }
    return Eigen::MatrixXd(0.5 * (H + H.transpose()));
  }

  /// Minimises Π from `start`; throws SolveError when the gradient does not reach the tolerance.
  VectorXd solve(const VectorXd& start, int& iterations, double& gradient_norm) const {
    VectorXd theta = start, g;
    double E = energy_grad(theta, g);
    const double tolerance = std::max(o_.tolerance, o_.relative_tolerance * worst(g));
    int it = 0;
    for (; it < o_.max_iterations && worst(g) > tolerance; ++it)
      if (!step(theta, g, E)) break;
    iterations = it;
    gradient_norm = worst(g);
    if (!(gradient_norm <= tolerance)) {
      Eigen::Index at = 0;
      g.cwiseAbs().maxCoeff(&at);
      std::ostringstream msg;
      msg << "spine equilibrium did not converge: " << it
          << " Newton iterations, max |dPi/dtheta| = " << gradient_norm << " N*mm (tolerance "
          << tolerance << ") at joint " << m_.joints[std::size_t(at / 3)].name << " ("
          << kAxisNames[at % 3] << ")";
      throw SolveError(msg.str());
    }
    return theta;
  }

  Eigen::Index size() const { return Eigen::Index(free_.size()); }
  Eigen::Index coordinate(Eigen::Index free_index) const { return free_[std::size_t(free_index)]; }

 private:
  static double worst(const VectorXd& g) { return g.cwiseAbs().maxCoeff(); }

  /// One modified-Newton step with line search; false when no step is accepted.
  bool step(VectorXd& theta, VectorXd& g, double& E) const {
    const Eigen::Index nf = size();
    const Eigen::MatrixXd H = hessian(theta);
    VectorXd gf(nf);
    for (Eigen::Index r = 0; r < nf; ++r) gf[r] = g[coordinate(r)];
    // Shift the Hessian until it is positive definite, so the step descends.
    double shift = 0;
    const double scale = std::max(1.0, H.diagonal().cwiseAbs().maxCoeff());
    Eigen::LLT<Eigen::MatrixXd> llt;
    for (int tries = 0; tries < 30; ++tries) {
      llt.compute(H + shift * Eigen::MatrixXd::Identity(nf, nf));
      if (llt.info() == Eigen::Success) break;
      shift = shift == 0 ? 1e-8 * scale : 10 * shift;
    }
    if (llt.info() != Eigen::Success) return false;
    const VectorXd dir = -llt.solve(gf);
    const double slope = gf.dot(dir);
    auto step_to = [&](double alpha, VectorXd& th) {
      th = theta;
      for (Eigen::Index r = 0; r < nf; ++r) th[coordinate(r)] += alpha * dir[r];
    };
    // Near the solution the energy change of a Newton step, ~g²/H, drops below Π's round-off
    // (stiff ROM bumps, H ~ 1e7 N·mm/rad: |g| = 0.01 N·mm is a 1e-11 N·mm change of a Π of 1e4):
    // then the Armijo test cannot tell, and the full step is taken when it lowers |g|.
    const double roundoff = 1e-12 * std::max(1.0, std::abs(E));
    VectorXd trial, gt;
    step_to(1.0, trial);
    double Et = energy_grad(trial, gt);
    bool accepted = Et <= E + 1e-4 * slope || (-slope < 100 * roundoff && worst(gt) < worst(g));
    for (double alpha = 0.5; !accepted && alpha > 1e-12; alpha *= 0.5) {
      step_to(alpha, trial);
      Et = energy_grad(trial, gt);
      accepted = Et <= E + 1e-4 * alpha * slope;
    }
    if (!accepted) return false;
    theta = trial;
    g = gt;
    E = Et;
    return true;
  }

  const SpineModel& m_;
  const std::vector<ExternalLoad>& loads_;
  const VectorXd& F_;
  const SolveOptions& o_;
  std::vector<Eigen::Index> free_;
};

/// Loads in the sagittal plane x = 0: forces without x component at x = 0, moments about x only.
bool sagittal(const std::vector<ExternalLoad>& loads) {
  for (const auto& l : loads)
    if (l.force_n.x() != 0 || l.moment_nmm.y() != 0 || l.moment_nmm.z() != 0 ||
        (l.has_point && l.point_mm.x() != 0))
      return false;
  return true;
}

/// Only flexion/extension coordinates are non-zero.
bool sagittal_posture(const VectorXd& theta) {
  for (Eigen::Index k = 0; k < theta.size(); ++k)
    if (k % 3 != 0 && theta[k] != 0) return false;
  return true;
}

/// A point and its mirror image x → −x are the same to round-off.
bool mirrored(const Vector3d& a, const Vector3d& b) {
  return std::abs(a.x() + b.x()) < 1e-9 && std::abs(a.y() - b.y()) < 1e-9 &&
         std::abs(a.z() - b.z()) < 1e-9;
}

/// Is the model its own mirror image in x → −x? (Joints, vertebrae and the bushing lie in x = 0
/// with diagonal stiffness; every line element and weight needs a mirrored twin.)
bool mirror_symmetric(const SpineModel& m) {
  for (const auto& v : m.vertebrae)
    if (v.centre_mm.x() != 0) return false;
  // A mirror-symmetric joint spring keeps flexion apart from torsion and lateral bending (θ_x is
  // even under x -> -x, θ_y and θ_z odd).
  for (const auto& j : m.joints)
    if (j.point_mm.x() != 0 || j.coupling(0, 1) != 0 || j.coupling(0, 2) != 0) return false;
  if (m.has_bushing && m.bushing.point_mm.x() != 0) return false;
  if (!m.contacts.empty() && m.contact_surface && !m.contact_surface->mirror_symmetric())
    return false;
  auto has_twin = [](const auto& items, const auto& same) {
    for (const auto& a : items) {
      bool found = false;
      for (const auto& b : items) found = found || same(a, b);
      if (!found) return false;
    }
    return true;
  };
  auto line_twin = [](const Line& a, const Line& b) {
    return a.body_a == b.body_a && a.body_b == b.body_b && mirrored(a.a_mm, b.a_mm) &&
           mirrored(a.b_mm, b.b_mm);
  };
  return has_twin(m.muscles,
                  [&](const Muscle& a, const Muscle& b) {
                    return line_twin(a, b) && a.pcsa_mm2 == b.pcsa_mm2 &&
                           a.max_stress_mpa == b.max_stress_mpa;
                  }) &&
         has_twin(m.ligaments,
                  [&](const Ligament& a, const Ligament& b) {
                    return line_twin(a, b) && a.k_n_per_mm == b.k_n_per_mm;
                  }) &&
         has_twin(m.weights,
                  [](const PointLoad& a, const PointLoad& b) {
                    return a.body == b.body && mirrored(a.point_mm, b.point_mm) &&
                           a.force_n.x() == -b.force_n.x() && a.force_n.y() == b.force_n.y() &&
                           a.force_n.z() == b.force_n.z();
                  }) &&
         has_twin(m.contacts, [](const ContactPoint& a, const ContactPoint& b) {
           return a.body == b.body && mirrored(a.point_mm, b.point_mm) &&
                  a.k_n_per_mm == b.k_n_per_mm;
         });
}

/// Stability at the solution: the smallest eigenvalue of the tangent stiffness over all free
/// coordinates and its mode. Not stable: a warning (a sagittal solve there is the symmetric
/// equilibrium the spine would buckle away from; static-optimisation muscles do not co-contract).
void assess_stability(const SpineModel& m, const Newton& full, const VectorXd& theta,
                      SpineSolution& out) {
  if (full.size() == 0) return;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(full.hessian(theta));
  out.min_stiffness_nmm_per_rad = eig.eigenvalues()[0];
  Eigen::Index at = 0;
  eig.eigenvectors().col(0).cwiseAbs().maxCoeff(&at);
  const Eigen::Index dof = full.coordinate(at);
  out.softest_mode = m.joints[std::size_t(dof / 3)].name + " " + kAxisNames[dof % 3];
  if (!(out.min_stiffness_nmm_per_rad > 0))
    out.warnings.push_back(
        "the equilibrium is not stable: smallest tangent stiffness " +
        std::to_string(out.min_stiffness_nmm_per_rad) + " N*mm/rad, mostly " + out.softest_mode +
        (out.sagittal_solve ? " (the spine would buckle out of the sagittal plane)" : ""));
}

/// Poses, displacements, joint reactions and element forces at the solution.
void report(const SpineModel& m, const State& s, SpineSolution& out) {
  out.poses = s.poses;
  const std::size_t n = m.vertebrae.size();
  out.displacement.resize(Eigen::Index(n), 6);
  for (std::size_t i = 0; i < n; ++i) {
    const Vector3d& C = m.vertebrae[i].centre_mm;
    out.displacement.row(Eigen::Index(i)).head<3>() = (s.poses[i].apply(C) - C).transpose();
    out.displacement.row(Eigen::Index(i)).tail<3>() =
        (rotation_log(s.poses[i].R) * kDegPerRad).transpose();
  }
  std::vector<Vector3d> Fa, Ma;
  resultants_above(m, s, Fa, Ma);
  for (std::size_t k = 0; k < m.joints.size(); ++k) {
    JointReaction r;
    r.joint = m.joints[k].name;
    r.force_world_n = -Fa[k];  // what the lower side pushes on everything above
    r.moment_world_nmm = Ma[k];
    const Eigen::Matrix3d R_low = k + 1 < n ? s.poses[k + 1].R : Eigen::Matrix3d::Identity();
    const Vector3d local = R_low.transpose() * r.force_world_n;
    r.shear_lat_n = local.x();
    r.axial_n = local.y();
    r.shear_ap_n = local.z();
    r.moment_local_nmm = R_low.transpose() * r.moment_world_nmm;
    // Disc frame: from the lower vertebra's centre (the sacrum: L5's mirrored) to the upper one's.
    const Vector3d& J = m.joints[k].point_mm;
    const Vector3d up = s.poses[k].apply(m.vertebrae[k].centre_mm);
    const Vector3d low = k + 1 < n ? s.poses[k + 1].apply(m.vertebrae[k + 1].centre_mm)
                                   : Vector3d(2 * J - m.vertebrae[k].centre_mm);
    const Vector3d axis = (up - low).normalized();
    r.disc_axial_n = r.force_world_n.dot(axis);
    r.disc_shear_n = (r.force_world_n - r.disc_axial_n * axis).norm();
    out.joints.push_back(r);
  }
  out.ligament_force_n = s.ligament_t;
  out.muscle_force_n = s.muscle_t;
  out.bushing_wrench = s.bushing;
  out.contact_force_n = s.contact_f;
  out.contact_point_mm = s.contact_x;
}

}  // namespace

SpineSolution spine_state(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                          const VectorXd& muscle_force_n, const VectorXd& theta) {
  check_loads(m, loads, nullptr);
  if (theta.size() != dof_count(m) || !theta.allFinite())
    throw std::invalid_argument("spine_state: the posture needs " + std::to_string(dof_count(m)) +
                                " finite joint coordinates");
  SpineSolution out;
  out.theta = theta;
  report(m, evaluate(m, loads, muscle_force_n, theta), out);
  return out;
}

double potential(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                 const VectorXd& muscle_force_n, const VectorXd& theta, VectorXd* gradient) {
  check_loads(m, loads, nullptr);
  const State s = evaluate(m, loads, muscle_force_n, theta);
  if (gradient) *gradient = gradient_of(m, s, theta);
  return s.energy;
}

void recruitment_problem(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                         Eigen::MatrixXd& arm, VectorXd& load_moment_nmm, std::vector<int>& joints,
                         const VectorXd& posture, const std::vector<Vector3d>* contact_forces) {
  check_loads(m, loads, nullptr);
  const VectorXd theta = posture.size() ? posture : VectorXd::Zero(dof_count(m));
  if (theta.size() != dof_count(m) || !theta.allFinite())
    throw std::invalid_argument("recruitment posture: " + std::to_string(dof_count(m)) +
                                " finite joint coordinates expected");
  if (contact_forces && contact_forces->size() != m.contacts.size())
    throw std::invalid_argument("recruitment contact forces: one per contact point expected");
  if (contact_forces)
    for (const Vector3d& f : *contact_forces)
      if (!(f.norm() <= kMaxForceN))
        throw std::invalid_argument("recruitment contact forces: finite and below 100 kN expected");
  joints.clear();
  for (int j : m.recruited_joints)
    if (!m.joints[std::size_t(j)].fused) joints.push_back(j);
  // What the muscles and the joints' shares must balance: ∂Π/∂θ of everything but the muscles
  // (in the reference posture, joints, ligaments and bushing are unloaded and this is minus the
  // moment of gravity and the external loads about each joint).
  const State s = evaluate(m, loads, VectorXd(), theta, contact_forces);
  const VectorXd g = gradient_of(m, s, theta);
  const Eigen::Index nm = Eigen::Index(m.muscles.size());
  arm = Eigen::MatrixXd::Zero(3 * Eigen::Index(joints.size()), nm);
  load_moment_nmm.resize(3 * Eigen::Index(joints.size()));
  for (std::size_t r = 0; r < joints.size(); ++r)
    load_moment_nmm.segment<3>(3 * Eigen::Index(r)) = g.segment<3>(3 * joints[r]);
  // A unit tension's generalised force, J_rᵀ R_kᵀ (moment about the moved joint point of its pull
  // on the part above): the same map gradient_of() applies.
  const auto& P = s.poses;
  for (Eigen::Index i = 0; i < nm; ++i) {
    const Muscle& mu = m.muscles[std::size_t(i)];
    const Vector3d xa = place(P, mu.body_a, mu.a_mm), xb = place(P, mu.body_b, mu.b_mm);
    const Vector3d u = (xa - xb).normalized();  // a unit tension pulls a towards b
    for (std::size_t r = 0; r < joints.size(); ++r) {
      const std::size_t j = std::size_t(joints[r]);
      auto above = [j](int body) { return body != kGround && std::size_t(body) <= j; };
      if (above(mu.body_a) == above(mu.body_b)) continue;  // does not cross joint j
      const Vector3d c = joint_point(m, P, j);
      const Vector3d M =
          above(mu.body_a) ? Vector3d((xa - c).cross(-u)) : Vector3d((xb - c).cross(u));
      const Vector3d th = theta.segment<3>(3 * Eigen::Index(j));
      arm.block<3, 1>(3 * Eigen::Index(r), i) =
          right_jacobian(th).transpose() * P[j].R.transpose() * M;
    }
  }
}

SpineSolution solve_spine(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                          const SolveOptions& o) {
  SpineSolution out;
  check_loads(m, loads, o.warn_above_600n ? &out.warnings : nullptr);
  if (!(o.tolerance > 0) || o.max_iterations < 1 || !(o.fd_step > 0))
    throw std::invalid_argument(
        "solve_spine: tolerance and finite-difference step must be > 0, iterations >= 1");
  if (o.posture.size() && (o.posture.size() != dof_count(m) || !o.posture.allFinite()))
    throw std::invalid_argument("solve_spine: the posture needs " + std::to_string(dof_count(m)) +
                                " finite joint coordinates");
  // Without a posture asked for, the model's own rest posture (a scoliotic curve) or θ = 0.
  const VectorXd& posture = o.posture.size() ? o.posture : m.rest_posture;
  Timer timer;

  VectorXd F;  // recruited muscle forces (empty: muscles off)
  if (o.recruit && !m.muscles.empty()) {
    Eigen::MatrixXd arm;
    VectorXd b;
    std::vector<int> joints;
    recruitment_problem(
        m, loads, arm, b, joints, posture,
        o.recruitment_contact_forces.empty() ? nullptr : &o.recruitment_contact_forces);
    out.recruitment = recruit(m, arm, b, o.recruitment);
    if (!out.recruitment.success)
      throw SolveError("muscle recruitment failed (Ipopt: " + out.recruitment.status + ")");
    F = out.recruitment.force_n;
  }
  out.seconds_recruitment = timer.restart();

  // A symmetric model under sagittal loads has a symmetric equilibrium: solve for it in the
  // sagittal plane (deterministic; where it is unstable, which way the spine would buckle is
  // decided by round-off otherwise) and judge its stability over all coordinates.
  // Recruited in another posture, the muscles' short-range springs rest there.
  const SpineModel* model = &m;
  SpineModel posed;
  VectorXd start = VectorXd::Zero(dof_count(m));
  if (posture.size()) {
    start = posture;
    posed = m;
    const std::vector<Pose> P = vertebra_poses(m, posture);
    for (Muscle& mu : posed.muscles)
      mu.rest_length_mm = (place(P, mu.body_a, mu.a_mm) - place(P, mu.body_b, mu.b_mm)).norm();
    model = &posed;
  }
  out.sagittal_solve = sagittal(loads) && mirror_symmetric(m) && sagittal_posture(start);
  const Newton newton(*model, loads, F, o, out.sagittal_solve), full(*model, loads, F, o, false);
  out.theta = newton.solve(start, out.iterations, out.gradient_norm);
  out.converged = true;
  assess_stability(*model, full, out.theta, out);
  out.seconds_equilibrium = timer.seconds();
  report(*model, evaluate(*model, loads, F, out.theta), out);
  return out;
}

DisplacementSensitivity displacement_sensitivity(const SpineModel& m,
                                                 const std::vector<ExternalLoad>& loads,
                                                 const SpineSolution& solution, int load,
                                                 const SolveOptions& o, double step_n,
                                                 SensitivityMethod method) {
  if (load < 0 || load >= int(loads.size()))
    throw std::invalid_argument("displacement_sensitivity: load index out of range");
  if (!(step_n > 0)) throw std::invalid_argument("displacement_sensitivity: step must be > 0");
  check_loads(m, loads, nullptr);
  const Eigen::Index rows = 6 * Eigen::Index(m.vertebrae.size());
  auto column = [&](const SpineSolution& s) {
    VectorXd d(rows);
    for (Eigen::Index i = 0; i < s.displacement.rows(); ++i)
      d.segment<6>(6 * i) = s.displacement.row(i).transpose();
    return d;
  };
  if (o.recruit && !m.muscles.empty() && method == SensitivityMethod::automatic) {
    DisplacementSensitivity S(rows, 3);
    const VectorXd d0 = column(solution);
    for (int a = 0; a < 3; ++a) {
      std::vector<ExternalLoad> shifted = loads;
      shifted[std::size_t(load)].force_n[a] += step_n;
      S.col(a) = (column(solve_spine(m, shifted, o)) - d0) / step_n;
    }
    return S;
  }
  const VectorXd& F = solution.recruitment.force_n;
  const Newton full(m, loads, F, o, false);
  const Eigen::Index nf = full.size();
  DisplacementSensitivity S = DisplacementSensitivity::Zero(rows, 3);
  if (nf == 0) return S;
  const VectorXd& theta = solution.theta;
  // ∂g/∂F_a: the gradient is affine in a dead force, so a difference of two gradients is exact
  // up to round-off (step 1 N).
  VectorXd g0, g1;
  potential(m, loads, F, theta, &g0);
  Eigen::MatrixXd dg(nf, 3);
  for (int a = 0; a < 3; ++a) {
    std::vector<ExternalLoad> shifted = loads;
    shifted[std::size_t(load)].force_n[a] += 1.0;
    potential(m, shifted, F, theta, &g1);
    for (Eigen::Index r = 0; r < nf; ++r)
      dg(r, a) = g1[full.coordinate(r)] - g0[full.coordinate(r)];
  }
  const Eigen::MatrixXd K = full.hessian(theta);
  Eigen::LDLT<Eigen::MatrixXd> ldlt(K);
  const Eigen::MatrixXd dtheta = -ldlt.solve(dg);  // nf × 3, rad/N
  // displacement(θ) along each direction by central differences (h: 1e-6 rad at the largest
  // component, well inside the finite-rotation maps' smooth range).
  auto displacement_at = [&](const VectorXd& th, Eigen::VectorXd& d) {
    const std::vector<Pose> P = vertebra_poses(m, th);
    d.resize(rows);
    for (std::size_t i = 0; i < m.vertebrae.size(); ++i) {
      const Vector3d& C = m.vertebrae[i].centre_mm;
      d.segment<3>(6 * Eigen::Index(i)) = P[i].apply(C) - C;
      d.segment<3>(6 * Eigen::Index(i) + 3) = rotation_log(P[i].R) * kDegPerRad;
    }
  };
  for (int a = 0; a < 3; ++a) {
    const double scale = dtheta.col(a).cwiseAbs().maxCoeff();
    if (!(scale > 0)) continue;
    const double h = 1e-6 / scale;
    VectorXd tp = theta, tm = theta, dp, dm;
    for (Eigen::Index r = 0; r < nf; ++r) {
      tp[full.coordinate(r)] += h * dtheta(r, a);
      tm[full.coordinate(r)] -= h * dtheta(r, a);
    }
    displacement_at(tp, dp);
    displacement_at(tm, dm);
    S.col(a) = (dp - dm) / (2 * h);
  }
  return S;
}

}  // namespace spinesim::spine
