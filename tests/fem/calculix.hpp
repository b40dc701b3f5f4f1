// CalculiX (Debian's calculix-ccx) as the independent reference of the FEM tests: a job written
// as an input deck, run by `ccx` in its own folder, and the last block of a kind read back from
// its .dat file (*EL PRINT / *NODE PRINT).
#pragma once

#include <gtest/gtest.h>

#include "spinesim/fem/hyperelastic.hpp"

#include <Eigen/Core>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace spinesim::test {

constexpr const char* kCalculix = "/usr/bin/ccx";

inline bool have_calculix() { return std::filesystem::exists(kCalculix); }

/// Runs the deck `inp` as job `name` in a fresh folder under SPINESIM_TEST_TMP; returns the
/// .dat file's text (empty, with a test failure, when ccx fails).
inline std::string run_calculix(const std::string& name, const std::string& inp) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(SPINESIM_TEST_TMP) / ("ccx-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / (name + ".inp")) << inp;
  const std::string cmd = "cd '" + dir.string() + "' && OMP_NUM_THREADS=1 " + kCalculix + " -i " +
                          name + " > ccx.log 2>&1";
  if (std::system(cmd.c_str()) != 0) {
    ADD_FAILURE() << "ccx failed: see " << (dir / "ccx.log").string();
    return {};
  }
  std::ifstream in(dir / (name + ".dat"));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The material cards of `m` as CalculiX's ELASTIC_FIBER: C10, D1, then per family a_x, a_y,
/// k1, k2, with a_z = +√(1 − a_x² − a_y²) (a family's sign does not matter, so a direction with
/// a_z < 0 is given reversed); eight constants a line. CalculiX picks the law by the name's first
/// 13 letters, so `name` must start with ELASTIC_FIBER.
inline std::string elastic_fiber_material(const fem::FibreHyperelastic& m,
                                          const std::string& name = "ELASTIC_FIBER") {
  std::vector<double> c{m.c10_mpa, m.d1_per_mpa};
  for (const fem::FibreFamily& f : m.fibres) {
    const Eigen::Vector3d a = f.direction.z() < 0 ? Eigen::Vector3d(-f.direction) : f.direction;
    c.insert(c.end(), {a.x(), a.y(), f.k1_mpa, f.k2});
  }
  std::ostringstream os;
  os << std::setprecision(13) << "*MATERIAL,NAME=" << name
     << "\n*USER MATERIAL,CONSTANTS=" << c.size() << "\n";
  for (std::size_t k = 0; k < c.size(); ++k)
    os << c[k] << ((k + 1) % 8 == 0 || k + 1 == c.size() ? ",\n" : ",");
  return os.str();
}

/// The rows of the last block whose header starts with `header` (e.g. " stresses", " forces"),
/// each row's numbers after `skip` leading integer columns.
inline std::vector<Eigen::VectorXd> last_block(const std::string& dat, const std::string& header,
                                               int skip) {
  const std::size_t at = dat.rfind(header);
  std::vector<Eigen::VectorXd> rows;
  if (at == std::string::npos) return rows;
  std::istringstream in(dat.substr(at));
  std::string line;
  std::getline(in, line);  // the header
  bool started = false;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::vector<double> values;
    std::string w;
    for (int k = 0; words >> w; ++k)
      if (k >= skip) values.push_back(std::stod(w));
    if (values.empty()) {
      if (started) break;
      continue;
    }
    started = true;
    rows.push_back(Eigen::Map<Eigen::VectorXd>(values.data(), Eigen::Index(values.size())));
  }
  return rows;
}

/// The largest row difference of `a` and `b` over the largest row of `b` (row norms): how two
/// per-node or per-element fields compare, relative to the field's size.
inline double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).rowwise().norm().maxCoeff() / b.rowwise().norm().maxCoeff();
}

}  // namespace spinesim::test
