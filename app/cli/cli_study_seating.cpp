// spinesim study seating | seating-sweep | seating-validation — the spine in a chair.
//
//   spinesim study seating [--backrest-recline DEG] [--lumbar-support MM] [--seat-angle DEG]
//       [--pelvic-tilt DEG] [--chair chair.stl] [--armrests] [--csv FILE] [--json] [--out DIR]
//   spinesim study seating-sweep --parameter backrest-recline --values 90,100,110,120 [...]
//   spinesim study seating-validation [--csv FILE] [--json]
#include "cli_common.hpp"
#include "spinesim/output/html_report.hpp"
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace spinesim::cli {
namespace {
namespace fs = std::filesystem;

struct SeatingArgs {
  SeatingRequest request;
  double pelvic_tilt_deg = NAN;
  std::string chair_file, csv, out, parameter, values, ligaments = "auto";
  bool json = false, quiet = false, markdown = false, no_trunk_muscles = false, rib_cage = false;
  SubjectFlags subject;
};

void add_chair_options(CLI::App* cmd, SeatingArgs& a) {
  spine::Chair& c = a.request.chair;
  cmd->add_option("--backrest-recline", c.backrest_recline_deg,
                  "Backrest angle to the horizontal behind the sitter, deg (90: upright)")
      ->capture_default_str();
  cmd->add_option("--backrest-height", c.backrest_height_mm,
                  "Backrest length from the seat, mm (0: a stool)")
      ->capture_default_str();
  cmd->add_option("--lumbar-support", c.lumbar_support_mm, "Lumbar pad depth, mm (0: none)")
      ->capture_default_str();
  cmd->add_option("--lumbar-height", c.lumbar_support_height_mm,
                  "Lumbar pad centre above the seat along the backrest, mm")
      ->capture_default_str();
  cmd->add_option("--seat-angle", c.seat_angle_deg, "Seat pan angle, deg (+: front edge up)")
      ->capture_default_str();
  cmd->add_flag("--armrests", c.armrests, "Forearms resting on armrests");
  cmd->add_option("--pelvic-tilt", a.pelvic_tilt_deg,
                  "Posterior pelvic tilt from standing, deg (default: data/spine/seating.json, "
                  "Endo et al. 2012: 18.3)");
  cmd->add_option("--chair", a.chair_file,
                  "Backrest surface (STL, OBJ, OFF or PLY; mm; chair frame: origin where seat and "
                  "backrest meet, y up, z forward; normals towards the sitter) in place of the "
                  "parametric backrest");
  cmd->add_flag("--no-trunk-muscles", a.no_trunk_muscles,
                "Lumbar muscles F.8-F.19 only (no thoracic erector spinae, no rectus abdominis)");
  add_ligaments_option(cmd, a.ligaments);
  add_rib_cage_option(cmd, a.rib_cage);
  add_subject_options(cmd, a.subject);
  cmd->add_option("--csv", a.csv, "Write the results as CSV");
  cmd->add_option("--out", a.out, "Write JSON, CSV, plots and report.html into this folder");
  cmd->add_flag("--markdown", a.markdown, "Print the tables as markdown");
  add_output_flags(cmd, a.json, a.quiet, "the JSON results");
}

/// Every option checked before any work.
void resolve(SeatingArgs& a) {
  if (!std::isnan(a.pelvic_tilt_deg)) a.request.pelvic_tilt_deg = a.pelvic_tilt_deg;
  a.request.model.trunk_muscles = !a.no_trunk_muscles;
  a.request.model.ligaments = spine::parse_ligaments(a.ligaments);
  a.request.model.rib_cage = a.rib_cage;
  a.request.model.subject = spine::resolve_subject(data_dir(), subject_of(a.subject));
  spine::check_chair(a.request.chair);
  if (!a.chair_file.empty()) {
    a.request.chair.surface = read_chair_surface(a.chair_file);
    a.request.chair.surface_name = a.chair_file;
  }
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");
  if (!a.out.empty()) prepare_output_folder(a.out, "--out");
}

/// --csv, --out (the JSON and CSV, then the plots and report.html: scripts/seating_report.py) and
/// --json; true when the JSON went to stdout (nothing else is printed then).
bool emit(const SeatingArgs& a, const nlohmann::json& j, const std::string& csv,
          const std::string& stem) {
  if (!a.csv.empty()) write_csv_file(a.csv, csv);
  if (!a.out.empty()) {
    write_json_file((fs::path(a.out) / (stem + ".json")).string(), j);
    write_csv_file((fs::path(a.out) / (stem + ".csv")).string(), csv);
    const HtmlReport r = write_html_report(a.out, "seating_report.py");
    if (r.failed) throw std::runtime_error("--out " + a.out + ": " + r.message);
    std::cerr << (r.written ? "" : "spinesim: warning: ") << r.message << std::endl;
  }
  if (a.json) print_json(j);
  return a.json;
}

void run_one(SeatingArgs& a) {
  resolve(a);
  Progress progress(1, a.quiet || a.json);
  progress.begin("seating the spine");
  const SeatingRun run = run_seating(data_dir(), a.request);
  progress.end(std::to_string(run.seated.solves) + " equilibria");
  if (emit(a, seating_json(run), seating_csv(run), "seating")) return;
  std::cout << "The spine seated in a chair (thesis 6.2)\n\n";
  print_seating(std::cout, run, a.markdown);
}

void run_sweep(SeatingArgs& a) {
  const std::vector<double> values = parse_number_list(a.values, "--values");
  with_parameter(a.request, a.parameter, values.front());  // an unknown name fails here
  resolve(a);
  Progress progress(int(values.size()), a.quiet || a.json);
  const SeatingSweep s =
      run_seating_sweep(data_dir(), a.parameter, values, a.request, progress.hooks());
  if (emit(a, seating_sweep_json(s), seating_sweep_csv(s), "seating_sweep")) return;
  std::cout << "Chair-design sweep over " << a.parameter << " (thesis 6.2)\n\n";
  print_seating_sweep(std::cout, s, a.markdown);
  std::cout << "Total " << fixed(s.seconds, 2) << " s\n";
}

void run_validation(SeatingArgs& a) {
  a.request.model.trunk_muscles = !a.no_trunk_muscles;
  a.request.model.ligaments = spine::parse_ligaments(a.ligaments);
  a.request.model.rib_cage = a.rib_cage;
  a.request.model.subject = spine::resolve_subject(data_dir(), subject_of(a.subject));
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");
  Progress progress(kSittingValidationStages, a.quiet || a.json);
  const SittingValidation v = run_sitting_validation(data_dir(), a.request.model, progress.hooks());
  if (!a.csv.empty()) write_csv_file(a.csv, sitting_validation_csv(v));
  if (a.json) {
    print_json(sitting_validation_json(v));
    return;
  }
  std::cout << "The standing and seated spine beside in-vivo L4-L5 disc loads "
               "(data/validation/sitting_in_vivo.json)\n\n";
  print_sitting_validation(std::cout, v, a.markdown);
  std::cout << "Total " << fixed(v.seconds, 2) << " s\n";
}

const char* const kFooter =
    "The standing model (spine solve) seated: pelvis tilted back and lumbar lordosis flattened as "
    "measured\n"
    "(data/spine/seating.json), gravity turned with the pelvis, the back's points (behind each "
    "spinous process\n"
    "by the soft tissue) pressing on the backrest through the tissue's stiffness. Muscles are "
    "recruited in the\n"
    "seated posture with the contact forces, iterated until they agree; the body then leans back "
    "about the\n"
    "ischia until the backrest balances it. Forces on the body in the chair's axes (y up, z "
    "forward); L5-S1 and\n"
    "the discs in the lower vertebra's axes. docs/seating.md.";

}  // namespace

void register_seating(CLI::App& study) {
  auto a = std::make_shared<SeatingArgs>();
  auto* cmd = study.add_subcommand(
      "seating", "The spine in a chair: back-chair contact, L5-S1 and disc loads (thesis 6.2)");
  add_chair_options(cmd, *a);
  cmd->footer(kFooter);
  cmd->callback([a] { run_one(*a); });

  auto s = std::make_shared<SeatingArgs>();
  auto* sweep = study.add_subcommand(
      "seating-sweep", "One chair parameter swept: L4-L5 and L5-S1 compression, back muscles");
  sweep
      ->add_option("--parameter", s->parameter,
                   "backrest-recline, lumbar-support, seat-angle, backrest-height or pelvic-tilt")
      ->required();
  sweep->add_option("--values", s->values, "Comma-separated values, e.g. 90,100,110,120")
      ->required();
  add_chair_options(sweep, *s);
  sweep->footer(std::string(kFooter) +
                "\nThe other parameters keep their values (flags or defaults); trends the "
                "literature states for the\nswept parameter (sitting_in_vivo.json) are checked: "
                "MATCH / DIFFERS.");
  sweep->callback([s] { run_sweep(*s); });

  auto v = std::make_shared<SeatingArgs>();
  auto* val = study.add_subcommand(
      "seating-validation",
      "Standing and seated L4-L5 loads and the chair trends beside in-vivo data (MATCH / DIFFERS)");
  val->add_option("--csv", v->csv, "Write the comparison as CSV");
  val->add_flag("--no-trunk-muscles", v->no_trunk_muscles, "Lumbar muscles F.8-F.19 only");
  add_ligaments_option(val, v->ligaments);
  add_rib_cage_option(val, v->rib_cage);
  add_subject_options(val, v->subject);
  add_output_flags(val, v->json, v->quiet, "the JSON comparison");
  val->callback([v] { run_validation(*v); });
}

}  // namespace spinesim::cli
