// One disc's calibration against the *nonlinear* FEM disc (`spinesim calibrate --nonlinear`):
// the tuned file of the mass-spring network that nonlinear_fit.hpp fits at several load levels.
//
// Why a second protocol beside protocol.hpp: that one fits the MSS linearised at rest to the
// linear FEM, which cannot see the fibres (tension-only, no stiffness at rest) nor the disc's
// stiffening with load. Here the reference is the nonlinear disc (fem/nonlinear_disc.hpp) under
// every case at every load level; the network is the region-scale network of `terms`, plus the
// embedded fibre elements when the material has fibres (mss/model.hpp), on the fibres' isochoric
// stretch by default; its switched-on knobs are fitted to the training cases at every level, the
// rest held out. The tuned file records the fit (kind "region", its report's "reference" is
// "nonlinear FEM") and the errors of the untuned (scales 1) and the tuned network on every
// (case, level), so a reader sees what the scales do at each load.
#pragma once

#include "spinesim/calibration/nonlinear_fit.hpp"
#include "spinesim/calibration/protocol.hpp"
#include "spinesim/calibration/tuned_disc.hpp"

#include <string>
#include <vector>

namespace spinesim::calibration {

struct NonlinearCalibrationRequest {
  std::vector<fem::LoadCase> train, holdout;
  std::vector<double> load_levels{0.1, 1.0};  ///< factors on the standard loads, each in (0, 2]
  int fem_order = 1;                          ///< 1: P1 nodal-average volume, 2: P2 mean dilatation
  TermSet terms = TermSet::all;
  /// The fibres on their tet's isochoric stretch J^(-2/3) I4, as the FEM (mss/elements.hpp);
  /// false: on the spring's own stretch. Only used when the material has fibres.
  bool isochoric_fibres = true;
  int load_increments = 4;  ///< Newton load steps of each FEM solve
  NonlinearFitRequest fit;  ///< train is filled from `train`; bounds, Ipopt, threads
};

struct NonlinearCalibrationOutcome {
  TunedDisc tuned;  ///< report filled; written only if `success`
  bool success = false;
  NonlinearReference reference;
  NonlinearFitResult fit;
  double total_seconds = 0;
};

/// Throws std::invalid_argument (one line) for no training case, a case both trained and held
/// out, no load level or one outside (0, 2], a FEM order other than 1 or 2, increments < 1.
void validate(const NonlinearCalibrationRequest& request);

/// The network the protocol fits on `materials`: `terms`, plus fibre elements when the material
/// has fibres.
mss::MssOptions nonlinear_network(const mesh::RegionMaterials& materials,
                                  const NonlinearCalibrationRequest& request);

/// Calibrates `mesh` with `materials` against the nonlinear FEM. Throws std::invalid_argument for
/// a bad request (validate) or a mesh without endplate labels, std::runtime_error naming the case
/// and level when a FEM solve does not converge. A failed Ipopt run is returned (success false).
NonlinearCalibrationOutcome calibrate_disc_nonlinear(const mesh::TetMesh& mesh,
                                                     const mesh::RegionMaterials& materials,
                                                     const NonlinearCalibrationRequest& request,
                                                     const StatusLine& status = StatusLine());

}  // namespace spinesim::calibration
