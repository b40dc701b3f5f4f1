// The torsional springs' constant where it enters the model, against thesis (5.6)-(5.8) worked
// out here: k_t = G π D_m⁴ / (32 L_m n_t), with L_m = 4 V / (π D_m²) from the mesh volume and
// n_t = 3 × the number of distinct faces counted by brute force; the model's torsion energy of a
// perturbed state must be ½ k_t Σ (θ − θ₀)² over every corner of every face, angles measured
// here with acos. A factor in k_t, in n_t or in the energy fails.
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mss/model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>

using namespace spinesim;

namespace {

double angle(const Eigen::Vector3d& apex, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp((a - apex).normalized().dot((b - apex).normalized()), -1.0, 1.0));
}

}  // namespace

TEST(AbsoluteScales, TorsionSpringConstantAndEnergyFollowTheEquivalentCylinder) {
  const auto dims = mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR);
  const mesh::TetMesh m = mesh::mesh_structured_disc(dims);
  const auto materials =
      mesh::load_material("real-disc", SPINESIM_DATA_DIR);  // one material everywhere
  const mss::MssModel model(m, materials);
  const mss::EquivalentCylinder& cyl = model.cylinder();

  // n_t: three angles per distinct face of the mesh.
  std::set<std::array<int, 3>> faces;
  static const int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (const auto& f : kFace) {
      std::array<int, 3> v{m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      std::sort(v.begin(), v.end());
      faces.insert(v);
    }
  const double n_t = 3.0 * double(faces.size());
  EXPECT_EQ(cyl.num_angle_springs, Eigen::Index(n_t));
  const double Dm = cyl.mean_diameter_mm, V = mesh::mesh_volume(m);
  const double Lm = 4 * V / (M_PI * Dm * Dm);
  EXPECT_NEAR(cyl.length_mm, Lm, 1e-9 * Lm);
  const double G = materials.at(int(mesh::Region::annulus)).shear_modulus_mpa();
  ASSERT_EQ(G, materials.at(int(mesh::Region::nucleus)).shear_modulus_mpa());
  const double k_t = G * M_PI * std::pow(Dm, 4) / (32 * Lm * n_t);  // N·mm/rad
  EXPECT_NEAR(G * cyl.k_t_per_shear_modulus, k_t, 1e-9 * k_t);

  // Energy of a perturbed state: every vertex moved by up to 0.02 mm.
  Eigen::VectorXd x = model.rest_positions_mm();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-0.02, 0.02);
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += d(rng);
  const Eigen::VectorXd& X = model.rest_positions_mm();
  double sum = 0;
  for (const auto& f : faces)
    for (int c = 0; c < 3; ++c) {
      const int p = f[std::size_t(c)], a = f[std::size_t((c + 1) % 3)],
                b = f[std::size_t((c + 2) % 3)];
      const double dtheta = angle(x.segment<3>(3 * p), x.segment<3>(3 * a), x.segment<3>(3 * b)) -
                            angle(X.segment<3>(3 * p), X.segment<3>(3 * a), X.segment<3>(3 * b));
      sum += dtheta * dtheta;
    }
  const double expected = 0.5 * k_t * sum;
  const double energy =
      model.term_energy(x, mss::Term::torsion, 0) + model.term_energy(x, mss::Term::torsion, 1);
  EXPECT_NEAR(energy, expected, 1e-6 * expected);
}
