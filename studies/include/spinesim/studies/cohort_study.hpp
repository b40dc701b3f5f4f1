// One level of the disc cohort (`spinesim study cohort-level`; a sweep over the levels gathers
// the cohort, data/sweeps/cohort.json): the level's parametric disc is calibrated against its FEM
// (the reference, as the spine's tuned discs are), and its tuned constants are carried to every
// other disc of that level the project can read — the disc meshed between the real vertebrae
// (ArtiSynth lumbosacral model, L1-L2 … L5-S1), the peer model's hexahedral FE disc (L1-L2 …
// L5-S1) and the parametric disc of the named bodies (p5-female, p95-male). Each is compared with
// its own FEM untuned, with the reference's constants (the MSS transfer error) and with its own
// fit, so the transfer error stands beside what a calibration of that disc gives.
//
// The external discs come from the test-data folder (studies::testdata_dir()); a member that is
// absent or cannot be meshed is listed with the reason, and the others go on.
#pragma once

#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace spinesim::studies {

struct CohortRequest {
  std::string level = "L4-L5";
  std::string material = "real-disc";  ///< preset or file (the tuned discs' material)
  double cell_size_mm = 3;             ///< CGAL cell size of the meshed discs
  std::vector<std::string> bodies = {"p5-female", "p95-male"};  ///< named bodies' discs
  bool own_fits = true;      ///< also calibrate every member on itself
  std::string testdata_dir;  ///< where artisynth-lss/ is (empty: no external discs)
};

struct CohortMember {
  std::string name;     ///< "parametric", "vertebrae", "peer", or a body's name
  std::string source;   ///< what the disc is
  std::string skipped;  ///< why it is not in the cohort (empty: it is)
  long tets = 0;
  double volume_mm3 = 0;
  /// Mean over the held-out cases of the nonlinear MSS's displacement error against this disc's
  /// own FEM (calibration/compare.hpp), with the untuned constants, the reference's tuned
  /// constants and its own fit (NaN: not run); and the same over every case.
  double untuned = 0, transfer = 0, own = 0;
  double untuned_all = 0, transfer_all = 0, own_all = 0;
  bool own_fit_converged = false;
  double seconds = 0;
};

struct CohortResult {
  CohortRequest request;
  std::vector<CohortMember> members;  ///< the reference (parametric) first
  std::vector<std::string> train, holdout;
  bool reference_converged = false;
  double seconds = 0;
};

/// Throws std::invalid_argument for an unknown level, body or material; a member that cannot be
/// built is skipped with its reason. Stages: see cohort_stages.
CohortResult run_cohort_level(const CohortRequest& request, const std::string& data_dir,
                              const StageHooks& hooks = StageHooks());
int cohort_stages(const CohortRequest& request);

nlohmann::json cohort_json(const CohortResult& r);
void print_cohort(std::ostream& os, const CohortResult& r);

}  // namespace spinesim::studies
