// The mass-spring model flags every MSS verb shares (`mss`, `mss compare`, `study probe|drive`).
#pragma once

#include "spinesim/mss/model.hpp"
#include "spinesim/mss/solver.hpp"

#include <CLI/CLI.hpp>

#include <string>

namespace spinesim::cli {

/// The flags every MSS verb shares: which energy terms, and the ambient damping.
struct ModelFlags {
  bool no_radial = false, no_torsion = false, volume_term = false, disc_volume_term = false;
  double volume_factor = mss::MssOptions().volume_factor;
  double disc_volume_factor = mss::MssOptions().disc_volume_factor;
  double damping_n_s_per_mm = -1.0;
  CLI::Option* damping_option = nullptr;
};
/// Adds --no-radial, --no-torsion, --volume-term, --disc-volume-term, their factors and
/// --damping to `cmd`.
void add_model_flags(CLI::App* cmd, ModelFlags& flags);
/// The model options they select; throws std::invalid_argument for a negative or non-finite
/// --damping or a volume factor that is not finite and > 0.
mss::MssOptions model_options(const ModelFlags& flags);
/// "radial" (thesis) or "no-radial", "+volume-term", "+disc-volume-term", "+no-torsion": the
/// variant's name for tables.
std::string model_variant(const ModelFlags& flags);

}  // namespace spinesim::cli
