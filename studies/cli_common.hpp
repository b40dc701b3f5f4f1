// Shared pieces of the `spinesim` command line: value parsing with clear errors, the data
// folder, JSON on stdout, and stage-by-stage progress on stderr.
#pragma once

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <chrono>
#include <string>

namespace spinesim::cli {

/// Folder with the shipped tables: $SPINESIM_DATA_DIR if set, else the source tree's data/.
std::string data_dir();

/// Parses "a,b,c" into exactly n finite numbers; throws std::invalid_argument naming `what`.
Eigen::VectorXd parse_numbers(const std::string& text, int n, const std::string& what);

/// JSON helpers for Eigen values (row-major nested arrays for matrices).
nlohmann::json to_json(const Eigen::VectorXd& v);
nlohmann::json to_json(const Eigen::MatrixXd& m);

/// Prints `j` as the only thing on stdout (pretty, one object).
void print_json(const nlohmann::json& j);

/// Progress on stderr, one line per stage: "[2/4] assembling ... done 0.42 s". Silent when
/// quiet. Anything that takes more than a second or two is announced before it starts.
class Progress {
 public:
  /// Prints only when not quiet and stderr is a terminal (so scripts see just errors).
  Progress(int stages, bool quiet);
  void begin(const std::string& what);
  double end(const std::string& detail = "");  ///< returns the stage's seconds
  bool quiet() const { return quiet_; }

 private:
  int stages_, current_ = 0;
  bool quiet_;
  std::chrono::steady_clock::time_point start_;
};

/// Seconds since `t0`.
double seconds_since(std::chrono::steady_clock::time_point t0);

// Sub-command registration; each lives in its own cli_<verb>.cpp.
void register_mesh(CLI::App& app);
void register_fem(CLI::App& app);
void register_mss(CLI::App& app);    ///< mss, mss compare (cli_mss.cpp)
void register_calibrate(CLI::App& app);  ///< calibrate (cli_calibrate.cpp)
void register_study(CLI::App& app);  ///< study probe|drive (cli_study.cpp)
void register_spine(CLI::App& app);  ///< spine solve (cli_spine.cpp)
void register_demo(CLI::App& app);
void register_bench(CLI::App& app);
void register_spine_database(CLI::App& spine);  ///< spine database, under `spine` (cli_spine_database.cpp)

}  // namespace spinesim::cli
