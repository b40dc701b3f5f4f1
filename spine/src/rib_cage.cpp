// The rib cage (rib_cage.hpp): built from data/spine/rib_cage.json, condensed onto the thoracic
// vertebrae, evaluated corotationally in T6's frame.
#include "spinesim/spine/rib_cage.hpp"

#include "json_fields.hpp"

#include <Eigen/Cholesky>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <stdexcept>

namespace spinesim::spine {
namespace {
using detail::number;
using detail::read_json;
using detail::vec3;
using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using nlohmann::json;

Matrix3d skew(const Vector3d& v) {
  Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Vector3d mirror(Vector3d v) {
  v.x() = -v.x();
  return v;
}

Vector3d point(const json& j, const std::string& what, const std::string& file) {
  if (!j.is_array() || j.size() != 3)
    throw std::runtime_error(file + ": " + what + " is not 3 numbers");
  Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!j[std::size_t(k)].is_number())
      throw std::runtime_error(file + ": " + what + " is not 3 numbers");
    v[k] = j[std::size_t(k)].get<double>();
  }
  if (!v.allFinite()) throw std::runtime_error(file + ": " + what + " is not finite");
  return v;
}

/// Stiffness assembly over bodies with 6 coordinates each: the small motion of body b moves a
/// reference point X by p_b + φ_b × (X − c_b).
class Network {
 public:
  explicit Network(std::vector<Vector3d> centres)
      : c_(std::move(centres)),
        K_(MatrixXd::Zero(6 * Eigen::Index(c_.size()), 6 * Eigen::Index(c_.size()))) {}

  /// A translational spring k (N/mm, isotropic) joining bodies a and b at X.
  void point_spring(int a, int b, const Vector3d& X, double k) {
    Eigen::Matrix<double, 3, 12> B;
    B << -Matrix3d::Identity(), skew(X - c_[std::size_t(a)]), Matrix3d::Identity(),
        -skew(X - c_[std::size_t(b)]);
    add(a, b, k * B.transpose() * B);
  }
  /// A rotational spring k (N·mm/rad, isotropic) between bodies a and b.
  void rotation_spring(int a, int b, double k) {
    Eigen::Matrix<double, 3, 12> B = Eigen::Matrix<double, 3, 12>::Zero();
    B.block<3, 3>(0, 3) = -Matrix3d::Identity();
    B.block<3, 3>(0, 9) = Matrix3d::Identity();
    add(a, b, k * B.transpose() * B);
  }
  const MatrixXd& K() const { return K_; }

 private:
  void add(int a, int b, const Eigen::Matrix<double, 12, 12>& Ke) {
    const Eigen::Index ia = 6 * a, ib = 6 * b;
    K_.block<6, 6>(ia, ia) += Ke.block<6, 6>(0, 0);
    K_.block<6, 6>(ia, ib) += Ke.block<6, 6>(0, 6);
    K_.block<6, 6>(ib, ia) += Ke.block<6, 6>(6, 0);
    K_.block<6, 6>(ib, ib) += Ke.block<6, 6>(6, 6);
  }
  std::vector<Vector3d> c_;
  MatrixXd K_;
};

/// The condensed stiffness and the recovery matrix for the cage's springs with `parts`. Bodies:
/// the 12 vertebrae, then the ribs, then the sternum.
void condense(RibCage& cage, const std::vector<Vertebra>& vertebrae, const RibCageParts& parts) {
  const int nv = int(cage.vertebrae.size()), nr = int(cage.ribs.size());
  std::vector<Vector3d> centres;
  for (int v : cage.vertebrae) centres.push_back(vertebrae[std::size_t(v)].centre_mm);
  for (const Vector3d& c : cage.body_centres_mm) centres.push_back(c);
  Network net(centres);
  const int sternum = nv + nr;
  auto local = [&](int body) {
    for (int i = 0; i < nv; ++i)
      if (cage.vertebrae[std::size_t(i)] == body) return i;
    throw std::logic_error("rib cage: a rib on a vertebra outside T1-T12");
  };
  const double kt = cage.k_costovertebral_n_per_mm * parts.costovertebral_scale,
               kr = cage.k_costovertebral_nmm_per_rad * parts.costovertebral_scale;
  const double kc = parts.cartilage ? cage.k_cartilage_n_per_mm * parts.cartilage_scale : 0.0;
  for (int r = 0; r < nr; ++r) {
    const Rib& rib = cage.ribs[std::size_t(r)];
    const double share = 1.0 / double(rib.vertebrae.size());
    for (int v : rib.vertebrae) {
      net.point_spring(local(v), nv + r, rib.head_mm, share * kt);
      net.rotation_spring(local(v), nv + r, share * kr);
    }
    if (!(kc > 0)) continue;
    if (rib.front == RibFront::Sternum) net.point_spring(nv + r, sternum, rib.cartilage_end_mm, kc);
    if (rib.front == RibFront::RibAbove)  // ribs are ordered R1, L1, R2, L2, …
      net.point_spring(nv + r, nv + r - 2, rib.cartilage_end_mm, kc);
  }
  const MatrixXd& K = net.K();
  const Eigen::Index nu = 6 * nv, nq = K.rows() - nu;
  MatrixXd Kqq = K.bottomRightCorner(nq, nq);
  if (!(kc > 0))  // no cartilage: the sternum hangs on nothing; keep it where it is
    Kqq.bottomRightCorner(6, 6) += MatrixXd::Identity(6, 6);
  const Eigen::LLT<MatrixXd> llt(Kqq);
  if (llt.info() != Eigen::Success)
    throw std::runtime_error("rib cage: the ribs and sternum are not held by their springs");
  cage.recovery = -llt.solve(K.bottomLeftCorner(nq, nu));
  cage.stiffness = K.topLeftCorner(nu, nu) + K.topRightCorner(nu, nq) * cage.recovery;
  cage.stiffness = 0.5 * (cage.stiffness + cage.stiffness.transpose()).eval();
}

/// Each thoracic vertebra's small motion relative to T6, u = (p, φ): the translation of its
/// centre and its rotation vector, in T6's reference frame. `pose_at(i)` is the pose of
/// cage.vertebrae[i] and P0 T6's. No allocation.
template <class PoseAt>
void relative_motion_into(const RibCage& cage, const std::vector<Vertebra>& vertebrae,
                          const Pose& P0, PoseAt pose_at, Eigen::VectorXd& u) {
  for (std::size_t i = 0; i < cage.vertebrae.size(); ++i) {
    const Pose& P = pose_at(i);
    const Vector3d& c = vertebrae[std::size_t(cage.vertebrae[i])].centre_mm;
    u.segment<3>(6 * Eigen::Index(i)) = P0.R.transpose() * (P.apply(c) - P0.t) - c;
    u.segment<3>(6 * Eigen::Index(i) + 3) = rotation_log(P0.R.transpose() * P.R);
  }
}

Eigen::VectorXd relative_motion(const RibCage& cage, const std::vector<Vertebra>& vertebrae,
                                const std::vector<Pose>& poses) {
  Eigen::VectorXd u(6 * Eigen::Index(cage.vertebrae.size()));
  relative_motion_into(
      cage, vertebrae, poses[std::size_t(cage.frame_body)],
      [&](std::size_t i) -> const Pose& { return poses[std::size_t(cage.vertebrae[i])]; }, u);
  return u;
}

/// The ribs' and the sternum's world poses from their motions q relative to T6 (pose P0).
void recovered_poses(const RibCage& cage, const Eigen::VectorXd& q, const Pose& P0, Pose* out) {
  for (std::size_t b = 0; b < cage.body_centres_mm.size(); ++b) {
    const Vector3d& c = cage.body_centres_mm[b];
    const Matrix3d R = rotation_exp(q.segment<3>(6 * Eigen::Index(b) + 3));
    // Relative to T6: X ↦ c + p + R (X − c); then T6's pose.
    const Vector3d t = c + q.segment<3>(6 * Eigen::Index(b)) - R * c;
    out[b].R = P0.R * R;
    out[b].t = P0.R * t + P0.t;
  }
}

}  // namespace

RibCage build_rib_cage(const std::string& data_dir, const std::vector<Vertebra>& vertebrae,
                       double s, const RibCageParts& parts) {
  const std::string file = (std::filesystem::path(data_dir) / "spine" / "rib_cage.json").string();
  const json j = read_json(file);
  RibCage cage;
  try {
    const auto& names = vertebra_names();
    auto index = [&](const std::string& name) {
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == name) return int(i);
      throw std::runtime_error(file + ": unknown vertebra '" + name + "'");
    };
    for (int t = 1; t <= 12; ++t) cage.vertebrae.push_back(index("T" + std::to_string(t)));
    cage.frame_body = index("T6");
    const json& cv = j.at("costovertebral");
    cage.k_costovertebral_n_per_mm = number(cv, "k_translation_n_per_mm", file) * s;
    cage.k_costovertebral_nmm_per_rad = number(cv, "k_rotation_nmm_per_rad", file) * s * s * s;
    const json& cc = j.at("costal_cartilage");
    cage.k_cartilage_n_per_mm = number(cc, "k_translation_n_per_mm", file) * s;
    auto listed = [](const json& list, int n) {
      for (const auto& e : list)
        if (e.get<int>() == n) return true;
      return false;
    };
    cage.sternum_top_mm = s * vec3(j.at("sternum"), "top_mm", file);
    cage.sternum_bottom_mm = s * vec3(j.at("sternum"), "bottom_mm", file);
    const json& rows = j.at("ribs").at("rows");
    if (!rows.is_array() || rows.size() != 12)
      throw std::runtime_error(file + ": ribs.rows must list ribs 1-12");
    for (const auto& row : rows) {
      const int n = row.at(0).get<int>();
      const std::string who = "rib " + std::to_string(n);
      const int own = index(row.at(1).get<std::string>());
      for (int side : {-1, +1}) {
        Rib r;
        r.number = n;
        r.side = side;
        // "rib_L4", not "L4": a rib's name must not be a vertebra's (the scene finds bodies by name).
        r.name = std::string(side < 0 ? "rib_R" : "rib_L") + std::to_string(n);
        auto at = [&](std::size_t col, const char* what) {
          const Vector3d p = s * point(row.at(col), who + " " + what, file);
          return side < 0 ? p : mirror(p);
        };
        r.head_mm = at(2, "head_mm");
        r.tubercle_mm = at(3, "tubercle_mm");
        r.lateral_mm = at(4, "lateral_mm");
        r.front_mm = at(5, "front_mm");
        if (listed(cv.at("shared_by_two_vertebrae"), n)) r.vertebrae.push_back(own - 1);
        r.vertebrae.push_back(own);
        const json& front = cc.at("front");
        if (listed(front.at("sternum"), n)) {
          r.front = RibFront::Sternum;
          const double f = row.at(6).get<double>();
          Vector3d e = cage.sternum_top_mm + f * (cage.sternum_bottom_mm - cage.sternum_top_mm);
          e.x() = side * s * (n == 1 ? 20.0 : 15.0);
          r.cartilage_end_mm = e;
        } else if (listed(front.at("rib_above"), n)) {
          r.front = RibFront::RibAbove;
          r.cartilage_end_mm = cage.ribs[cage.ribs.size() - 2].front_mm;
        } else {
          r.cartilage_end_mm = r.front_mm;
        }
        cage.ribs.push_back(r);
      }
    }
  } catch (const json::exception& e) {
    throw std::runtime_error(file + ": " + e.what());
  }
  for (const Rib& r : cage.ribs) cage.body_centres_mm.push_back(r.head_mm);
  cage.body_centres_mm.push_back(0.5 * (cage.sternum_top_mm + cage.sternum_bottom_mm));
  cage.parts = parts;
  condense(cage, vertebrae, parts);
  return cage;
}

double rib_cage_energy(const RibCage& cage, const std::vector<Vertebra>& vertebrae,
                       const std::vector<Pose>& poses, std::vector<Vector3d>& force,
                       std::vector<Vector3d>& couple) {
  force.assign(poses.size(), Vector3d::Zero());
  couple.assign(poses.size(), Vector3d::Zero());
  const Eigen::VectorXd u = relative_motion(cage, vertebrae, poses);
  const Eigen::VectorXd g = cage.stiffness * u;
  // Π(u) = ½ uᵀ K u with u_i = (R0ᵀ(x_i − t0) − c_i, log(R0ᵀ R_i)); for the world variations
  // δx_i, δw_i of vertebra i and δx0, δw0 of T6 (x0 its centre): δp_i = R0ᵀ(δx_i − δx0 +
  // (x_i − x0) × δw0), δφ_i = J_r⁻¹(φ_i) R_iᵀ (δw_i − δw0). So with a = R0 ∂Π/∂p_i and
  // b = R_i J_r⁻ᵀ ∂Π/∂φ_i, vertebra i feels −a at x_i and the couple −b; T6 feels +a at x_i
  // and the couple +b (the cage's forces on the thorax sum to zero).
  const std::size_t f = std::size_t(cage.frame_body);
  const Pose& P0 = poses[f];
  for (std::size_t i = 0; i < cage.vertebrae.size(); ++i) {
    const std::size_t v = std::size_t(cage.vertebrae[i]);
    if (v == f) continue;
    const Pose& P = poses[v];
    const Vector3d phi = u.segment<3>(6 * Eigen::Index(i) + 3);
    const Vector3d a = P0.R * g.segment<3>(6 * Eigen::Index(i));
    // J_r⁻¹(φ) = J_l⁻¹(−φ).
    const Vector3d b =
        P.R * left_jacobian_inverse(-phi).transpose() * g.segment<3>(6 * Eigen::Index(i) + 3);
    const Vector3d xi = P.apply(vertebrae[v].centre_mm), x0 = P0.apply(vertebrae[f].centre_mm);
    force[v] -= a;
    couple[v] -= b;
    force[f] += a;
    couple[f] += b + (xi - x0).cross(a);
  }
  return 0.5 * u.dot(g);
}

std::vector<Pose> rib_cage_poses(const RibCage& cage, const std::vector<Vertebra>& vertebrae,
                                 const std::vector<Pose>& poses) {
  const Eigen::VectorXd q = cage.recovery * relative_motion(cage, vertebrae, poses);
  std::vector<Pose> out(cage.body_centres_mm.size());
  recovered_poses(cage, q, poses[std::size_t(cage.frame_body)], out.data());
  return out;
}

RibCagePoser::RibCagePoser(const RibCage& cage, const std::vector<Vertebra>& vertebrae)
    : cage_(cage),
      vertebrae_(vertebrae),
      u_(Eigen::VectorXd::Zero(cage.recovery.cols())),
      q_(Eigen::VectorXd::Zero(cage.recovery.rows())) {
  for (std::size_t i = 0; i < cage.vertebrae.size(); ++i)
    if (cage.vertebrae[i] == cage.frame_body) frame_ = i;
}

void RibCagePoser::pose(const Pose* thoracic, Pose* out) {
  relative_motion_into(
      cage_, vertebrae_, thoracic[frame_],
      [thoracic](std::size_t i) -> const Pose& { return thoracic[i]; }, u_);
  q_.noalias() = cage_.recovery * u_;
  recovered_poses(cage_, q_, thoracic[frame_], out);
}

}  // namespace spinesim::spine
