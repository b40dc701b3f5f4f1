// The exported Abaqus deck (abaqus_deck.hpp) run by CalculiX as it is, against our own solve of
// the same problem: displacements node by node, and stress, strain and energy density element
// by element (stress_fields.hpp). A CGAL-meshed L4-L5 disc with the fibre-reinforced annulus and
// a foreign geometry (a CGAL-meshed cylinder, isotropic), C3D4 and C3D10, a prescribed plate
// motion and an applied wrench (CalculiX's *RIGID BODY).
#include "spinesim/fem/abaqus_deck.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/stress_fields.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/mesher.hpp"

#include "calculix.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

const mesh::TetMesh& disc() {
  static const mesh::TetMesh m = [] {
    mesh::MeshOptions opt;
    opt.cell_size_mm = 3.0;
    opt.seed = 1;
    return mesh::mesh_parametric_disc(mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR), opt);
  }();
  return m;
}

const mesh::TetMesh& cylinder() {
  static const mesh::TetMesh m = [] {
    constexpr double R = 6.0, L = 8.0;
    mesh::LabeledBody body;
    body.label = [=](const Eigen::Vector3d& p) {
      return (p.x() * p.x() + p.z() * p.z() <= R * R && std::abs(p.y()) <= 0.5 * L) ? 1 : 0;
    };
    body.bounding_radius_mm = 1.5 * std::hypot(R, 0.5 * L);
    body.exact_volume_mm3 = M_PI * R * R * L;
    body.classify_facet = [](const Eigen::Vector3d&, const Eigen::Vector3d& n) {
      if (n.y() < -0.9) return mesh::Surface::inferior_endplate;
      if (n.y() > 0.9) return mesh::Surface::superior_endplate;
      return mesh::Surface::outer_wall;
    };
    for (double y : {-0.5 * L, 0.5 * L}) {
      std::vector<Eigen::Vector3d> rim;
      for (int i = 0; i < 60; ++i)
        rim.emplace_back(R * std::cos(2 * M_PI * i / 60), y, R * std::sin(2 * M_PI * i / 60));
      rim.push_back(rim.front());
      body.features.push_back(rim);
    }
    mesh::MeshOptions opt;
    opt.cell_size_mm = 2.0;
    opt.seed = 2;
    return mesh::mesh_labeled_body(body, opt);
  }();
  return m;
}

mesh::RegionMaterials rubber() {
  mesh::RegionMaterials m;
  m.name = "isotropic";
  m.fallback = {10.0, 0.3, 1000};
  return m;
}

/// Per-element means of the rows of a CalculiX integration-point block (npts rows per element).
Eigen::MatrixXd element_means(const std::vector<Eigen::VectorXd>& rows, int npts) {
  if (rows.empty()) return {};
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(Eigen::Index(rows.size()) / npts, rows[0].size());
  for (std::size_t k = 0; k < rows.size(); ++k) out.row(Eigen::Index(k) / npts) += rows[k].transpose() / npts;
  return out;
}

/// Our (xx, yy, zz, xy, yz, xz) as CalculiX's (xx, yy, zz, xy, xz, yz).
Eigen::MatrixXd to_calculix_order(const Eigen::MatrixXd& a) {
  Eigen::MatrixXd b = a;
  b.col(4) = a.col(5);
  b.col(5) = a.col(4);
  return b;
}


struct Case {
  const char* name;
  const mesh::TetMesh& (*mesh)();
  bool fibres;
  int order;
  bool motion;
};

void compare(const Case& c) {
  SCOPED_TRACE(c.name);
  const mesh::TetMesh& m = c.mesh();
  const mesh::RegionMaterials mat =
      c.fibres ? mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR) : rubber();
  const Eigen::Vector3d center = DiscFem::default_plate_center(m);
  Vector6d load;
  if (c.motion)
    load << 0.01, -0.08, 0.02, 0.004, -0.003, 0.006;  // mm, rad
  else
    load << 20, -300, 40, 500, -400, 300;  // N, N·mm
  SolverOptions opt;
  opt.solver = LinearSolver::direct;
  const DiscFem fem(m, mat, c.order, center, opt);
  const PlateSolution s = c.motion ? fem.solve_motion(load) : fem.solve_wrench(load);
  const ElementFields ours = element_fields(m, mat, fem.fibres(), c.order, s.node_displacement_mm);

  AbaqusDeck deck;
  deck.order = c.order;
  deck.plate_center_mm = center;
  deck.prescribed_motion = c.motion;
  deck.load = load;
  std::ostringstream inp;
  write_abaqus_deck(inp, m, mat, deck);
  const std::string dat = test::run_calculix(c.name, inp.str());
  ASSERT_FALSE(dat.empty());

  const auto u_rows = test::last_block(dat, " displacements (vx,vy,vz) for set NALL", 1);
  ASSERT_EQ(Eigen::Index(u_rows.size()), fem.num_nodes());
  Eigen::MatrixXd u(fem.num_nodes(), 3);
  for (Eigen::Index i = 0; i < u.rows(); ++i) u.row(i) = u_rows[std::size_t(i)].transpose();
  const int npts = c.order == 1 ? 1 : 4;
  const Eigen::MatrixXd S = element_means(test::last_block(dat, " stresses", 2), npts);
  const Eigen::MatrixXd E = element_means(test::last_block(dat, " strains", 2), npts);
  const Eigen::MatrixXd W = element_means(test::last_block(dat, " internal energy density", 2), npts);
  ASSERT_EQ(S.rows(), m.num_tets());
  ASSERT_EQ(E.rows(), m.num_tets());
  ASSERT_EQ(W.rows(), m.num_tets());

  const double eu = test::relative_difference(u, s.node_displacement_mm);
  const double es = test::relative_difference(S, to_calculix_order(ours.stress_mpa));
  const double ee = test::relative_difference(E, to_calculix_order(ours.strain));
  const double ew = test::relative_difference(W, ours.strain_energy_density_mpa);
  Eigen::VectorXd vm(m.num_tets());
  for (Eigen::Index t = 0; t < vm.rows(); ++t) {
    Vector6d st;
    st << S(t, 0), S(t, 1), S(t, 2), S(t, 3), S(t, 5), S(t, 4);
    vm(t) = von_mises(st);
  }
  const double evm = test::relative_difference(vm, ours.von_mises_mpa);
  std::printf("| %s | %ld | %.1e | %.1e | %.1e | %.1e | %.1e | max von Mises %.4g MPa |\n", c.name,
              long(m.num_tets()), eu, es, evm, ee, ew, ours.von_mises_mpa.maxCoeff());
  // CalculiX prints 7 significant digits: agreement to its print precision.
  EXPECT_LT(eu, 1e-5);
  EXPECT_LT(es, 1e-5);
  EXPECT_LT(evm, 1e-5);
  EXPECT_LT(ee, 1e-5);
  EXPECT_LT(ew, 1e-5);
}

}  // namespace

TEST(AbaqusDeckCalculix, StressStrainAndEnergyEqualCalculixElementByElement) {
  if (!test::have_calculix()) GTEST_SKIP() << "CalculiX (calculix-ccx) not installed";
  std::printf("| case | tets | u | stress | von Mises | strain | energy density | |\n");
  for (const Case& c : {Case{"disc_fibres_c3d4_motion", disc, true, 1, true},
                        Case{"disc_fibres_c3d10_motion", disc, true, 2, true},
                        Case{"disc_fibres_c3d10_wrench", disc, true, 2, false},
                        Case{"cylinder_c3d4_motion", cylinder, false, 1, true},
                        Case{"cylinder_c3d10_wrench", cylinder, false, 2, false}})
    compare(c);
}

TEST(AbaqusDeck, BadInputIsRefused) {
  const mesh::TetMesh& m = cylinder();
  std::ostringstream os;
  AbaqusDeck deck;
  deck.order = 3;
  EXPECT_THROW(write_abaqus_deck(os, m, rubber(), deck), std::invalid_argument);
  deck.order = 1;
  deck.load(2) = NAN;
  EXPECT_THROW(write_abaqus_deck(os, m, rubber(), deck), std::invalid_argument);
  mesh::TetMesh flat = m;
  flat.surface.setZero();
  deck.load.setZero();
  EXPECT_THROW(write_abaqus_deck(os, flat, rubber(), deck), std::invalid_argument);
}
