// Circular cylinder between bonded rigid ends (bottom fixed, top = the rigid plate), meshed by
// CGAL Mesh_3 with the rims protected as features. Radius R, length L along y.
//   - Torsion by theta about the axis: the exact solution is Coulomb torsion (sections rotate
//     rigidly, no warping), which bonded ends do not disturb: torque T = G J theta / L,
//     J = pi D^4 / 32. The field is bilinear (u_x = -theta y z / L ...) so P2 represents it
//     exactly; what is left is the polygonal boundary (facet sag), kept below ~0.3 % by the
//     facet size/distance chosen here. Asserted within 1 % with P2.
//   - Axial compression by delta with nu = 0: exact uniaxial stress, F = E A delta / L, again
//     undisturbed by bonded ends (no lateral contraction to restrain). P1 and P2, within 2 %.
//     With nu > 0 bonded ends restrain the Poisson contraction and stiffen the cylinder; that
//     ratio is printed, not asserted.
// Reaction convention: the wrench the cylinder exerts on the top plate, so compression gives
// F_y > 0 and a positive twist theta_y gives M_y < 0.
// Slow (CGAL meshing + three 55k-DOF P2 solves, ~20 s), hence the _slow label.
#include "spinesim/common/constants.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

constexpr double kR = 5.0, kL = 10.0;  // mm

const mesh::TetMesh& cylinder() {
  static const mesh::TetMesh m = [] {
    mesh::LabeledBody body;
    body.label = [](const Eigen::Vector3d& p) {
      return (p.x() * p.x() + p.z() * p.z() <= kR * kR && std::abs(p.y()) <= 0.5 * kL) ? 1 : 0;
    };
    body.bounding_radius_mm = 1.5 * std::hypot(kR, 0.5 * kL);
    body.exact_volume_mm3 = kPi * kR * kR * kL;
    body.classify_facet = [](const Eigen::Vector3d&, const Eigen::Vector3d& n) {
      if (n.y() < -0.9) return mesh::Surface::inferior_endplate;
      if (n.y() > 0.9) return mesh::Surface::superior_endplate;
      return mesh::Surface::outer_wall;
    };
    for (double y : {-0.5 * kL, 0.5 * kL}) {
      std::vector<Eigen::Vector3d> rim;
      const int n = 160;
      for (int i = 0; i < n; ++i)
        rim.emplace_back(kR * std::cos(2 * kPi * i / n), y, kR * std::sin(2 * kPi * i / n));
      rim.push_back(rim.front());  // closed: the last point must repeat the first exactly
      body.features.push_back(rim);
    }
    mesh::MeshOptions opt;
    opt.cell_size_mm = 1.0;
    opt.facet_size_mm = 0.5;
    opt.edge_size_mm = 0.4;
    opt.facet_distance_mm = 0.005;
    opt.seed = 3;
    mesh::TetMesh out = mesh::mesh_labeled_body(body, opt);
    std::printf("cylinder R=%g L=%g: %ld vertices, %ld tets, volume %.4f %% of exact\n", kR, kL,
                long(out.num_vertices()), long(out.num_tets()),
                100.0 * mesh::mesh_volume(out) / body.exact_volume_mm3);
    return out;
  }();
  return m;
}

mesh::RegionMaterials homogeneous(double E, double nu) {
  mesh::RegionMaterials m;
  m.name = "test";
  m.fallback = {E, nu, 1000.0};
  return m;
}

// Torque and force about the top end's centre on the axis (the mean of the top nodes is off
// the axis by up to ~0.07 mm on this unstructured mesh).
Eigen::Vector3d top_center() { return Eigen::Vector3d(0, 0.5 * kL, 0); }

Vector6d motion(int component, double value) {
  Vector6d q = Vector6d::Zero();
  q(component) = value;
  return q;
}

}  // namespace

TEST(Cylinder, TorsionTorqueIsGJThetaOverLWithP2) {
  const mesh::TetMesh& m = cylinder();
  const double E = 10.0, nu = 0.3, theta = 0.01;  // MPa, -, rad
  const DiscFem fem(m, homogeneous(E, nu), 2, top_center());
  const PlateSolution s = fem.solve_motion(motion(4, theta));  // twist about +y
  const double G = E / (2 * (1 + nu)), J = kPi * std::pow(2 * kR, 4) / 32;
  const double expected = G * J * theta / kL;  // N·mm
  const double torque = -s.reaction_wrench(4);
  std::printf("torsion P2 (%ld DOF): torque %.5f N·mm, GJθ/L %.5f, error %+.3f %%\n",
              long(fem.num_dofs()), torque, expected, 100 * (torque / expected - 1));
  EXPECT_NEAR(torque / expected, 1.0, 0.01);
  // Pure torsion: no axial force and no bending moments to speak of.
  EXPECT_LT(std::abs(s.reaction_wrench(1)) * kR, 1e-3 * torque);
}

TEST(Cylinder, AxialCompressionWithNuZeroIsEADeltaOverL) {
  const mesh::TetMesh& m = cylinder();
  const double E = 10.0, delta = 0.05;                     // MPa, mm
  const double expected = E * kPi * kR * kR * delta / kL;  // N
  for (int order : {1, 2}) {
    const DiscFem fem(m, homogeneous(E, 0.0), order, top_center());
    const PlateSolution s = fem.solve_motion(motion(1, -delta));
    const double force = s.reaction_wrench(1);  // compression pushes the plate up: F_y > 0
    std::printf("compression P%d nu=0 (%ld DOF): F %.5f N, EAδ/L %.5f, error %+.3f %%\n", order,
                long(fem.num_dofs()), force, expected, 100 * (force / expected - 1));
    EXPECT_GT(force, 0.0);
    EXPECT_NEAR(force / expected, 1.0, 0.02);
  }
  // nu > 0: bonded ends restrain the Poisson contraction -> stiffer than E A / L (stated only).
  const DiscFem fem(m, homogeneous(E, 0.45), 2, top_center());
  const double ratio = fem.solve_motion(motion(1, -delta)).reaction_wrench(1) / expected;
  std::printf("compression P2 nu=0.45: F / (EAδ/L) = %.4f (bonded-end stiffening)\n", ratio);
  EXPECT_GT(ratio, 1.0);
}
