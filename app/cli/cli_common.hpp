// Shared pieces of the `spinesim` command line: value parsing with clear errors and the verbs'
// registration. Everything else a verb needs (drivers, reports, tables, progress, files) is in
// the studies library (spinesim/studies/).
#pragma once

#include "flag_values.hpp"

#include "spinesim/haptics/scene_builder.hpp"
#include "spinesim/output/files.hpp"
#include "spinesim/output/format.hpp"
#include "spinesim/output/json.hpp"
#include "spinesim/output/progress.hpp"
#include "spinesim/output/table.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/data.hpp"
#include "spinesim/studies/haptics_run.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace spinesim::cli {

using namespace spinesim::studies;  // the command line is a thin layer over the studies library

/// Every number-valued flag of `app` and its sub-commands read as every number is
/// (spinesim/common/numbers.hpp): "nan", "", "0x10" or "1,5" are refused, not read as the
/// default, 0, 16 or 1.
void require_plain_numbers(CLI::App& app);

/// --json (one JSON object on stdout; `what` says which) and --quiet (no progress on stderr).
void add_output_flags(CLI::App* cmd, bool& json, bool& quiet,
                      const std::string& what = "a JSON summary");

/// --height, --mass, --sex, or --subject NAME (a sourced body, spine::named_body): the body the
/// spine belongs to (spine::Subject; 0: the reference body's).
struct SubjectFlags {
  double height_m = 0, mass_kg = 0;
  std::string sex = "male", named;
  bool given() const { return height_m != 0 || mass_kg != 0 || sex != "male" || !named.empty(); }
};
void add_subject_options(CLI::App* cmd, SubjectFlags& flags);
/// --subject alone (`instead_of` names the flags it replaces, for the help).
void add_named_subject_option(CLI::App* cmd, SubjectFlags& flags, const std::string& instead_of);
spine::Subject subject_of(const SubjectFlags& flags);

/// --ligaments auto|on|off (spine::Ligaments, read with spine::parse_ligaments) on the spine verbs.
void add_ligaments_option(CLI::App* cmd, std::string& ligaments);
/// --rib-cage (spine::ModelOptions::rib_cage) on the spine verbs.
void add_rib_cage_option(CLI::App* cmd, bool& rib_cage);

/// A scoliotic spine (spine/scoliosis.hpp): --scoliosis TYPE --cobb DEG [--apex V]
/// [--curve-ends U,L] [--apical-rotation DEG] [--convex right|left].
/// The spine model's uncertain inputs (spine::ModelOptions muscle_strength, joint_stiffness,
/// ligament_stiffness, inclination_deg), for sensitivity sweeps.
struct ModelInputFlags {
  double muscle_strength = 1, joint_stiffness = 1, ligament_stiffness = 1, inclination_deg = 0;
};
void add_model_input_options(CLI::App* cmd, ModelInputFlags& f);
/// Copies the flags into `o` and checks them (std::invalid_argument naming the option).
void apply_model_inputs(const ModelInputFlags& f, spine::ModelOptions& o);

struct ScoliosisFlags {
  std::string type, apex, ends, convex;
  double cobb_deg = 0, apical_rotation_deg = 0;
};
void add_scoliosis_options(CLI::App* cmd, ScoliosisFlags& flags);
/// The curve the flags describe (cobb_deg 0: none); std::invalid_argument (one line) for a flag
/// without --scoliosis or a bad value.
spine::ScoliosisCurve scoliosis_of(const ScoliosisFlags& flags);

/// The plate load options of `fem` and `mss`: --motion, --wrench, --case, --center.
void add_plate_load_options(CLI::App* cmd, std::string& motion, std::string& wrench,
                            std::string& load_case, std::string& center);

/// The whole command line: every verb registered, --save-study on each, --version (cli_app.cpp).
/// `spinesim run` builds a second one for the study it runs.
std::unique_ptr<CLI::App> make_app();

// Sub-command registration; each lives in its own cli_<verb>.cpp.
void register_mesh(CLI::App& app);
void register_mesh_vertebrae(CLI::App& mesh);  ///< mesh vertebrae, under `mesh`
void register_mesh_import(CLI::App& mesh);     ///< mesh import, under `mesh` (cli_mesh.cpp)
void register_fem(CLI::App& app);
void register_sweep(CLI::App& app);   ///< sweep PLAN: many studies on MPI, Slurm or here
void register_export(CLI::App& app);  ///< in cli_fem.cpp: the fem problem for other solvers
void register_mss(CLI::App& app);        ///< mss, mss compare (cli_mss.cpp)
void register_calibrate(CLI::App& app);  ///< calibrate (cli_calibrate.cpp)
void register_study(
    CLI::App& app);  ///< study probe|drive|materials|validation|fusion|trends (cli_study.cpp)
void register_spine(CLI::App& app);              ///< spine solve (cli_spine.cpp)
void register_haptics(CLI::App& app);            ///< haptics run|devices (cli_haptics.cpp)
void register_haptic_plane(CLI::App& study);     ///< study haptic-plane (cli_haptics.cpp)
void register_haptic_drag(CLI::App& study);      ///< study haptic-drag (cli_haptics.cpp)
void register_disc_validation(CLI::App& study);  ///< study disc-validation (cli_study_disc.cpp)
void register_disc_identify(CLI::App& study);    ///< study disc-identify (cli_study_identify.cpp)
void register_mss_fibres(CLI::App& study);       ///< study mss-fibres (cli_study_mss_fibres.cpp)
void register_cohort_level(CLI::App& study);     ///< study cohort-level (cli_study_cohort.cpp)
void register_seating(CLI::App& study);          ///< study seating|seating-sweep|seating-validation
void register_demo(CLI::App& app);
void register_view(CLI::App& app);
void register_run(CLI::App& app);  ///< run STUDY, run --schema (cli_run.cpp)

/// --scene, --vertebrae, --testdata, --triangles: the haptic scene's flags (haptics run, view).
void add_scene_flags(CLI::App* cmd, haptics::HapticSceneRequest& scene);

/// A haptic session's flags (scene, disc, device, renderer, compliant stage …), shared by
/// `haptics run` and `view` (`viewer`: the help names the mouse device).
struct HapticsRunFlags {
  studies::HapticsRunRequest request;
  std::string workspace_center, chair_file;
  ScoliosisFlags scoliosis;
  SubjectFlags body;  ///< --body-height, --body-mass, --sex (view's --height is the window's)
  bool no_realtime = false;
  bool no_floor = false;
  /// A run that misses more than this share of its deadlines ends with a warning (--strict: an
  /// error, exit status 1).
  double max_missed_percent = 1.0;
  bool strict = false;
};
void add_haptics_run_flags(CLI::App* cmd, HapticsRunFlags& flags, bool viewer);
/// After parsing: --workspace-center, --no-realtime and the test-data folder into the request.
void resolve_haptics_run_flags(HapticsRunFlags& flags);
void register_bench(CLI::App& app);
void register_spine_database(
    CLI::App& spine);  ///< spine database, under `spine` (cli_spine_database.cpp)
void register_spine_disc_joints(
    CLI::App& spine);                        ///< spine disc-joints (cli_spine_disc_joints.cpp)
void register_spine_discs(CLI::App& spine);  ///< spine discs, under `spine` (cli_spine_discs.cpp)
void register_spine_schedule(CLI::App& spine);  ///< spine schedule (cli_spine_schedule.cpp)

}  // namespace spinesim::cli
