// spinesim bench — measured speed and memory of meshing and of the FEM reference.
//
//   spinesim bench mesh [--level L4-L5] [--cell-sizes 3,2,1.5,1]
//   spinesim bench fem  [--level L4-L5] [--orders 1,2] [--cell-sizes 3,2,1.5,1.2,1]
//
// Each measurement (studies/bench_runs.hpp) runs in a fresh child process (this program,
// re-executed), so the peak resident memory it reports (getrusage ru_maxrss) belongs to that one
// run. Times are wall clock on this machine; nothing here is asserted in tests.
#include "cli_common.hpp"

#include "spinesim/studies/bench_runs.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

std::string self_exe() { return std::filesystem::read_symlink("/proc/self/exe").string(); }

/// Runs this program with `args` and parses the one JSON object it prints; a run that fails is
/// an error naming the run and the child's own error line.
nlohmann::json run_child(const std::string& args) {
  const std::string err = std::filesystem::temp_directory_path().string() + "/spinesim-bench-" +
                          std::to_string(getpid()) + ".stderr";
  const std::string cmd = "'" + self_exe() + "' " + args + " 2>'" + err + "'";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("bench: cannot start " + cmd);
  std::string text;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, pipe)) text.append(buf, n);
  const int status = pclose(pipe);
  std::string why;
  {
    std::ifstream in(err);
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) why = line;
  }
  std::remove(err.c_str());
  if (status != 0)
    throw std::runtime_error("bench: the run `" + args + "` failed" +
                             (why.empty() ? std::string() : ": " + why));
  return nlohmann::json::parse(text);
}

// --- one measurement per process -----------------------------------------------------------

struct OneArgs {
  std::string level = "L4-L5", mesh_out, mesh_in;
  double cell_size_mm = 2.0;
  int order = 1;
};

void mesh_one(const OneArgs& a) {
  print_json(bench_mesh_once(a.level, a.cell_size_mm, data_dir(), a.mesh_out));
}

void fem_one(const OneArgs& a) { print_json(bench_fem_once(a.mesh_in, a.order, data_dir())); }

// --- the runs, each in a child process, and their tables ------------------------------------

struct BenchArgs {
  std::string level = "L4-L5", cell_sizes = "3,2,1.5,1", orders = "1,2";
  bool json = false;
};

void bench_mesh(const BenchArgs& a) {
  nlohmann::json rows = nlohmann::json::array();
  TextTable t({"cell mm", "tets", "nodes", "seconds", "min dihedral", "volume err %", "peak MB"},
              0);
  const auto sizes = parse_number_list(a.cell_sizes, "--cell-sizes");
  ProgressBar bar(int(sizes.size()), a.json, "runs");
  for (double h : sizes) {
    bar.update(int(rows.size()), "meshing at " + fixed(h, 2) + " mm");
    std::ostringstream args;
    args << "bench-mesh-one --level " << a.level << " --cell-size " << h;
    const auto r = run_child(args.str());
    rows.push_back(r);
    t.add({fixed(h, 2), std::to_string(r["tets"].get<long>()),
           std::to_string(r["nodes"].get<long>()), fixed(r["seconds"].get<double>(), 2),
           fixed(r["min_dihedral_deg"].get<double>(), 2),
           fixed(100 * r["volume_error"].get<double>(), 3),
           fixed(r["peak_rss_mb"].get<double>(), 0)});
  }
  bar.finish();
  if (a.json) {
    print_json({{"level", a.level}, {"runs", rows}});
    return;
  }
  std::cout << "Meshing " << a.level << " (CGAL Mesh_3, default options)\n";
  t.print(std::cout, false, " ");
}

void bench_fem(const BenchArgs& a) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("spinesim-bench-" + std::to_string(getpid()));
  fs::create_directories(dir);
  nlohmann::json rows = nlohmann::json::array();
  TextTable t({"order", "DOF", "assembly", "analyse", "factorise", "6 solves", "6x6 total",
               "1 load", "peak MB"},
              0);
  const auto sizes = parse_number_list(a.cell_sizes, "--cell-sizes");
  ProgressBar bar(int(sizes.size()), a.json, "meshes");
  int done = 0;
  for (double h : sizes) {
    bar.update(done++, "cell size " + fixed(h, 2) + " mm");
    const fs::path mesh_path = dir / ("disc-" + std::to_string(h) + ".vtu");
    std::ostringstream margs;
    margs << "bench-mesh-one --level " << a.level << " --cell-size " << h << " --mesh-out '"
          << mesh_path.string() << "'";
    run_child(margs.str());
    for (double order : parse_number_list(a.orders, "--orders")) {
      std::ostringstream fargs;
      fargs << "bench-fem-one --mesh '" << mesh_path.string() << "' --order " << int(order);
      auto r = run_child(fargs.str());
      r["cell_size_mm"] = h;
      rows.push_back(r);
      t.add({std::to_string(int(order)), std::to_string(r["dofs"].get<long>()),
             fixed(r["assembly_s"].get<double>(), 3), fixed(r["analyse_s"].get<double>(), 3),
             fixed(r["factorise_s"].get<double>(), 3),
             fixed(r["stiffness_solves_s"].get<double>(), 3),
             fixed(r["stiffness_total_s"].get<double>(), 3),
             fixed(r["load_solve_s"].get<double>(), 3), fixed(r["peak_rss_mb"].get<double>(), 0)});
    }
  }
  bar.finish();
  fs::remove_all(dir);
  if (a.json) {
    print_json({{"level", a.level}, {"runs", rows}});
    return;
  }
  std::cout << "FEM reference on " << a.level
            << " meshes (real-disc), one process per run; times in s\n";
  t.print(std::cout, false, " ");
}

}  // namespace

void register_bench(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  auto* cmd = app.add_subcommand(
      "bench", "Measure meshing and FEM speed and memory (each run in its own process)");
  cmd->require_subcommand(1);
  auto* m = cmd->add_subcommand("mesh", "Meshing time, tet count and quality vs cell size");
  auto* f = cmd->add_subcommand("fem",
                                "FEM assembly / factorisation / solve time and peak memory vs DOF");
  for (auto* sub : {m, f}) {
    sub->add_option("--level", a->level, "Disc level")->capture_default_str();
    sub->add_option("--cell-sizes", a->cell_sizes, "Comma-separated cell sizes, mm")
        ->capture_default_str();
    sub->add_flag("--json", a->json, "Print a JSON summary on stdout");
  }
  f->add_option("--orders", a->orders, "Comma-separated element orders")->capture_default_str();
  m->callback([a] { bench_mesh(*a); });
  f->callback([a] { bench_fem(*a); });

  // Hidden single-run verbs used by the drivers above.
  auto one = std::make_shared<OneArgs>();
  auto* mo = app.add_subcommand("bench-mesh-one")->group("");
  mo->add_option("--level", one->level);
  mo->add_option("--cell-size", one->cell_size_mm);
  mo->add_option("--mesh-out", one->mesh_out);
  mo->callback([one] { mesh_one(*one); });
  auto* fo = app.add_subcommand("bench-fem-one")->group("");
  fo->add_option("--mesh", one->mesh_in)->required();
  fo->add_option("--order", one->order);
  fo->callback([one] { fem_one(*one); });
}

}  // namespace spinesim::cli
