// spinesim study cohort-level — one level of the disc cohort (studies/cohort_study.hpp): the
// parametric disc calibrated, its constants carried to the level's other discs (real vertebrae,
// the peer's FE disc, the named bodies' discs), each beside its own fit. A sweep over the levels
// (data/sweeps/cohort.json) is the cohort.
//
//   spinesim study cohort-level [--level L4-L5] [--material real-disc] [--cell-size 3]
//       [--bodies p5-female,p95-male] [--no-own-fits] [--json] [--quiet]
#include "cli_common.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/studies/cohort_study.hpp"

#include <cmath>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct CohortArgs {
  studies::CohortRequest request;
  std::string bodies = "p5-female,p95-male";
  bool no_own_fits = false, json = false, quiet = false;
};

void run_cohort(const CohortArgs& a) {
  studies::CohortRequest rq = a.request;
  mesh::disc_dimensions(rq.level, data_dir());  // an unknown level, before any work
  if (!std::isfinite(rq.cell_size_mm) || rq.cell_size_mm <= 0 || rq.cell_size_mm > 20)
    throw std::invalid_argument("--cell-size must be a number within 0 … 20 mm");
  rq.bodies = a.bodies == "none" ? std::vector<std::string>() : split_list(a.bodies);
  rq.own_fits = !a.no_own_fits;
  rq.testdata_dir = testdata_dir();
  Progress progress(studies::cohort_stages(rq), a.quiet || a.json);
  const studies::CohortResult r = studies::run_cohort_level(rq, data_dir(), progress.hooks());
  if (a.json)
    print_json(studies::cohort_json(r));
  else
    studies::print_cohort(std::cout, r);
  if (!r.reference_converged)
    throw std::runtime_error("the parametric disc's calibration did not converge");
}

}  // namespace

void register_cohort_level(CLI::App& study) {
  auto a = std::make_shared<CohortArgs>();
  auto* cmd = study.add_subcommand(
      "cohort-level",
      "One level of the disc cohort: the parametric disc calibrated, its constants carried to the "
      "level's other discs (real vertebrae, the peer's FE disc, other bodies), the MSS transfer "
      "error beside each disc's own fit");
  cmd->add_option("--level", a->request.level, "Disc level T1-T2 … L5-S1")->capture_default_str();
  cmd->add_option("--material", a->request.material, "Preset or JSON file")->capture_default_str();
  cmd->add_option("--cell-size", a->request.cell_size_mm, "Cell size of the meshed discs, mm")
      ->capture_default_str();
  cmd->add_option("--bodies", a->bodies,
                  "Named bodies whose parametric discs join the cohort (comma list, or none)")
      ->capture_default_str();
  cmd->add_flag("--no-own-fits", a->no_own_fits,
                "Only the parametric disc is calibrated (the transfer errors alone)");
  add_output_flags(cmd, a->json, a->quiet, "the JSON summary");
  cmd->footer(
      "Members: the parametric disc (the reference); for L1-L2 … L5-S1 the disc meshed between "
      "the\n"
      "real vertebral bodies and the peer model's FE disc (from the test-data folder, skipped "
      "with\n"
      "the reason when absent); the named bodies' parametric discs. Calibration as `spinesim\n"
      "calibrate` (train compression, shear-ap, flexion, torsion; the other cases held out).\n"
      "Error: the nonlinear MSS's displacement error against the disc's own FEM at 0.1 x the\n"
      "standard loads, mean over the held-out cases. A sweep: data/sweeps/cohort.json.");
  cmd->callback([a] { run_cohort(*a); });
}

}  // namespace spinesim::cli
