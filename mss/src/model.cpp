// MssModel: builder (mesh + material -> springs, masses) and the energy/gradient/Hessian loops.
// Formulas and constants: model.hpp; element kernels: elements.cpp.
#include "spinesim/mss/model.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/common/skew.hpp"
#include "spinesim/mesh/fibre_field.hpp"

#include "face_angles.hpp"
#include "hessian_pattern.hpp"
#include "tet_terms.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::mss {
namespace {

/// Region label -> index into the per-region stiffness parts (0 annulus, 1 nucleus).
int region_index(int region_label) {
  return region_label == static_cast<int>(mesh::Region::nucleus) ? 1 : 0;
}

struct EdgeSpring {
  int i, j;
  double rest_mm;
  double k_part[2];  ///< annulus / nucleus parts of k, N/mm (unscaled)
  double mu;         ///< per-spring multiplier (MssOptions::edge_multipliers)
  double k;          ///< scaled total mu (s_a k_part[0] + s_n k_part[1]), N/mm
};

/// The three angle springs of one face (one per corner), which share one k_t.
struct AngleFace {
  int v[3];
  double rest_rad[3];  ///< rest angle at each corner
  FaceRest rest;       ///< its cos and sin
  double k_part[2];    ///< N·mm/rad (unscaled)
  double k;            ///< scaled total
};

/// One embedded fibre spring (elements.hpp fibre_spring).
struct FibreSpring {
  int t;
  Eigen::Vector4d c;  ///< fibre_coefficients, 1/mm
  double V0;          ///< rest volume of its tet, mm^3
  double k1;          ///< MPa (unscaled)
  double k2;          ///< toe exponent
  double rest_i4;     ///< |X c|^2 at the rest points as rounded (elements.hpp)
  double k;           ///< scaled k1
  double rest_det;    ///< det of its rest tet's arms (isochoric fibres)
};

/// Per-tetrahedron terms (radial springs and volume penalty share the vertex set).
struct TetTerm {
  int t;
  int region;         ///< 0 annulus, 1 nucleus
  double rest;        ///< S0 (mm) for radial springs, V0 (mm^3) for the volume term
  double k_unscaled;  ///< k_s N/mm or k_v N/mm^5
  double k;           ///< scaled
};

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

/// The per-spring multipliers: none, or one finite positive value per edge spring.
void validate_edge_multipliers(const std::vector<double>& mu, std::size_t num_edges) {
  require(mu.empty() || mu.size() == num_edges,
          "mss: " + std::to_string(mu.size()) + " edge multipliers for " +
              std::to_string(num_edges) +
              " edge springs (per-spring multipliers belong to the mesh they were made for)");
  for (double v : mu)
    require(std::isfinite(v) && v > 0.0, "mss: edge multipliers must be finite and > 0");
}

void validate_options(const MssOptions& o) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  require(positive(o.radial_factor), "mss: radial_factor must be finite and > 0");
  require(positive(o.volume_factor), "mss: volume_factor must be finite and > 0");
  require(positive(o.disc_volume_factor), "mss: disc_volume_factor must be finite and > 0");
  require(std::isfinite(o.damping_ratio) && o.damping_ratio >= 0.0,
          "mss: damping ratio must be finite and >= 0");
  require(std::isfinite(o.damping_n_s_per_mm), "mss: damping K_d must be finite");
  for (const auto& s : o.scales)
    for (double v : s.by_region)
      require(positive(v), "mss: stiffness scales must be finite and > 0");
}

TetPoints tet_points(const Eigen::VectorXd& x, const Eigen::MatrixX4i& T, int t) {
  TetPoints p;
  for (int c = 0; c < 4; ++c) p.col(c) = x.segment<3>(3 * T(t, c));
  return p;
}

void check_size(const Eigen::VectorXd& x, Eigen::Index n) {
  if (x.size() != 3 * n)
    throw std::invalid_argument("mss: position vector has " + std::to_string(x.size()) +
                                " entries, expected 3 x " + std::to_string(n));
}

/// Stiffness selector: the scaled total, or one region's unscaled part (dE/d scale; an edge
/// spring's part keeps its multiplier).
struct KSelect {
  int region = -1;  ///< -1: scaled total
  double edge(const EdgeSpring& e) const { return region < 0 ? e.k : e.mu * e.k_part[region]; }
  double angle(const AngleFace& a) const { return region < 0 ? a.k : a.k_part[region]; }
  double tet(const TetTerm& t) const {
    return region < 0 ? t.k : (t.region == region ? t.k_unscaled : 0.0);
  }
  double fibre(const FibreSpring& f) const { return region < 0 ? f.k : (region == 0 ? f.k1 : 0.0); }
  double disc(double k_scaled, double k_unscaled) const {
    return region < 0 ? k_scaled : (region == 0 ? k_unscaled : 0.0);
  }
};

/// Σ of the isochoric fibre elements' energies (elements.hpp isochoric_fibre) and their forces
/// added to g: the same formulas, per run of fibres on one tet (the families of a tet follow each
/// other), so J, ∇J and J^(−1/3) are made once per tet and the ∇J part is scattered once. The
/// per-element call was 60 % of a palpated fibre disc's step. A slack fibre (Ī4 <= 1, tested as
/// I4³ <= J²) costs its I4 only. An inverted tet gives NaN energy and no force, as the element.
double isochoric_fibres_gradient(const std::vector<FibreSpring>& fibres, const Eigen::MatrixX4i& T,
                                 const double* x, KSelect sel, double* g) {
  double energy = 0.0;
  for (std::size_t first = 0; first < fibres.size();) {
    const int t = fibres[first].t;
    std::size_t end = first + 1;
    while (end < fibres.size() && fibres[end].t == t) ++end;
    const int v[4] = {T(t, 0), T(t, 1), T(t, 2), T(t, 3)};
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = Eigen::Map<const Eigen::Vector3d>(x + 3 * v[k]);
    const Eigen::Vector3d a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
    const Eigen::Vector3d ga = b.cross(c), gb = c.cross(a), gc = a.cross(b);
    // The families of a tet share its rest determinant, hence J.
    const double rest_det = fibres[first].rest_det, J = a.dot(ga) / rest_det;
    if (!(J > 0.0)) {
      energy += std::numeric_limits<double>::quiet_NaN();
      first = end;
      continue;
    }
    double j23 = 0.0, det_coefficient = 0.0;  // j23 made at the first stretched fibre
    for (std::size_t f = first; f < end; ++f) {
      const FibreSpring& s = fibres[f];
      const Eigen::Vector3d d = s.c(0) * p[0] + s.c(1) * p[1] + s.c(2) * p[2] + s.c(3) * p[3];
      const double i4 = d.squaredNorm() / s.rest_i4;
      if (i4 * i4 * i4 <= J * J) continue;  // slack
      if (j23 == 0.0) {
        const double cbrt_J = std::cbrt(J);
        j23 = 1.0 / (cbrt_J * cbrt_J);
      }
      const double bar = j23 * i4, k = sel.fibre(s);
      double psi1 = 0, psi2 = 0;
      energy += s.V0 * fibre_law(bar - 1.0, k, s.k2, psi1, psi2);
      if (!(psi1 > 0.0)) continue;
      // V0 ψ' ∇Ī4, ∇Ī4 = J^(−2/3) 2 c_i d / rest_i4 − (2/3)(Ī4 / J) ∇det / rest_det.
      const double w = s.V0 * psi1;
      for (int k4 = 0; k4 < 4; ++k4) {
        const Eigen::Vector3d gi = (w * j23 * 2.0 * s.c(k4) / s.rest_i4) * d;
        for (int e = 0; e < 3; ++e) g[3 * v[k4] + e] += gi(e);
      }
      det_coefficient -= w * (2.0 / 3.0) * (bar / J) / rest_det;
    }
    if (det_coefficient != 0.0) {
      const Eigen::Vector3d g0 = -(ga + gb + gc);
      for (int e = 0; e < 3; ++e) {
        g[3 * v[0] + e] += det_coefficient * g0(e);
        g[3 * v[1] + e] += det_coefficient * ga(e);
        g[3 * v[2] + e] += det_coefficient * gb(e);
        g[3 * v[3] + e] += det_coefficient * gc(e);
      }
    }
    first = end;
  }
  return energy;
}

}  // namespace

struct MssModel::Impl {
  mesh::TetMesh mesh;
  MssOptions options;
  Eigen::VectorXd X;       // rest positions, 3n
  Eigen::VectorXd mass_t;  // n
  double damping = 0;      // K_d, N·s/mm
  EquivalentCylinder cylinder;
  double rest_volume = 0;
  // The outer surface, oriented outward (faces of tets not cancelled by a neighbour), for the
  // disc volume by the divergence theorem; about the rest centroid for round-off.
  std::vector<std::array<int, 3>> outer_faces;
  Eigen::Vector3d volume_origin = Eigen::Vector3d::Zero();
  double outer_rest_volume = 0;  // the rest volume that way (rest_volume_mm3)
  double outer_volume(const Eigen::VectorXd& x) const;
  void build_outer_faces();

  std::vector<EdgeSpring> edges;
  std::vector<AngleFace> faces;        // angle springs, three per face
  std::vector<FaceBlock> face_blocks;  // faces packed for the gradient kernel, scaled k
  std::vector<TetTerm> radial;
  std::vector<TetTerm> volume;
  // radial[i] and volume[i] (when on) in one list for the blocked gradient kernel, scaled k.
  std::vector<detail::TetTermBlockInput> tet_block;
  bool disc_volume_on = false;
  double disc_k_unscaled = 0, disc_k = 0;  // k_g, N/mm^5
  std::vector<FibreSpring> fibres;         // two per fibre-reinforced tet, when on

  HessianPattern pattern;       // 3x3 node blocks of every node pair sharing a tet
  std::vector<int> edge_slots;  // 4 per edge: block (a,b) offsets, a,b in {0,1}
  std::vector<int> face_slots;  // 9 per face
  std::vector<int> tet_slots;   // 16 per tetrahedron

  void build(const mesh::RegionMaterials& materials);
  void apply_scales();

  // The steps of build(), in order.
  struct TetProps;
  TetProps tet_properties(const mesh::RegionMaterials& materials) const;
  void build_masses(const TetProps& tp);
  void build_edges(const TetProps& tp);
  std::vector<std::pair<std::array<int, 3>, std::vector<int>>> build_cylinder();
  void build_angle_springs(
      const TetProps& tp,
      const std::vector<std::pair<std::array<int, 3>, std::vector<int>>>& unique_faces);
  void build_tet_terms(const TetProps& tp);
  void build_fibre_springs(const mesh::RegionMaterials& materials, const TetProps& tp);
  void build_damping(const TetProps& tp);
  void build_slots();
  /// Disc volume V(x) = sum of signed tet volumes, and dV/dx into *u (3n) when u != nullptr.
  double volume_and_gradient(const Eigen::VectorXd& x, Eigen::VectorXd* u) const;
  /// Energy and (optionally, grad != nullptr, accumulated) gradient of the selected terms: the
  /// one loop behind energy, gradient, term_energy and term_gradient.
  double accumulate(const Eigen::VectorXd& x, const bool* terms, KSelect sel,
                    Eigen::VectorXd* grad) const;
  /// radial[i] and volume[i] as the blocked kernel's input, stiffnesses by `sel` (0 for a term
  /// not wanted).
  std::vector<detail::TetTermBlockInput> tet_block_input(KSelect sel, bool want_radial,
                                                         bool want_volume) const;
  /// Energy and accumulated gradient of the radial and per-tet volume terms wanted.
  double tet_terms_gradient(const double* x, KSelect sel, bool want_radial, bool want_volume,
                            double* g) const;
  /// Sparse Hessian of the selected terms (the whole-disc term without its rank-one part).
  /// fibres_tension_side: the fibre elements' rest tangent from the tension side (x = rest).
  void assemble_hessian(const Eigen::VectorXd& x, HessianMode mode, const bool* terms, KSelect sel,
                        Eigen::SparseMatrix<double>& H, bool fibres_tension_side = false) const;
};

/// Per-tetrahedron material constants and rest volumes (the inputs of every term).
struct MssModel::Impl::TetProps {
  std::vector<double> E, G, K, rho, V0;  ///< MPa, MPa, MPa, t/mm^3, mm^3
};

MssModel::Impl::TetProps MssModel::Impl::tet_properties(
    const mesh::RegionMaterials& materials) const {
  const Eigen::Index nt = mesh.num_tets();
  TetProps tp;
  std::vector<double>&E = tp.E, &G = tp.G, &K = tp.K, &rho = tp.rho, &V0 = tp.V0;
  E.resize(nt), G.resize(nt), K.resize(nt), rho.resize(nt), V0.resize(nt);
  for (Eigen::Index t = 0; t < nt; ++t) {
    const mesh::IsotropicMaterial& m = materials.at(mesh.region(t));
    mesh::validate(m, "material of region " + std::to_string(mesh.region(t)));
    E[t] = m.youngs_modulus_mpa;
    G[t] = m.shear_modulus_mpa();
    K[t] = m.youngs_modulus_mpa / (3.0 * (1.0 - 2.0 * m.poisson_ratio));
    rho[t] = m.density_t_mm3();
    V0[t] = tet_signed_volume(tet_points(X, mesh.T, static_cast<int>(t)));
  }

  return tp;
}

// 1. Lumped masses (5.1).
void MssModel::Impl::build_masses(const TetProps& tp) {
  const Eigen::Index n = mesh.num_vertices(), nt = mesh.num_tets();
  mass_t = Eigen::VectorXd::Zero(n);
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c) mass_t(mesh.T(t, c)) += 0.25 * tp.rho[t] * tp.V0[t];
  for (Eigen::Index i = 0; i < n; ++i)
    require(mass_t(i) > 0.0, "mss: node " + std::to_string(i) +
                                 " belongs to no tetrahedron (zero mass); remove unused vertices");
}

// 2. Main springs on the unique edges, Van Gelder (5.2): k = sum E_t V_t / L0^2.
void MssModel::Impl::build_edges(const TetProps& tp) {
  const Eigen::Index nt = mesh.num_tets();
  static constexpr int kEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  {
    std::vector<std::pair<std::pair<int, int>, int>> pairs;  // ((lo, hi), tet)
    pairs.reserve(6 * nt);
    for (Eigen::Index t = 0; t < nt; ++t)
      for (const auto& e : kEdge) {
        int a = mesh.T(t, e[0]), b = mesh.T(t, e[1]);
        pairs.push_back({{std::min(a, b), std::max(a, b)}, static_cast<int>(t)});
      }
    std::sort(pairs.begin(), pairs.end());
    for (std::size_t s = 0; s < pairs.size();) {
      EdgeSpring sp{pairs[s].first.first, pairs[s].first.second, 0.0, {0.0, 0.0}, 1.0, 0.0};
      sp.rest_mm = (X.segment<3>(3 * sp.j) - X.segment<3>(3 * sp.i)).norm();
      for (; s < pairs.size() && pairs[s].first == std::make_pair(sp.i, sp.j); ++s) {
        int t = pairs[s].second;
        sp.k_part[region_index(mesh.region(t))] += tp.E[t] * tp.V0[t];
      }
      for (double& k : sp.k_part) k /= sp.rest_mm * sp.rest_mm;
      edges.push_back(sp);
    }
  }
}

// 3. Equivalent cylinder (5.6)-(5.7): endplate diameters from their areas projected on the
//    disc axis (equal-area circles), V the mesh volume. Returns the unique faces with the
//    tetrahedra that share each (the torsional springs sit on them).
std::vector<std::pair<std::array<int, 3>, std::vector<int>>> MssModel::Impl::build_cylinder() {
  const Eigen::Index nt = mesh.num_tets();
  std::vector<std::array<int, 4>> face_list;  // sorted (v0, v1, v2) + tet
  face_list.reserve(4 * nt);
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (Eigen::Index t = 0; t < nt; ++t)
    for (const auto& f : kFace) {
      std::array<int, 3> v{mesh.T(t, f[0]), mesh.T(t, f[1]), mesh.T(t, f[2])};
      std::sort(v.begin(), v.end());
      face_list.push_back({v[0], v[1], v[2], static_cast<int>(t)});
    }
  std::sort(face_list.begin(), face_list.end());
  const Eigen::Vector3d axis = mesh.frame.axes.col(1).normalized();
  double area_label[3] = {0, 0, 0};
  std::vector<std::pair<std::array<int, 3>, std::vector<int>>> unique_faces;
  for (std::size_t s = 0; s < face_list.size();) {
    const auto& fs = face_list;
    std::array<int, 3> v{fs[s][0], fs[s][1], fs[s][2]};
    std::vector<int> tets;
    for (; s < fs.size() && fs[s][0] == v[0] && fs[s][1] == v[1] && fs[s][2] == v[2]; ++s)
      tets.push_back(fs[s][3]);
    if (tets.size() == 1) {
      const int l0 = mesh.surface(v[0]), l1 = mesh.surface(v[1]), l2 = mesh.surface(v[2]);
      if (l0 == l1 && l1 == l2 && (l0 == 1 || l0 == 2)) {
        const Eigen::Vector3d p0 = X.segment<3>(3 * v[0]);
        const Eigen::Vector3d n2 = (X.segment<3>(3 * v[1]) - p0).cross(X.segment<3>(3 * v[2]) - p0);
        area_label[l0] += 0.5 * std::abs(n2.dot(axis));
      }
    }
    unique_faces.push_back({v, std::move(tets)});
  }
  cylinder.volume_mm3 = rest_volume;
  cylinder.upper_diameter_mm = 2.0 * std::sqrt(area_label[2] / kPi);
  cylinder.lower_diameter_mm = 2.0 * std::sqrt(area_label[1] / kPi);
  cylinder.mean_diameter_mm = 0.5 * (cylinder.upper_diameter_mm + cylinder.lower_diameter_mm);

  return unique_faces;
}

// 4. Torsional springs (5.8): three per unique face; k_t = G pi D_m^4 / (32 L_m n_t), G the mean
//    over the face's tetrahedra. Needs both endplates to define the cylinder.
void MssModel::Impl::build_angle_springs(
    const TetProps& tp,
    const std::vector<std::pair<std::array<int, 3>, std::vector<int>>>& unique_faces) {
  if (options.torsion_springs) {
    require(cylinder.upper_diameter_mm > 0.0 && cylinder.lower_diameter_mm > 0.0,
            "mss: torsional springs need both endplates (surface labels 1 and 2) for the "
            "equivalent cylinder (5.6)-(5.8)");
    const double Dm = cylinder.mean_diameter_mm;
    cylinder.length_mm = 4.0 * rest_volume / (kPi * Dm * Dm);
    cylinder.num_angle_springs = static_cast<Eigen::Index>(3 * unique_faces.size());
    cylinder.k_t_per_shear_modulus =
        kPi * std::pow(Dm, 4) /
        (32.0 * cylinder.length_mm * static_cast<double>(cylinder.num_angle_springs));
    faces.reserve(unique_faces.size());
    for (const auto& [v, tets] : unique_faces) {
      AngleFace f;
      double g_part[2] = {0.0, 0.0};
      for (int t : tets)
        g_part[region_index(mesh.region(t))] += tp.G[t] / static_cast<double>(tets.size());
      for (int r = 0; r < 2; ++r) f.k_part[r] = g_part[r] * cylinder.k_t_per_shear_modulus;
      f.k = 0.0;
      for (int corner = 0; corner < 3; ++corner) {
        f.v[corner] = v[corner];
        f.rest_rad[corner] =
            angle_at(X.segment<3>(3 * v[corner]), X.segment<3>(3 * v[(corner + 1) % 3]),
                     X.segment<3>(3 * v[(corner + 2) % 3]));
        f.rest.cos0[corner] = std::cos(f.rest_rad[corner]);
        f.rest.sin0[corner] = std::sin(f.rest_rad[corner]);
      }
      faces.push_back(f);
    }
  } else if (cylinder.mean_diameter_mm > 0.0) {
    const double Dm = cylinder.mean_diameter_mm;
    cylinder.length_mm = 4.0 * rest_volume / (kPi * Dm * Dm);
  }
}

// 5. Radial springs (5.3)-(5.5) and the volume terms (per tetrahedron, whole disc).
void MssModel::Impl::build_tet_terms(const TetProps& tp) {
  const Eigen::Index nt = mesh.num_tets();
  for (Eigen::Index t = 0; t < nt; ++t) {
    const TetPoints p = tet_points(X, mesh.T, static_cast<int>(t));
    const int r = region_index(mesh.region(t));
    if (options.radial_springs) {
      const Eigen::Vector3d xb = 0.25 * p.rowwise().sum();
      double S0 = 0.0;
      for (int c = 0; c < 4; ++c) S0 += (p.col(c) - xb).norm();
      radial.push_back({static_cast<int>(t), r, S0,
                        options.radial_factor * tp.E[t] * tp.V0[t] / (S0 * S0), 0.0});
    }
    if (options.volume_term)
      volume.push_back(
          {static_cast<int>(t), r, tp.V0[t], options.volume_factor * tp.K[t] / tp.V0[t], 0.0});
  }

  // 5b. Whole-disc volume term: k_g = c_g K_mean / V0.
  if (options.disc_volume_term) {
    double KV = 0.0;
    for (Eigen::Index t = 0; t < nt; ++t) KV += tp.K[t] * tp.V0[t];
    disc_volume_on = true;
    disc_k_unscaled = options.disc_volume_factor * (KV / rest_volume) / rest_volume;
  }
}

// 5c. Fibre springs: one per family in every fibre-reinforced tet, k1 = k/4 as the nonlinear FEM.
void MssModel::Impl::build_fibre_springs(const mesh::RegionMaterials& materials,
                                         const TetProps& tp) {
  if (!options.fibre_springs) return;
  require(materials.has_fibres(), "mss: fibre springs need a fibre-reinforced material (\"" +
                                      materials.name + "\" has no fibres)");
  const mesh::ElementFibres field = mesh::fibre_field(mesh, materials);
  for (Eigen::Index t = 0; t < mesh.num_tets(); ++t) {
    if (!(field.stiffness_mpa(t) > 0.0)) continue;
    const TetPoints p = tet_points(X, mesh.T, static_cast<int>(t));
    for (const Eigen::MatrixX3d* dir : {&field.direction_1, &field.direction_2}) {
      const Eigen::Vector3d a = dir->row(t).transpose().normalized();
      const Eigen::Vector4d c = fibre_coefficients(p, a);
      fibres.push_back({static_cast<int>(t), c, tp.V0[t], field.stiffness_mpa(t) / 4.0,
                        field.toe_k2(t), (p * c).squaredNorm(), 0.0, arm_determinant(p)});
    }
  }
}

// 6. Ambient damping (5.11).
void MssModel::Impl::build_damping(const TetProps& tp) {
  const Eigen::Index nt = mesh.num_tets();
  if (options.damping_n_s_per_mm >= 0.0) {
    damping = options.damping_n_s_per_mm;
  } else {
    double EV = 0.0, rhoV = 0.0;
    for (Eigen::Index t = 0; t < nt; ++t) EV += tp.E[t] * tp.V0[t], rhoV += tp.rho[t] * tp.V0[t];
    const double length = cylinder.length_mm > 0.0 ? cylinder.length_mm : std::cbrt(rest_volume);
    const double omega1 = kPi / length * std::sqrt(EV / rhoV);
    damping = 2.0 * options.damping_ratio * omega1 * mass_t.mean();
  }
}

// 7. Hessian pattern and the value slots of every element block.
void MssModel::Impl::build_slots() {
  const Eigen::Index n = mesh.num_vertices(), nt = mesh.num_tets();
  pattern = HessianPattern(mesh.T, n);
  edge_slots.resize(4 * edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const int v[2] = {edges[e].i, edges[e].j};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) edge_slots[4 * e + 2 * a + b] = pattern.block(v[a], v[b]);
  }
  face_slots.resize(9 * faces.size());
  for (std::size_t s = 0; s < faces.size(); ++s)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        face_slots[9 * s + 3 * a + b] = pattern.block(faces[s].v[a], faces[s].v[b]);
  tet_slots.resize(16 * static_cast<std::size_t>(nt));
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        tet_slots[16 * t + 4 * a + b] = pattern.block(mesh.T(t, a), mesh.T(t, b));
}

void MssModel::Impl::build(const mesh::RegionMaterials& materials) {
  const Eigen::Index n = mesh.num_vertices();
  X.resize(3 * n);
  for (Eigen::Index i = 0; i < n; ++i) X.segment<3>(3 * i) = mesh.V.row(i).transpose();
  const TetProps tp = tet_properties(materials);
  rest_volume = std::accumulate(tp.V0.begin(), tp.V0.end(), 0.0);
  build_masses(tp);
  build_edges(tp);
  validate_edge_multipliers(options.edge_multipliers, edges.size());
  const auto unique_faces = build_cylinder();
  build_angle_springs(tp, unique_faces);
  build_tet_terms(tp);
  build_fibre_springs(materials, tp);
  build_outer_faces();
  build_damping(tp);
  build_slots();
  apply_scales();
}

void MssModel::Impl::build_outer_faces() {
  // Each tet's faces oriented outward (for a positively oriented tet 0123: 123, 032, 013, 021)
  // counted per face with the sign of their orientation; a face met once each way cancels. The
  // sum over tets of (1/6) sum over their outward faces of x0.(x1 x2) is the sum of their signed
  // volumes, so the faces left give that sum exactly (up to round-off), whatever the deformation.
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::map<std::array<int, 3>, int> net;  // sorted corners -> orientation count
  for (Eigen::Index t = 0; t < mesh.num_tets(); ++t)
    for (const auto& f : kFace) {
      const std::array<int, 3> face{mesh.T(t, f[0]), mesh.T(t, f[1]), mesh.T(t, f[2])};
      std::array<int, 3> key = face;
      std::sort(key.begin(), key.end());
      // (a, b, c) has the sorted orientation iff it is a rotation of it.
      const int first = face[0] == key[0] ? 0 : face[1] == key[0] ? 1 : 2;
      net[key] += face[(first + 1) % 3] == key[1] ? 1 : -1;
    }
  outer_faces.clear();
  for (const auto& [key, count] : net)
    for (int c = 0; c < std::abs(count); ++c)
      outer_faces.push_back(count > 0 ? key : std::array<int, 3>{key[0], key[2], key[1]});
  volume_origin = X.reshaped(3, X.size() / 3).rowwise().mean();
  outer_rest_volume = outer_volume(X);
}

void MssModel::Impl::apply_scales() {
  const auto& s = options.scales;
  auto scale = [&](Term term, int r) { return s[static_cast<int>(term)].by_region[r]; };
  const std::vector<double>& mu = options.edge_multipliers;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    EdgeSpring& e = edges[i];
    e.mu = mu.empty() ? 1.0 : mu[i];
    e.k = e.mu * (scale(Term::main, 0) * e.k_part[0] + scale(Term::main, 1) * e.k_part[1]);
  }
  for (auto& a : faces)
    a.k = scale(Term::torsion, 0) * a.k_part[0] + scale(Term::torsion, 1) * a.k_part[1];
  face_blocks = pack_faces(faces, [](const AngleFace& f) { return f.k; });
  for (auto& t : radial) t.k = scale(Term::radial, t.region) * t.k_unscaled;
  for (auto& t : volume) t.k = scale(Term::volume, t.region) * t.k_unscaled;
  tet_block = tet_block_input(KSelect{}, !radial.empty(), !volume.empty());
  disc_k = scale(Term::disc_volume, 0) * disc_k_unscaled;
  for (auto& f : fibres) f.k = scale(Term::fibre, 0) * f.k1;
}

MssModel::MssModel(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                   const MssOptions& options)
    : impl_(std::make_unique<Impl>()) {
  mesh::validate(mesh);
  validate_options(options);
  impl_->mesh = mesh;
  impl_->options = options;
  impl_->build(materials);
}

MssModel::~MssModel() = default;
MssModel::MssModel(MssModel&&) noexcept = default;
MssModel& MssModel::operator=(MssModel&&) noexcept = default;
MssModel::MssModel(const MssModel& o) : impl_(std::make_unique<Impl>(*o.impl_)) {}
MssModel& MssModel::operator=(const MssModel& o) {
  if (this != &o) impl_ = std::make_unique<Impl>(*o.impl_);
  return *this;
}

const mesh::TetMesh& MssModel::mesh() const { return impl_->mesh; }
const MssOptions& MssModel::options() const { return impl_->options; }
Eigen::Index MssModel::num_nodes() const { return impl_->mesh.num_vertices(); }
const Eigen::VectorXd& MssModel::rest_positions_mm() const { return impl_->X; }
const Eigen::VectorXd& MssModel::node_masses_t() const { return impl_->mass_t; }
double MssModel::total_mass_t() const { return impl_->mass_t.sum(); }
double MssModel::damping_n_s_per_mm() const { return impl_->damping; }
const EquivalentCylinder& MssModel::cylinder() const { return impl_->cylinder; }
Eigen::Index MssModel::num_edge_springs() const {
  return static_cast<Eigen::Index>(impl_->edges.size());
}
std::vector<EdgeSpringInfo> MssModel::edge_springs() const {
  const auto& s = impl_->options.scales[static_cast<int>(Term::main)].by_region;
  std::vector<EdgeSpringInfo> out;
  out.reserve(impl_->edges.size());
  for (const EdgeSpring& e : impl_->edges) {
    EdgeSpringInfo info;
    info.i = e.i, info.j = e.j, info.rest_mm = e.rest_mm;
    info.k_part = {e.k_part[0], e.k_part[1]};
    info.k_region = s[0] * e.k_part[0] + s[1] * e.k_part[1];
    info.multiplier = e.mu;
    out.push_back(info);
  }
  return out;
}
Eigen::Index MssModel::num_radial_tets() const {
  return static_cast<Eigen::Index>(impl_->radial.size());
}
Eigen::Index MssModel::num_angle_springs() const {
  return 3 * static_cast<Eigen::Index>(impl_->faces.size());
}
Eigen::Index MssModel::num_volume_terms() const {
  return static_cast<Eigen::Index>(impl_->volume.size());
}
Eigen::Index MssModel::num_fibre_springs() const {
  return static_cast<Eigen::Index>(impl_->fibres.size());
}
// Through the outer surface, as volume_mm3, so that volume_change is exactly zero at rest; it
// differs from the tet sum (rest_volume, which the whole-disc term uses) by round-off only.
double MssModel::rest_volume_mm3() const { return impl_->outer_rest_volume; }

void MssModel::set_scales(const std::array<RegionScales, kNumTerms>& scales) {
  MssOptions o = impl_->options;
  o.scales = scales;
  validate_options(o);
  impl_->options.scales = scales;
  impl_->apply_scales();
}

void MssModel::set_edge_multipliers(const std::vector<double>& multipliers) {
  validate_edge_multipliers(multipliers, impl_->edges.size());
  impl_->options.edge_multipliers = multipliers;
  impl_->apply_scales();
}

double MssModel::energy(const Eigen::VectorXd& x) const {
  check_size(x, num_nodes());
  const bool all[kNumTerms] = {true, true, true, true, true, true};
  return impl_->accumulate(x, all, KSelect{}, nullptr);
}

double MssModel::gradient(const Eigen::VectorXd& x, Eigen::VectorXd& grad) const {
  check_size(x, num_nodes());
  const bool all[kNumTerms] = {true, true, true, true, true, true};
  grad.setZero(x.size());
  return impl_->accumulate(x, all, KSelect{}, &grad);
}

double MssModel::term_energy(const Eigen::VectorXd& x, Term term, int region_index) const {
  check_size(x, num_nodes());
  if (region_index != 0 && region_index != 1)
    throw std::invalid_argument("mss: region index must be 0 (annulus) or 1 (nucleus)");
  bool only[kNumTerms] = {false, false, false, false, false, false};
  only[static_cast<int>(term)] = true;
  return impl_->accumulate(x, only, KSelect{region_index}, nullptr);
}

void MssModel::term_gradient(const Eigen::VectorXd& x, Term term, int region_index,
                             Eigen::VectorXd& grad) const {
  check_size(x, num_nodes());
  if (region_index != 0 && region_index != 1)
    throw std::invalid_argument("mss: region index must be 0 (annulus) or 1 (nucleus)");
  bool only[kNumTerms] = {false, false, false, false, false, false};
  only[static_cast<int>(term)] = true;
  grad.setZero(x.size());
  impl_->accumulate(x, only, KSelect{region_index}, &grad);
}

double MssModel::Impl::accumulate(const Eigen::VectorXd& x, const bool* terms, KSelect sel,
                                  Eigen::VectorXd* grad) const {
  const Impl& m = *this;
  double energy = 0.0;
  const double* xp = x.data();
  auto point = [xp](int i) { return Eigen::Map<const Eigen::Vector3d>(xp + 3 * i); };
  if (terms[static_cast<int>(Term::main)]) {
    if (grad) {
      // edge_spring inlined (the call per spring was 9 % of a step): same formulas, and zero
      // force for coincident ends (tests/mss/test_model.cpp against edge_spring).
      double* g = grad->data();
      for (const EdgeSpring& e : m.edges) {
        const Eigen::Vector3d d = point(e.j) - point(e.i);
        const double l = d.norm(), k = sel.edge(e), stretch = l - e.rest_mm;
        energy += 0.5 * k * stretch * stretch;
        if (l < kMinLength_mm) continue;  // a NaN length falls through and propagates
        const Eigen::Vector3d f = (k * stretch / l) * d;
        for (int c = 0; c < 3; ++c) g[3 * e.i + c] -= f(c), g[3 * e.j + c] += f(c);
      }
    } else {
      for (const EdgeSpring& e : m.edges)
        energy += edge_spring(point(e.i), point(e.j), sel.edge(e), e.rest_mm);
    }
  }
  if (terms[static_cast<int>(Term::torsion)]) {
    if (grad) {
      energy += sel.region < 0 ? face_angle_springs_blocks(m.face_blocks, xp, grad->data())
                               : face_angle_springs_all(
                                     m.faces, [&sel](const AngleFace& f) { return sel.angle(f); },
                                     xp, grad->data());
    } else {
      for (const AngleFace& f : m.faces)
        energy += face_angle_springs<false>(xp + 3 * f.v[0], xp + 3 * f.v[1], xp + 3 * f.v[2],
                                            sel.angle(f), f.rest, nullptr, nullptr, nullptr);
    }
  }
  const bool want_radial = terms[static_cast<int>(Term::radial)] && !m.radial.empty();
  const bool want_volume = terms[static_cast<int>(Term::volume)] && !m.volume.empty();
  if (grad && (want_radial || want_volume)) {
    energy += tet_terms_gradient(xp, sel, want_radial, want_volume, grad->data());
  } else if (!grad) {  // energy only (line searches): one tet at a time
    const Eigen::MatrixX4i& T = m.mesh.T;
    if (want_radial)
      for (const TetTerm& t : m.radial)
        energy += radial_springs(tet_points(x, T, t.t), sel.tet(t), t.rest);
    if (want_volume)
      for (const TetTerm& t : m.volume)
        energy += volume_penalty(tet_points(x, T, t.t), sel.tet(t), t.rest);
  }
  if (terms[static_cast<int>(Term::disc_volume)] && m.disc_volume_on) {
    const double k = sel.disc(m.disc_k, m.disc_k_unscaled);
    Eigen::VectorXd u;
    const double excess = volume_and_gradient(x, grad ? &u : nullptr) - m.rest_volume;
    energy += 0.5 * k * excess * excess;
    if (grad) *grad += (k * excess) * u;
  }
  if (terms[static_cast<int>(Term::fibre)] && grad && m.options.isochoric_fibres) {
    energy += isochoric_fibres_gradient(m.fibres, m.mesh.T, xp, sel, grad->data());
  } else if (terms[static_cast<int>(Term::fibre)]) {
    Vector12d g12;
    for (const FibreSpring& f : m.fibres) {
      const TetPoints p = tet_points(x, m.mesh.T, f.t);
      energy += m.options.isochoric_fibres
                    ? isochoric_fibre(p, f.c, f.V0, sel.fibre(f), f.k2, f.rest_det,
                                      grad ? &g12 : nullptr, nullptr, f.rest_i4)
                    : fibre_spring(p, f.c, f.V0, sel.fibre(f), f.k2, grad ? &g12 : nullptr, nullptr,
                                   f.rest_i4);
      if (grad)
        for (int c = 0; c < 4; ++c) grad->segment<3>(3 * m.mesh.T(f.t, c)) += g12.segment<3>(3 * c);
    }
  }
  return energy;
}

std::vector<detail::TetTermBlockInput> MssModel::Impl::tet_block_input(KSelect sel,
                                                                       bool want_radial,
                                                                       bool want_volume) const {
  // radial and volume hold every tet in order when on (build_tet_terms).
  const std::size_t nt = want_radial ? radial.size() : want_volume ? volume.size() : 0;
  std::vector<detail::TetTermBlockInput> in(nt);
  for (std::size_t i = 0; i < nt; ++i) {
    detail::TetTermBlockInput& b = in[i];
    b.t = want_radial ? radial[i].t : volume[i].t;
    b.k_radial = want_radial ? sel.tet(radial[i]) : 0.0;
    b.rest_sum = want_radial ? radial[i].rest : 0.0;
    b.k_volume = want_volume ? sel.tet(volume[i]) : 0.0;
    b.rest_volume = want_volume ? volume[i].rest : 0.0;
  }
  return in;
}

double MssModel::Impl::tet_terms_gradient(const double* x, KSelect sel, bool want_radial,
                                          bool want_volume, double* g) const {
  // The scaled total with every tet term the model has: the list kept by apply_scales;
  // otherwise (calibration's per-term, per-region gradients) one made for the call.
  const bool cached =
      sel.region < 0 && want_radial == !radial.empty() && want_volume == !volume.empty();
  const std::vector<detail::TetTermBlockInput> made =
      cached ? std::vector<detail::TetTermBlockInput>()
             : tet_block_input(sel, want_radial, want_volume);
  const std::vector<detail::TetTermBlockInput>& in = cached ? tet_block : made;
  if (want_radial && want_volume) return detail::tet_terms_all<true, true>(in, mesh.T, x, g);
  if (want_radial) return detail::tet_terms_all<true, false>(in, mesh.T, x, g);
  return detail::tet_terms_all<false, true>(in, mesh.T, x, g);
}

void MssModel::hessian(const Eigen::VectorXd& x, HessianMode mode,
                       Eigen::SparseMatrix<double>& H) const {
  check_size(x, num_nodes());
  const bool all[kNumTerms] = {true, true, true, true, true, true};
  impl_->assemble_hessian(x, mode, all, KSelect{}, H);
}

void MssModel::rest_tangent(Eigen::SparseMatrix<double>& H) const {
  const bool all[kNumTerms] = {true, true, true, true, true, true};
  impl_->assemble_hessian(impl_->X, HessianMode::exact, all, KSelect{}, H, true);
}

void MssModel::term_hessian(const Eigen::VectorXd& x, Term term, int region_index, HessianMode mode,
                            Eigen::SparseMatrix<double>& H) const {
  check_size(x, num_nodes());
  if (region_index != 0 && region_index != 1)
    throw std::invalid_argument("mss: region index must be 0 (annulus) or 1 (nucleus)");
  bool only[kNumTerms] = {false, false, false, false, false, false};
  only[static_cast<int>(term)] = true;
  impl_->assemble_hessian(x, mode, only, KSelect{region_index}, H);
}

void MssModel::Impl::assemble_hessian(const Eigen::VectorXd& x, HessianMode mode, const bool* terms,
                                      KSelect sel, Eigen::SparseMatrix<double>& H,
                                      bool fibres_tension_side) const {
  const Impl& m = *this;
  m.pattern.reset(H);
  double* val = H.valuePtr();
  const double* xp = x.data();
  auto point = [xp](int i) { return Eigen::Map<const Eigen::Vector3d>(xp + 3 * i); };
  // Scatter a local (3k x 3k) element Hessian into its node blocks.
  auto scatter = [&](const auto& h, const int* slots, int k, const int* nodes) {
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b)
        m.pattern.add_block(val, slots[k * a + b], nodes[b], h.template block<3, 3>(3 * a, 3 * b));
  };
  Matrix6d h6;
  for (std::size_t e = 0; e < (terms[static_cast<int>(Term::main)] ? m.edges.size() : 0); ++e) {
    const EdgeSpring& s = m.edges[e];
    edge_spring(point(s.i), point(s.j), sel.edge(s), s.rest_mm, nullptr, &h6, mode);
    const int nodes[2] = {s.i, s.j};
    scatter(h6, &m.edge_slots[4 * e], 2, nodes);
  }
  Matrix9d h9;
  for (std::size_t s = 0; s < (terms[static_cast<int>(Term::torsion)] ? m.faces.size() : 0); ++s) {
    const AngleFace& f = m.faces[s];
    for (int c = 0; c < 3; ++c) {  // corner c: apex v[c], arms to v[c+1], v[c+2]
      const int nodes[3] = {f.v[c], f.v[(c + 1) % 3], f.v[(c + 2) % 3]};
      angle_spring(point(nodes[0]), point(nodes[1]), point(nodes[2]), sel.angle(f), f.rest_rad[c],
                   nullptr, &h9, mode);
      int slots[9];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          slots[3 * a + b] = m.face_slots[9 * s + 3 * ((c + a) % 3) + (c + b) % 3];
      scatter(h9, slots, 3, nodes);
    }
  }
  Matrix12d h12;
  auto tet_hessians = [&](const std::vector<TetTerm>& list, auto kernel) {
    for (const TetTerm& t : list) {
      const double k = sel.tet(t);
      if (k == 0.0) continue;
      kernel(tet_points(x, m.mesh.T, t.t), k, t.rest, &h12);
      const int nodes[4] = {m.mesh.T(t.t, 0), m.mesh.T(t.t, 1), m.mesh.T(t.t, 2), m.mesh.T(t.t, 3)};
      scatter(h12, &m.tet_slots[16 * static_cast<std::size_t>(t.t)], 4, nodes);
    }
  };
  if (terms[static_cast<int>(Term::radial)])
    tet_hessians(m.radial, [mode](const TetPoints& p, double k, double rest, Matrix12d* h) {
      radial_springs(p, k, rest, nullptr, h, mode);
    });
  if (terms[static_cast<int>(Term::volume)])
    tet_hessians(m.volume, [mode](const TetPoints& p, double k, double rest, Matrix12d* h) {
      volume_penalty(p, k, rest, nullptr, h, mode);
    });
  if (terms[static_cast<int>(Term::fibre)])
    for (const FibreSpring& f : m.fibres) {
      const double k = sel.fibre(f);
      if (k == 0.0) continue;
      if (fibres_tension_side)
        h12 = fibre_rest_tangent(tet_points(x, m.mesh.T, f.t), f.c, f.V0, k, f.rest_det, f.rest_i4,
                                 m.options.isochoric_fibres);
      else if (m.options.isochoric_fibres)
        isochoric_fibre(tet_points(x, m.mesh.T, f.t), f.c, f.V0, k, f.k2, f.rest_det, nullptr, &h12,
                        f.rest_i4, mode);
      else
        fibre_spring(tet_points(x, m.mesh.T, f.t), f.c, f.V0, k, f.k2, nullptr, &h12, f.rest_i4);
      const int nodes[4] = {m.mesh.T(f.t, 0), m.mesh.T(f.t, 1), m.mesh.T(f.t, 2), m.mesh.T(f.t, 3)};
      scatter(h12, &m.tet_slots[16 * static_cast<std::size_t>(f.t)], 4, nodes);
    }
  // Whole-disc volume, sparse part k_g (V - V0) H_V (exact mode only; the rank-one part is
  // disc_volume_rank_one's). H_V is trilinear in the arms a, b, c of each tet:
  //   d2V/da db = -[c]x/6,  d2V/da dc = [b]x/6,  d2V/db dc = -[a]x/6, zero diagonal blocks.
  if (terms[static_cast<int>(Term::disc_volume)] && m.disc_volume_on &&
      mode == HessianMode::exact) {
    const double w =
        sel.disc(m.disc_k, m.disc_k_unscaled) * (m.volume_and_gradient(x, nullptr) - m.rest_volume);
    for (Eigen::Index t = 0; t < m.mesh.num_tets(); ++t) {
      const TetPoints p = tet_points(x, m.mesh.T, static_cast<int>(t));
      const Eigen::Matrix3d Sa = skew((p.col(1) - p.col(0)) * (w / 6.0));
      const Eigen::Matrix3d Sb = skew((p.col(2) - p.col(0)) * (w / 6.0));
      const Eigen::Matrix3d Sc = skew((p.col(3) - p.col(0)) * (w / 6.0));
      Eigen::Matrix<double, 9, 9> arms;  // w H_V with respect to (a, b, c)
      arms << Eigen::Matrix3d::Zero(), -Sc, Sb, Sc, Eigen::Matrix3d::Zero(), -Sa, -Sb, Sa,
          Eigen::Matrix3d::Zero();
      // Nodes: x1, x2, x3 are the arm ends, x0 = minus their sum: H = P arms P^T.
      Matrix12d h = Matrix12d::Zero();
      h.bottomRightCorner<9, 9>() = arms;
      for (int i = 0; i < 3; ++i) {
        Eigen::Matrix3d row = Eigen::Matrix3d::Zero();
        for (int j = 0; j < 3; ++j) row += arms.block<3, 3>(3 * i, 3 * j);
        h.block<3, 3>(3 + 3 * i, 0) = -row;  // d/dx_{i+1} d/dx0 = -sum over the arms of x0
      }
      h.topRightCorner<3, 9>() = h.bottomLeftCorner<9, 3>().transpose();
      h.topLeftCorner<3, 3>() = -h.block<3, 3>(3, 0) - h.block<3, 3>(6, 0) - h.block<3, 3>(9, 0);
      const int nodes[4] = {m.mesh.T(t, 0), m.mesh.T(t, 1), m.mesh.T(t, 2), m.mesh.T(t, 3)};
      scatter(h, &m.tet_slots[16 * static_cast<std::size_t>(t)], 4, nodes);
    }
  }
}

double MssModel::Impl::volume_and_gradient(const Eigen::VectorXd& x, Eigen::VectorXd* u) const {
  if (u) u->setZero(x.size());
  double v = 0.0;
  for (Eigen::Index t = 0; t < mesh.num_tets(); ++t) {
    const TetPoints p = tet_points(x, mesh.T, static_cast<int>(t));
    const Eigen::Vector3d a = p.col(1) - p.col(0), b = p.col(2) - p.col(0), c = p.col(3) - p.col(0);
    const Eigen::Vector3d bc = b.cross(c);
    v += a.dot(bc) / 6.0;
    if (u) {
      // dV_t/dx_i: a third of the opposite face's area vector, pointing towards x_i.
      const Eigen::Vector3d g1 = bc / 6.0, g2 = c.cross(a) / 6.0, g3 = a.cross(b) / 6.0;
      u->segment<3>(3 * mesh.T(t, 0)) -= g1 + g2 + g3;
      u->segment<3>(3 * mesh.T(t, 1)) += g1;
      u->segment<3>(3 * mesh.T(t, 2)) += g2;
      u->segment<3>(3 * mesh.T(t, 3)) += g3;
    }
  }
  return v;
}

bool MssModel::has_disc_volume_term() const { return impl_->disc_volume_on; }

double MssModel::disc_volume_rank_one(const Eigen::VectorXd& x, Eigen::VectorXd& u) const {
  check_size(x, num_nodes());
  if (!impl_->disc_volume_on) {
    u.setZero(x.size());
    return 0.0;
  }
  impl_->volume_and_gradient(x, &u);
  return impl_->disc_k;
}

Eigen::Index MssModel::inverted_tets(const Eigen::VectorXd& x) const {
  check_size(x, num_nodes());
  Eigen::Index n = 0;
  for (Eigen::Index t = 0; t < impl_->mesh.num_tets(); ++t)
    n += tet_signed_volume(tet_points(x, impl_->mesh.T, static_cast<int>(t))) <= 0.0;
  return n;
}

double MssModel::volume_mm3(const Eigen::VectorXd& x) const {
  check_size(x, num_nodes());
  return impl_->outer_volume(x);
}

// The sum of signed tet volumes through the outer surface (build_outer_faces): a third of the
// work of the tet loop on the palpation discs, which report their volume every step.
double MssModel::Impl::outer_volume(const Eigen::VectorXd& x) const {
  const Eigen::Vector3d o = volume_origin;
  double v = 0.0;
  for (const auto& f : outer_faces) {
    const Eigen::Vector3d a = x.segment<3>(3 * f[0]) - o, b = x.segment<3>(3 * f[1]) - o,
                          c = x.segment<3>(3 * f[2]) - o;
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

}  // namespace spinesim::mss
