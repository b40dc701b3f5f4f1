// The nonlinear disc's material point against CalculiX's built-in ELASTIC_FIBER material (the
// same energy, fem/hyperelastic.hpp): one C3D4 tetrahedron carried through a homogeneous
// deformation (every node's displacement prescribed, NLGEOM), its Cauchy stress and the nodal
// reaction forces compared with σ = J⁻¹ F S Fᵀ and f_a = V₀ F S ∇N_a.
#include "spinesim/fem/hyperelastic.hpp"

#include "calculix.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace spinesim::fem {
namespace {

using test::have_calculix;
using test::last_block;
using test::run_calculix;

const Eigen::Matrix<double, 4, 3> kNodes =
    (Eigen::Matrix<double, 4, 3>() << 0, 0, 0, 2, 0, 0, 0, 1.5, 0, 0.2, 0.1, 1.8).finished();

/// The deck: one C3D4 of material ELASTIC_FIBER, every node moved to F X.
std::string deck(const FibreHyperelastic& m, const Eigen::Matrix3d& F) {
  std::ostringstream os;
  os << std::setprecision(13);  // CalculiX reads fields of at most 20 characters
  os << "*NODE,NSET=NALL\n";
  for (int a = 0; a < 4; ++a)
    os << a + 1 << "," << kNodes(a, 0) << "," << kNodes(a, 1) << "," << kNodes(a, 2) << "\n";
  os << "*ELEMENT,TYPE=C3D4,ELSET=EALL\n1,1,2,3,4\n" << test::elastic_fiber_material(m);
  os << "*SOLID SECTION,ELSET=EALL,MATERIAL=ELASTIC_FIBER\n*STEP,NLGEOM,INC=1000\n*STATIC\n"
     << "0.05,1.0\n*BOUNDARY\n";
  for (int a = 0; a < 4; ++a) {
    const Eigen::Vector3d X = kNodes.row(a).transpose(), u = (F - Eigen::Matrix3d::Identity()) * X;
    for (int d = 0; d < 3; ++d)
      os << a + 1 << "," << d + 1 << "," << d + 1 << "," << (std::abs(u(d)) < 1e-14 ? 0.0 : u(d))
         << "\n";
  }
  os << "*EL PRINT,ELSET=EALL\nS\n*NODE PRINT,NSET=NALL\nRF\n*END STEP\n";
  return os.str();
}

/// The annulus of the unit tests: a soft matrix, two families at ±30°, out of the x-y plane.
FibreHyperelastic annulus() {
  FibreHyperelastic m;
  m.c10_mpa = 0.35;
  m.d1_per_mpa = 0.3;
  const double a = 30.0 * M_PI / 180.0;
  const Eigen::Vector3d circ = Eigen::Vector3d(1, 0, 0.3).normalized(), axial(0, 1, 0);
  m.fibres.push_back({std::cos(a) * circ + std::sin(a) * axial, 3.0, 45.0});
  m.fibres.push_back({std::cos(a) * circ - std::sin(a) * axial, 3.0, 45.0});
  return m;
}

void expect_same_as_calculix(const std::string& name, const FibreHyperelastic& m,
                             const Eigen::Matrix3d& F, int fibres_in_tension) {
  SCOPED_TRACE(name);
  const Eigen::Matrix3d C = F.transpose() * F;
  const MaterialPointState p = fibre_hyperelastic_point(C, m);
  ASSERT_EQ(p.fibres_in_tension, fibres_in_tension);
  const std::string dat = run_calculix(name, deck(m, F));
  const auto stress = last_block(dat, " stresses", 2);
  const auto forces = last_block(dat, " forces", 1);
  ASSERT_EQ(stress.size(), 1u) << dat;
  ASSERT_EQ(forces.size(), 4u) << dat;

  // CalculiX prints (xx, yy, zz, xy, xz, yz) with 7 significant digits.
  const Eigen::Matrix3d s = cauchy_stress(F, m);
  const Eigen::VectorXd ours =
      (Eigen::VectorXd(6) << s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(0, 2), s(1, 2)).finished();
  EXPECT_LE((stress[0] - ours).cwiseAbs().maxCoeff(), 2e-6 * ours.cwiseAbs().maxCoeff())
      << "CalculiX " << stress[0].transpose() << "\nours     " << ours.transpose();

  // Reactions: f_a = V₀ P ∇N_a, P = F S (the first Piola–Kirchhoff stress).
  double volume = 0;
  const Eigen::Matrix<double, 4, 3> g = barycentric_gradients(kNodes, volume);
  const Eigen::Matrix3d P = F * p.S;
  double scale = 0;
  std::vector<Eigen::Vector3d> f(4);
  for (int a = 0; a < 4; ++a) {
    f[std::size_t(a)] = volume * P * g.row(a).transpose();
    scale = std::max(scale, f[std::size_t(a)].cwiseAbs().maxCoeff());
  }
  for (int a = 0; a < 4; ++a)
    EXPECT_LE((forces[std::size_t(a)] - f[std::size_t(a)]).cwiseAbs().maxCoeff(), 2e-6 * scale)
        << "node " << a + 1 << ": CalculiX " << forces[std::size_t(a)].transpose() << ", ours "
        << f[std::size_t(a)].transpose();
}

TEST(FibreHyperelasticCalculix, SameStressAndReactionsAsElasticFiber) {
  ASSERT_TRUE(have_calculix()) << "CalculiX is the reference of this test: no " << test::kCalculix
                               << " (scripts/install-deps.sh installs calculix-ccx)";
  const FibreHyperelastic m = annulus();
  Eigen::Matrix3d sheared;  // one family stretched, the other shortened
  sheared << 1.0, 0.25, 0.01, 0.02, 0.99, -0.03, -0.01, 0.02, 1.0;
  expect_same_as_calculix("sheared", m, sheared, 1);

  const Eigen::Matrix3d compressed = Eigen::Vector3d(0.92, 1.03, 1.02).asDiagonal();
  expect_same_as_calculix("compressed", m, compressed, 0);  // the matrix alone

  // Both families stretched into the toe and beyond: Ī4 ≈ 1.1.
  Eigen::Matrix3d stretched = Eigen::Vector3d(1.08, 1.06, 0.9).asDiagonal();
  stretched(2, 0) = 0.03;
  expect_same_as_calculix("stretched", m, stretched, 2);
}

}  // namespace
}  // namespace spinesim::fem
