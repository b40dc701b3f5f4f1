// A calibration as the program shows it: the tuned model a file gives on a mesh, and the
// readable summary of a calibration (calibration/protocol.hpp runs it).
#pragma once

#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/mss_run.hpp"

#include "spinesim/calibration/levels.hpp"
#include "spinesim/calibration/protocol.hpp"

#include <ostream>

namespace spinesim::studies {

using calibration::AllLevelsRequest;
using calibration::AllLevelsResult;
using calibration::calibrate_all_levels;
using calibration::calibrate_disc;
using calibration::CalibrationOutcome;
using calibration::CalibrationRequest;
using calibration::parse_term_set;
using calibration::StatusLine;
using calibration::term_set_name;
using calibration::term_set_options;
using calibration::TermSet;
using calibration::TransferCheck;

/// Builds the MSS for `mesh` from a tuned file, after check_applies (one-line refusal otherwise);
/// prints check_applies's note to stderr unless quiet.
mss::MssModel tuned_model(const calibration::TunedDisc& tuned, const mesh::TetMesh& mesh,
                          const mesh::RegionMaterials& materials, bool quiet);

/// Readable summary: every case untuned vs tuned (nonlinear and linear; region-only beside
/// per-spring when that stage ran), K6 diagonals, Ipopt.
void print_calibration(std::ostream& os, const CalibrationOutcome& o,
                       const CalibrationRequest& request);

/// Readable summary of a calibration against the nonlinear FEM: every (case, level) untuned
/// beside tuned (displacement and reaction), the scales, Ipopt.
void print_nonlinear_calibration(std::ostream& os,
                                 const calibration::NonlinearCalibrationOutcome& o);

/// The table of `calibrate --level all`: tets, train and held-out worst errors (untuned >
/// tuned), K6 ratio range, Ipopt iterations and time per level.
void print_all_levels(std::ostream& os, const AllLevelsResult& r, const std::string& terms,
                      double check_load_scale);

}  // namespace spinesim::studies
