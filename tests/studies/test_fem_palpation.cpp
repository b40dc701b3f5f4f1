// Palpating the linear FEM disc (`haptics run --scene disc --disc-model fem`): the multirate
// worker's local contact model against the synchronous solve (the FEM equilibrium every 1 ms),
// passivity of the hand's work, the force balance of a held press, and the scene's set-up.
#include "../haptics/disc_fixture.hpp"
#include "spinesim/haptics/disc_palpation.hpp"
#include "spinesim/haptics/safety.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/studies/disc_palpation_setup.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace sh = spinesim::haptics;
namespace mesh = spinesim::mesh;
using Eigen::Vector3d;

namespace spinesim::studies {
namespace {

const std::string kData = SPINESIM_DATA_DIR;

const mesh::TetMesh& disc_mesh() { return spinesim::test::structured_l4l5_disc(); }

std::unique_ptr<sh::PalpableDisc> fem_disc() {
  return make_fem_palpable_disc(disc_mesh(), mesh::load_material("fibre-reinforced", kData), 4.0,
                                0.0);
}

std::pair<Vector3d, Vector3d> anterior_wall() { return spinesim::test::anterior_wall(disc_mesh()); }

sh::DiscPalpationOptions options() {
  sh::DiscPalpationOptions o;
  o.coupling_stiffness_n_per_mm = 0.5;
  o.probe_radius_mm = 4;
  o.realtime_priority = false;
  o.force_scale = 30;
  return o;
}

std::vector<Vector3d> press_path(double depth, double press_s) {
  return spinesim::test::press_path(disc_mesh(), 4.0, depth, press_s);
}

TEST(FemPalpation, HeldPressBalancesTheCouplingAndIndentsTheWall) {
  sh::DiscPalpation p(fem_disc(), options());
  EXPECT_STREQ(p.disc().name(), "linear FEM");
  const auto [wall, n] = anterior_wall();
  p.step(wall + 10.0 * n);
  sh::DiscContact c;
  for (int k = 0; k < 400; ++k) {
    const double depth = 3.0 * std::min(1.0, k / 200.0);
    c = p.step(wall + (4.0 - depth) * n);
    ASSERT_FALSE(c.failed) << "step " << k;
  }
  ASSERT_TRUE(c.contact);
  const Vector3d device = wall + 1.0 * n;
  const Vector3d coupling = p.disc_coupling_n_per_mm() * (c.probe_mm - device);
  // Static disc, massless probe: the coupling spring and the disc's push balance.
  EXPECT_LT((coupling - c.force_n).norm(), 0.02 * c.force_n.norm())
      << "coupling " << coupling.transpose() << " disc " << c.force_n.transpose();
  EXPECT_GT(c.force_n.dot(n), 10.0);  // tens of disc newtons at 3 mm of hand travel, s = 30
  EXPECT_GT(c.indentation_mm, 0.2);   // the wall visibly gives
  EXPECT_LT(c.volume_change, 0.0);    // pressed in, the disc loses a little volume
}

TEST(FemPalpation, MultirateLocalModelFollowsTheSynchronousSolveAndIsPassive) {
  const std::vector<Vector3d> path = press_path(3.0, 0.1);  // 30 mm/s
  sh::DiscPalpationOptions sync = options();
  sh::DiscPalpationOptions multi = sync;
  multi.multirate = true;
  multi.dt_s = 10e-3;
  const auto reference = sh::palpate_offline(fem_disc, sync, path, 1e-3);
  const auto run = sh::palpate_offline(fem_disc, multi, path, 1e-3);
  const sh::ForceError e = sh::force_error(run, reference);
  std::vector<Vector3d> held(path.size(), Vector3d::Zero());
  for (std::size_t k = 1; k < path.size(); ++k) held[k] = run[k - (k - 1) % 10];
  const sh::ForceError zero_order = sh::force_error(held, reference);
  std::printf(
      "FEM disc, multirate (10 ms worker, local model at 1 kHz) vs synchronous 1 ms: peak %.2f "
      "N, RMS error %.2f %%, max %.2f %%; force held between steps: RMS %.2f %%\n",
      e.peak_n, 100 * e.relative_rms(), 100 * e.relative_max(), 100 * zero_order.relative_rms());
  EXPECT_GT(e.peak_n, 10.0);
  EXPECT_LT(e.relative_rms(), 0.05);
  EXPECT_LT(e.relative_max(), 0.15);  // the largest at the first touch, within a worker period
  EXPECT_LT(e.relative_rms(), zero_order.relative_rms());
  // Passivity. The static disc stores the hand's work and gives all of it back (it has no
  // damping of its own, unlike the mass-spring disc's implicit steps), so the felt spring, held
  // for a tick, returns a little more than it took (about k_c |dx|^2 / 2 a tick). Colgate &
  // Brown: a sampled spring k is passive with a damping b >= k T / 2 — the coupling damping the
  // run gives the FEM disc by default. Without it the loss is that small; with it, none.
  const double T = 1e-3, b = 0.5 * sync.coupling_stiffness_n_per_mm * T;
  for (const auto* forces : {&run, &reference}) {
    sh::PassivityObserver bare, damped;
    for (std::size_t k = 2; k < path.size(); ++k) {
      const Vector3d felt = (*forces)[k - 1] / multi.force_scale;
      const Vector3d v = (path[k - 1] - path[k - 2]) / T;
      const bool touching = (*forces)[k - 1].squaredNorm() > 0;
      bare.add(felt, path[k] - path[k - 1], T);
      damped.add(touching ? Vector3d(felt - b * v) : felt, path[k] - path[k - 1], T);
    }
    std::printf(
        "hand's work on the felt force: least %.5f mJ (with b = k_c T / 2: %.5f mJ), end "
        "%.5f mJ\n",
        bare.minimum_mj(), damped.minimum_mj(), bare.energy_mj());
    EXPECT_GE(damped.minimum_mj(), -1e-9);
    EXPECT_GT(bare.minimum_mj(), -0.05);  // of ~1 mJ stored at the deepest
  }
}

// At 4 mm on L4-L5: the scene's set-up builds the FEM disc on the tuned disc's mesh, measures its
// step, and its disc maker gives a fresh disc for the synchronous check.
TEST(FemPalpation, TheSceneSetsUpTheFemDiscOnTheTunedMesh) {
  DiscSceneRequest rq;
  rq.level = "L4-L5";
  rq.fixed_cell_size_mm = 4.0;
  rq.disc_model = "fem";
  const DiscSetup s = make_disc_setup(rq, kData);
  ASSERT_TRUE(s.model && s.palpation && s.make_disc);
  EXPECT_STREQ(s.palpation->disc().name(), "linear FEM");
  EXPECT_EQ(s.palpation->disc().mesh().num_tets(), s.model->mesh().num_tets());
  EXPECT_GT(s.chosen.step_us.p50, 0.0);
  EXPECT_STREQ(s.make_disc()->name(), "linear FEM");
  rq.disc_model = "hex";
  EXPECT_THROW(make_disc_setup(rq, kData), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::studies
