// spinesim sweep PLAN --out DIR: a sweep plan's points (studies/sweep_plan.hpp) run as studies,
// each in its own folder DIR/points/NNNN (study.json, result.json: its --json, log.txt: its
// stderr, status.json: ok or failed and why), on MPI ranks, Slurm array tasks or one process
// (sweep_world.hpp); then DIR/summary.csv and DIR/summary.json gather them. A point is done when
// its status.json exists (written last, by rename), so the same command again resumes a killed
// sweep and never runs a finished point twice.
#include "cli_common.hpp"
#include "study_file.hpp"
#include "sweep_tables.hpp"
#include "sweep_world.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/common/provenance.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/output/html_report.hpp"
#include "spinesim/studies/sweep_plan.hpp"
#include "spinesim/studies/uncertainty.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>

namespace spinesim::cli {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

struct SweepArgs {
  std::string plan, out;
  bool retry_failed = false, dry_run = false, json = false, quiet = false, no_report = false;
  int jobs = 1;  ///< points at once in this process (0: one per core)
};

struct Sweep {
  studies::SweepPlan plan;
  std::vector<studies::SweepPoint> points;
  std::vector<json> studies;  ///< per point, as written into its folder
  std::string plan_path, plan_sha256;
  fs::path out;
};

std::string point_folder_name(int index, std::size_t count) {
  const int width = std::max(4, int(std::to_string(count > 0 ? count - 1 : 0).size()));
  std::string s = std::to_string(index);
  return "points/" + std::string(std::size_t(std::max(0, width - int(s.size()))), '0') + s;
}

/// The plan read, expanded and every point's study checked (its verb and options, as `run` would
/// read them) before anything is run or written.
Sweep read_sweep(const SweepArgs& a) {
  Sweep s;
  s.plan_path = a.plan;
  const std::string where = "sweep plan '" + a.plan + "'";
  s.plan = studies::parse_sweep_plan(read_json_file(a.plan, "sweep plan"), where);
  s.plan_sha256 = sha256_of_file(a.plan);
  s.points = studies::expand_sweep(s.plan);
  s.out = fs::absolute(a.out).lexically_normal();
  const fs::path plan_dir = fs::absolute(a.plan).parent_path();
  const std::unique_ptr<CLI::App> app = make_app();
  for (const auto& p : s.points) {
    const fs::path folder = s.out / point_folder_name(p.index, s.points.size());
    json study = rebase_study_inputs(*app, studies::point_study(s.plan, p), plan_dir.string(),
                                     folder.string());
    study_arguments(*app, study, where + ", point " + std::to_string(p.index));
    s.studies.push_back(std::move(study));
  }
  return s;
}

void write_atomically(const fs::path& path, const std::string& text) {
  const fs::path part = path.string() + ".part";
  {
    std::ofstream o(part);
    o << text;
    if (!o) throw std::runtime_error("cannot write " + part.string());
  }
  fs::rename(part, path);
}

/// DIR/plan.json: the plan this folder holds. Another plan's folder is refused.
void claim_folder(const Sweep& s) {
  fs::create_directories(s.out / "points");
  const fs::path mark = s.out / "plan.json";
  const json here = {{"plan", s.plan_path}, {"sha256", s.plan_sha256}, {"points", s.points.size()}};
  if (fs::exists(mark)) {
    const json there = read_json_file(mark.string(), "sweep folder's plan record");
    if (there.value("sha256", "") != s.plan_sha256)
      throw std::invalid_argument("--out " + s.out.string() + " holds another plan's sweep (" +
                                  there.value("plan", std::string("?")) + "): give a new folder");
    return;
  }
  write_atomically(mark, here.dump(2) + "\n");
}

/// The last non-empty line of a file (a failed point's error).
std::string last_line(const fs::path& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

/// A point's status.json ({} when it has none yet).
json read_status(const fs::path& folder) {
  const fs::path p = folder / "status.json";
  std::error_code ec;
  if (!fs::exists(p, ec)) return json::object();
  return read_json_file(p.string(), "point status");
}

/// Starts point i in its folder: a child `spinesim run study.json --json`; returns its pid.
int start_point(const Sweep& s, std::size_t i) {
  const fs::path folder = s.out / point_folder_name(int(i), s.points.size());
  fs::remove_all(folder);  // a point killed before its status: run afresh
  fs::create_directories(folder);
  write_atomically(folder / "study.json", s.studies[i].dump(2) + "\n");
  return start_child({own_executable(), "run", "study.json", "--json"}, folder.string(),
                     (folder / "result.json").string(), (folder / "log.txt").string());
}

/// Point i's status, written last: the point is done.
void finish_point(const Sweep& s, std::size_t i, int code, double seconds) {
  const fs::path folder = s.out / point_folder_name(int(i), s.points.size());
  json status = {{"point", i}, {"exit_code", code}, {"seconds", seconds}};
  status["status"] = code == 0 ? "ok" : "failed";
  if (code != 0) status["error"] = last_line(folder / "log.txt");
  write_atomically(folder / "status.json", status.dump(2) + "\n");
}

/// The summary: one row per point, its values, status and outputs. Its provenance names the
/// program and the plan (not the command or the folder), so every way of running the same plan
/// writes the same bytes.
json gather(const Sweep& s) {
  json rows = json::array();
  std::vector<json> outputs;  // per point, for the sensitivity
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const fs::path folder = s.out / point_folder_name(int(i), s.points.size());
    const json status = read_status(folder);
    json row = {
        {"point", i}, {"values", s.points[i].values}, {"status", status.value("status", "")}};
    if (status.value("status", "") == "ok") {
      const json result = read_json_file((folder / "result.json").string(), "point result");
      row["outputs"] = studies::point_outputs(s.plan, result);
    } else {
      row["error"] = status.value("error", "");
    }
    outputs.push_back(row.value("outputs", json()));
    rows.push_back(row);
  }
  return {{"plan", fs::path(s.plan_path).filename().string()},
          {"verb", s.plan.verb},
          {"points", rows},
          {"sensitivity", studies::sweep_sensitivity(s.plan, s.points, outputs)},
          {"uncertainty", studies::sweep_uncertainty(s.plan, s.points, outputs)},
          {"provenance",
           {{"program", "spinesim"},
            {"version", build_version()},
            {"commit", build_commit()},
            {"plan_sha256", s.plan_sha256}}}};
}

void write_summary(const Sweep& s, const json& summary) {
  std::ostringstream csv;
  csv << "# provenance: " << summary["provenance"].dump() << "\n";
  csv << "point";
  for (const auto& p : s.plan.parameters) csv << "," << csv_cell(p.option);
  csv << ",status";
  for (const auto& o : s.plan.outputs) csv << "," << csv_cell(o.first);
  csv << ",error\n";
  for (const auto& row : summary["points"]) {
    csv << row["point"].get<int>();
    for (const auto& p : s.plan.parameters) csv << "," << csv_cell(row["values"][p.option]);
    csv << "," << row["status"].get<std::string>();
    for (const auto& o : s.plan.outputs)
      csv << "," << (row.contains("outputs") ? csv_cell(row["outputs"][o.first]) : "");
    csv << "," << csv_cell(row.value("error", json()));
    csv << "\n";
  }
  write_atomically(s.out / "summary.csv", csv.str());
  write_atomically(s.out / "summary.json", summary.dump(2) + "\n");
  if (!summary["sensitivity"].is_null())
    write_atomically(s.out / "sensitivity.csv", sensitivity_csv(s.plan, summary));
  if (!summary["uncertainty"].is_null())
    write_atomically(s.out / "uncertainty.csv", uncertainty_csv(s.plan, summary));
}

struct Tally {
  int ran = 0, skipped = 0, ok = 0, failed = 0, pending = 0;
  bool stopped = false;
  std::vector<double> point_seconds;  ///< each done point's own time (its status.json)
};

/// This process's points (i mod size == rank), `jobs` at a time. A point ends with its status,
/// unless this process was asked to stop: then the running points are stopped and left without
/// one, to run again.
Tally run_my_points(const Sweep& s, const SweepWorld& w, const SweepArgs& a) {
  using Clock = std::chrono::steady_clock;
  Tally t;
  std::vector<std::size_t> mine;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (int(i % std::size_t(w.size)) == w.rank) mine.push_back(i);
  ProgressBar bar(int(mine.size()), a.quiet || a.json || w.rank != 0, "points");
  std::map<int, std::pair<std::size_t, Clock::time_point>> running;  // pid: point, start
  int done = 0;
  auto reap = [&] {
    const auto [pid, code] = wait_child(-1);
    const auto it = running.find(pid);
    if (it == running.end()) return;
    if (!stop_requested()) {
      finish_point(s, it->second.first, code,
                   std::chrono::duration<double>(Clock::now() - it->second.second).count());
      ++t.ran;
      bar.update(++done, "point " + std::to_string(it->second.first));
    }
    running.erase(it);
  };
  for (const std::size_t i : mine) {
    const json status = read_status(s.out / point_folder_name(int(i), s.points.size()));
    const bool again = status.value("status", "") == "failed" && a.retry_failed;
    if (!status.empty() && !again) {
      ++t.skipped;
      bar.update(++done);
      continue;
    }
    while (int(running.size()) >= a.jobs && !stop_requested()) reap();
    if (stop_requested()) break;
    running[start_point(s, i)] = {i, Clock::now()};
  }
  while (!running.empty()) reap();
  t.stopped = stop_requested();
  return t;
}

void count(const Sweep& s, Tally& t) {
  t.ok = t.failed = t.pending = 0;
  t.point_seconds.clear();
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const json status = read_status(s.out / point_folder_name(int(i), s.points.size()));
    const std::string st = status.value("status", "");
    (st == "ok" ? t.ok : st == "failed" ? t.failed : t.pending)++;
    if (!st.empty()) t.point_seconds.push_back(status.value("seconds", 0.0));
  }
}

/// The wall time of the done points' measured costs on `ranks` ranks, each running the points
/// i mod ranks in turn as `spinesim sweep` deals them (the slowest rank's sum), s.
double projected_seconds(const std::vector<double>& seconds, int ranks) {
  std::vector<double> sum(std::size_t(ranks), 0.0);
  for (std::size_t i = 0; i < seconds.size(); ++i) sum[i % std::size_t(ranks)] += seconds[i];
  return *std::max_element(sum.begin(), sum.end());
}

json timing_json(const Tally& t) {
  double total = 0;
  for (double v : t.point_seconds) total += v;
  json projected = json::object();
  for (int ranks : {1, 2, 64, 512})
    projected[std::to_string(ranks)] = projected_seconds(t.point_seconds, ranks);
  return {{"points_timed", t.point_seconds.size()},
          {"point_seconds_sum", total},
          {"mean_point_seconds",
           t.point_seconds.empty() ? 0.0 : total / double(t.point_seconds.size())},
          {"projected_wall_seconds_by_ranks", projected}};
}

void print_dry_run(const Sweep& s, const SweepWorld& w) {
  std::cout << s.points.size() << " points of " << s.plan.verb << " (" << s.plan.design << "), "
            << w.kind << " " << w.rank << " of " << w.size << " would run "
            << (s.points.size() + std::size_t(w.size - 1 - w.rank)) / std::size_t(w.size)
            << " into " << s.out.string() << "\n";
  for (std::size_t i = 0; i < s.points.size() && i < 20; ++i)
    std::cout << "  " << point_folder_name(int(i), s.points.size()) << "  "
              << s.points[i].values.dump() << "\n";
  if (s.points.size() > 20) std::cout << "  …\n";
}

void run_sweep(SweepArgs a) {
  if (a.jobs < 0 || a.jobs > 256) throw std::invalid_argument("--jobs: give 0 to 256");
  if (a.jobs == 0) a.jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  const SweepWorld w = sweep_world();
  const Timer timer;
  const Sweep s = read_sweep(a);
  if (a.dry_run) {
    print_dry_run(s, w);
    sweep_barrier(w, true);
    return;
  }
  if (w.rank == 0 || w.kind != "MPI") claim_folder(s);
  sweep_barrier(w, false);
  install_stop_handlers();
  Tally t = run_my_points(s, w, a);
  sweep_barrier(w, true);
  count(s, t);
  const bool gathers = (w.kind == "MPI" ? w.rank == 0 : true) && t.pending == 0;
  json summary;
  output::HtmlReport report;
  if (gathers) {
    summary = gather(s);
    write_summary(s, summary);
    if (!a.no_report) {
      report = output::write_html_report(s.out.string(), "sweep_report.py");
      if (report.failed) throw std::runtime_error("--out " + a.out + ": " + report.message);
      if (!report.written) std::cerr << "spinesim: warning: " << report.message << std::endl;
    }
  }
  if (w.rank != 0 && w.kind == "MPI") return;
  if (a.json) {
    json j = {{"points", s.points.size()},
              {"ran", t.ran},
              {"skipped", t.skipped},
              {"ok", t.ok},
              {"failed", t.failed},
              {"pending", t.pending},
              {"world", w.kind},
              {"size", w.size},
              {"seconds", timer.seconds()},
              {"timing", timing_json(t)}};
    if (gathers)
      j["summary"] = {{"csv", (s.out / "summary.csv").string()},
                      {"json", (s.out / "summary.json").string()},
                      {"report", report.written ? json(report.path) : json()}};
    print_json(j);
  } else {
    std::cout << s.points.size() << " points of " << s.plan.verb << ": " << t.ok << " ok, "
              << t.failed << " failed, " << t.pending << " to run (" << w.kind << " " << w.rank
              << " of " << w.size << " ran " << t.ran << ", found " << t.skipped << " done) in "
              << fixed(timer.seconds(), 1) << " s\n";
    const json timing = timing_json(t);
    if (!t.point_seconds.empty())
      std::cout << "points took " << fixed(timing["mean_point_seconds"].get<double>(), 2)
                << " s each on average (" << fixed(timing["point_seconds_sum"].get<double>(), 1)
                << " s in all); dealt as this sweep deals them they would take "
                << fixed(projected_seconds(t.point_seconds, 64), 1) << " s on 64 ranks, "
                << fixed(projected_seconds(t.point_seconds, 512), 1) << " s on 512\n";
    if (gathers) {
      print_sensitivity(s.plan, summary);
      print_uncertainty(s.plan, summary);
      std::cout << "wrote " << (s.out / "summary.csv").string() << ", summary.json"
                << (summary["sensitivity"].is_null() ? "" : ", sensitivity.csv")
                << (summary["uncertainty"].is_null() ? "" : ", uncertainty.csv") << "\n";
      if (report.written) std::cout << report.message << "\n";
    }
  }
  if (t.stopped)
    throw std::runtime_error("stopped by a signal: run the same command again to resume");
}

}  // namespace

void register_sweep(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  auto* cmd = app.add_subcommand(
      "sweep",
      "Run a sweep plan's points (a study with options that vary) on MPI, a Slurm array "
      "or this machine, and gather them into one table");
  cmd->add_option("plan", a->plan, "The sweep plan (JSON; docs/sweeps.md)")
      ->type_name("PLAN")
      ->required();
  cmd->add_option("--out", a->out, "The sweep's folder (made; the same command resumes it)")
      ->required();
  cmd->add_flag("--retry-failed", a->retry_failed, "Run the points that failed again");
  cmd->add_option("--jobs", a->jobs,
                  "Points at once in each process (0: one per core); on MPI, per rank")
      ->capture_default_str();
  cmd->add_flag("--dry-run", a->dry_run, "List the points and stop");
  cmd->add_flag("--no-report", a->no_report,
                "No DIR/report.html and plots (each output against each parameter; the "
                "sensitivity; the uncertainty)");
  add_output_flags(cmd, a->json, a->quiet, "the counts and the summary's files");
  cmd->footer(
      "mpirun -np N spinesim sweep PLAN --out DIR: rank r runs the points i with i mod N == r.\n"
      "As a Slurm job array (sbatch --array=0-K): task k runs the points i with i mod (K+1) == k.\n"
      "Each point runs `spinesim run study.json --json` in DIR/points/NNNN. A point is done when\n"
      "its status.json exists: the same command resumes a killed sweep; a failed point is\n"
      "recorded with its error and the others go on. DIR/summary.csv and summary.json are\n"
      "written when every point is done, the same bytes however the points were run; with them\n"
      "a Morris or Sobol plan writes sensitivity.csv (the indices and their bootstrap intervals)\n"
      "and a Latin hypercube with windows uncertainty.csv (the parameters and outputs before and\n"
      "after weighting by the windows). Plans of the project's studies: data/sweeps/.");
  cmd->callback([a] { run_sweep(*a); });
}

}  // namespace spinesim::cli
