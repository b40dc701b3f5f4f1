// spinesim spine database — thesis 3.5's displacement–force database for the haptic loop
// (spine/database.hpp): the spine solved under 0…600 N in 50 N steps on each vertebra T1…L5
// along ±x, ±y, ±z, every vertebra's 6-DOF response fitted by least-squares polynomials, the
// compact file written, and the thesis's superposition assumption (an oblique force's response
// is the sum of its axis responses) measured against direct solves.
//
//   spinesim spine database --out data/spine/displacement_db.json      # the shipped file
//   spinesim spine database --vertebrae T1,L3 --out part.json --json   # a subset
//   spinesim spine database --check                                   # verify the shipped file
//
// --check regenerates nothing: it loads the file (--out, default the shipped one), re-solves a
// sample of grid forces and the oblique cases with the model the file names, and exits 1 when a
// grid response differs from the file by more than its stored fit residual (+ margin).
#include "cli_common.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/studies/spine_database.hpp"

#include "spinesim/spine/database.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace spinesim::cli {
namespace {
using nlohmann::json;
namespace sp = spinesim::spine;

struct DatabaseArgs {
  std::string out = "displacement_db.json", vertebrae, fusion, superposition_on = "T1,T7,L3";
  std::string magnitudes = "200,400,600", ligaments = "auto";
  CLI::Option* out_option = nullptr;
  int workers = 0;
  bool check = false, no_recruit = false, rib_cage = false, json = false, quiet = false;
};

std::vector<int> vertebra_list(const std::string& text) {
  std::vector<int> out;
  for (const auto& name : split_list(text)) out.push_back(sp::vertebra_index(name));
  return out;
}

sp::SolveOptions solve_options(bool recruit) {
  sp::SolveOptions o;
  o.recruit = recruit;
  return o;
}

std::vector<double> magnitudes(const DatabaseArgs& a) {
  const Eigen::VectorXd m =
      parse_numbers(a.magnitudes, int(split_list(a.magnitudes).size()), "--magnitudes");
  if (m.size() == 0 || m.minCoeff() <= 0)
    throw std::invalid_argument("--magnitudes: give forces > 0 N");
  return std::vector<double>(m.data(), m.data() + m.size());
}

/// Everything a long run could trip over at its end, refused before it starts.
void validate(const DatabaseArgs& a) {
  if (a.workers < 0) throw std::invalid_argument("--workers must be >= 0");
  vertebra_list(a.vertebrae);
  if (vertebra_list(a.superposition_on).empty())
    throw std::invalid_argument("--superposition-on: no vertebra given");
  magnitudes(a);
  if (!a.fusion.empty()) sp::parse_fusion(a.fusion);
  if (a.check &&
      (!a.fusion.empty() || a.ligaments != DatabaseArgs().ligaments || a.rib_cage || a.no_recruit))
    throw std::invalid_argument(
        "--check solves the file's own model: --fusion, --ligaments, --rib-cage and --no-recruit "
        "are for generating a file");
  if (!a.check) {
    const auto dir = std::filesystem::absolute(a.out).parent_path();
    if (!std::filesystem::is_directory(dir))
      throw std::invalid_argument("--out: no folder " + dir.string());
  }
}

// --- generate --------------------------------------------------------------------------------

std::string command_line(const DatabaseArgs& a) {
  std::string c = "spinesim spine database --out " + a.out;
  if (!a.vertebrae.empty()) c += " --vertebrae " + a.vertebrae;
  if (!a.fusion.empty()) c += " --fusion " + a.fusion;
  if (a.ligaments != DatabaseArgs().ligaments) c += " --ligaments " + a.ligaments;
  if (a.no_recruit) c += " --no-recruit";
  if (a.rib_cage) c += " --rib-cage";
  if (a.superposition_on != DatabaseArgs().superposition_on)
    c += " --superposition-on " + a.superposition_on;
  if (a.magnitudes != DatabaseArgs().magnitudes) c += " --magnitudes " + a.magnitudes;
  return c;
}

/// Stage hooks that also close the solves' progress bar before each stage's line.
StageHooks hooks_with_bar(Progress& progress, ProgressBar& bar) {
  StageHooks h = progress.hooks();
  h.begin = [&progress, &bar](const std::string& what) {
    bar.finish();
    progress.begin(what);
  };
  h.end = [&progress, &bar](const std::string& detail) {
    bar.finish();
    progress.end(detail);
  };
  return h;
}

void run_generate(const DatabaseArgs& a) {
  const Timer t0;
  DatabaseRequest rq;
  if (!a.fusion.empty()) rq.model.fused_joints = sp::parse_fusion(a.fusion);
  rq.model.ligaments = sp::parse_ligaments(a.ligaments);
  rq.model.rib_cage = a.rib_cage;
  rq.solve = solve_options(!a.no_recruit);
  rq.loaded_vertebrae = vertebra_list(a.vertebrae);
  rq.workers = a.workers;
  rq.superposition_on = vertebra_list(a.superposition_on);
  rq.magnitudes_n = magnitudes(a);
  rq.generated_by = command_line(a);

  // 1. Solves, fits and the superposition check (studies/spine_database.hpp).
  Progress progress(4, a.quiet);
  ProgressBar solves(0, progress.quiet(), "solves");
  const DatabaseBuild b =
      generate_database(data_dir(), rq, hooks_with_bar(progress, solves), solves.callback());

  // 2. The file, then the report (re-read from the file, so what is printed is what was written).
  progress.begin("writing " + a.out);
  b.db.save(a.out);
  progress.end();
  std::ifstream in(a.out);
  json file = json::parse(in);
  if (a.json) {
    file.erase("fits");
    file.erase("baseline");
    file["file"] = a.out;
    file["bytes"] = std::filesystem::file_size(a.out);
    file["total_seconds"] = t0.seconds();
    print_json(file);
    return;
  }
  print_database_build(std::cout, b);
  std::cout << "Wrote " << a.out << " (" << std::filesystem::file_size(a.out) / 1024
            << " KiB), total " << fixed(t0.seconds(), 1) << " s\n";
}

void run_check(const DatabaseArgs& a) {
  const std::string path =
      a.out_option->count() ? a.out : data_dir() + "/spine/displacement_db.json";
  Progress progress(3, a.quiet);
  ProgressBar solves(0, progress.quiet(), "solves");
  const DatabaseCheck c =
      check_database(data_dir(), path, vertebra_list(a.superposition_on), magnitudes(a), a.workers,
                     hooks_with_bar(progress, solves), solves.callback());
  if (a.json)
    print_json(database_check_json(c));
  else
    print_database_check(std::cout, c);
  if (!c.ok)
    throw std::runtime_error(
        path + " does not match the model: re-solved responses differ beyond the fit residuals");
}

}  // namespace

void register_spine_database(CLI::App& spine) {
  auto a = std::make_shared<DatabaseArgs>();
  auto* cmd = spine.add_subcommand("database",
                                   "Thesis 3.5 displacement-force database: solve, fit, write; "
                                   "measure the superposition assumption");
  a->out_option = cmd->add_option("--out", a->out,
                                  "Database file (JSON); with --check the file checked "
                                  "(default there: data/spine/displacement_db.json)")
                      ->capture_default_str();
  cmd->add_flag("--check", a->check,
                "Verify an existing file against direct solves instead of generating one");
  cmd->add_option("--vertebrae", a->vertebrae, "Loaded vertebrae, e.g. T1,L3 (default: T1…L5)");
  cmd->add_option("--fusion", a->fusion, "Fused levels of the model, e.g. L3-L4,L4-L5");
  add_ligaments_option(cmd, a->ligaments);
  add_rib_cage_option(cmd, a->rib_cage);
  cmd->add_flag("--no-recruit", a->no_recruit, "Muscles off (passive spine)");
  cmd->add_option("--superposition-on", a->superposition_on,
                  "Vertebrae loaded by the oblique forces")
      ->capture_default_str();
  cmd->add_option("--magnitudes", a->magnitudes, "Oblique force magnitudes, N")
      ->capture_default_str();
  cmd->add_option("--workers", a->workers, "Solver threads (0: one per core)")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "One JSON object on stdout (the file's metadata, or the check)");
  cmd->add_flag("--quiet", a->quiet, "No progress on stderr");
  cmd->callback([a] {
    validate(*a);
    if (a->check)
      run_check(*a);
    else
      run_generate(*a);
  });
}

}  // namespace spinesim::cli
