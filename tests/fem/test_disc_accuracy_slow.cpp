// Mesh convergence of the 6×6 stiffness on the CGAL-meshed L4-L5 disc (annulus E 4.2 MPa,
// nu 0.45; nucleus E 1 MPa, nu 0.49): P1 and P2 at several cell sizes against P2 at 1.0 mm
// (~265k DOF, p-multigrid CG) as the reference. Prints the relative error of each diagonal
// entry and the wall time, to weigh P1 against P2 as the default order (accuracy per second).
// Asserts only convergence properties: P2 at 1.5 mm within 3 % on every diagonal entry, and
// P1 errors shrinking under refinement. All K6 about one fixed centre (the reference's).
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

mesh::TetMesh l4_l5(double cell_mm) {
  mesh::MeshOptions opt;
  opt.cell_size_mm = cell_mm;
  return mesh::mesh_parametric_disc({"L4-L5", 47.3, 35.5, 46.6, 35.0, 11.3}, opt);
}

mesh::RegionMaterials annulus_nucleus() {
  mesh::RegionMaterials m;
  m.name = "annulus-nucleus-like";
  m.fallback = {4.2, 0.45, 1038.0};
  m.by_region[2] = {1.0, 0.49, 1038.0};
  return m;
}

struct Timed {
  Vector6d diag;
  double seconds;
  Eigen::Index dofs;
};

Timed run_case(const mesh::TetMesh& m, int order, const Eigen::Vector3d& c) {
  const auto t0 = std::chrono::steady_clock::now();
  const DiscFem fem(m, annulus_nucleus(), order, c);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {fem.stiffness_6x6().diagonal(), s, fem.num_dofs()};
}

}  // namespace

TEST(DiscAccuracySlow, P1AndP2ConvergeToTheSameStiffness) {
  const mesh::TetMesh fine = l4_l5(1.0);
  const Eigen::Vector3d c = DiscFem::default_plate_center(fine);
  SolverOptions cg;
  cg.solver = LinearSolver::p_multigrid_cg;
  const Vector6d ref = DiscFem(fine, annulus_nucleus(), 2, c, cg).stiffness_6x6().diagonal();
  std::printf("reference P2 @ 1.0 mm: diag K6 = %s (N/mm x3, N·mm/rad x3)\n",
              [&] {
                std::ostringstream os;
                os << ref.transpose();
                return os.str();
              }()
                  .c_str());
  std::printf("order cell_mm     DOF   time_s   rel. error of diag(K6): tx ty tz rx ry rz\n");
  const auto report = [&](int order, double cell, const Timed& r) {
    const Vector6d e = (r.diag - ref).cwiseQuotient(ref);
    std::printf("P%d    %5.2f  %7ld  %7.2f  %+.4f %+.4f %+.4f %+.4f %+.4f %+.4f\n", order, cell,
                long(r.dofs), r.seconds, e(0), e(1), e(2), e(3), e(4), e(5));
    return e.cwiseAbs().maxCoeff();
  };
  double previous = 1e9;
  for (double cell : {2.0, 1.5, 1.0, 0.75}) {
    const double err = report(1, cell, run_case(cell == 1.0 ? fine : l4_l5(cell), 1, c));
    EXPECT_LT(err, previous) << "P1 error should shrink with the cell size";
    previous = err;
  }
  report(2, 2.0, run_case(l4_l5(2.0), 2, c));
  EXPECT_LT(report(2, 1.5, run_case(l4_l5(1.5), 2, c)), 0.03);
}
