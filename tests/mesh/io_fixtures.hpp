// Shared fixtures of the mesh I/O tests: a small exact cube mesh, a fresh temporary folder,
// and the check that a refusal is one line naming the file and the problem.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <utility>

namespace spinesim::mesh::test {

/// Cube [o, o+h]^3 split into 6 positively oriented tets (Kuhn split), with awkward h and o so
/// that coordinates use all 53 mantissa bits. Regions alternate 1/2; surface 1 at the bottom
/// (y = o), 2 at the top.
inline TetMesh kuhn_cube_mesh() {
  TetMesh m;
  const double h = 12.345678901234567, o = 1.0 / 3.0;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(i) << o + h * (i & 1), o + h * ((i >> 1) & 1), o + h * ((i >> 2) & 1);
  const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                          {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  m.T.resize(6, 4);
  for (int t = 0; t < 6; ++t) {
    m.T.row(t) << kuhn[t][0], kuhn[t][1], kuhn[t][2], kuhn[t][3];
    if (tet_volume(m, t) < 0) std::swap(m.T(t, 2), m.T(t, 3));
  }
  m.region.resize(6);
  m.region << 1, 2, 1, 2, 1, 2;
  m.surface.resize(8);
  for (int i = 0; i < 8; ++i) m.surface(i) = ((i >> 1) & 1) ? 2 : 1;
  return m;
}

/// An empty folder SPINESIM_TEST_TMP/<prefix><name>, removed first if it exists.
inline std::string fresh_tmp_dir(const std::string& prefix, const std::string& name) {
  const std::filesystem::path d = std::filesystem::path(SPINESIM_TEST_TMP) / (prefix + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d.string();
}

/// Runs `read`, which must throw std::invalid_argument with one line naming `path` and
/// containing `needle`.
inline void expect_one_line_refusal(const std::function<void()>& read, const std::string& path,
                                    const std::string& needle) {
  try {
    read();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
  }
}

/// The whole file at `path`, bytes as they are.
inline std::string slurp(const std::string& path) {
  std::ifstream is(path, std::ios::binary);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

/// Writes `text` to `path`.
inline void spit(const std::string& path, const std::string& text) {
  std::ofstream os(path, std::ios::binary);
  os << text;
}

/// Whether Debian's /usr/bin/python3 imports `modules` (e.g. "meshio, numpy").
inline bool python_has(const std::string& modules) {
  return std::filesystem::exists("/usr/bin/python3") &&
         std::system(("/usr/bin/python3 -c 'import " + modules + "' >/dev/null 2>&1").c_str()) == 0;
}

/// Runs /usr/bin/python3 on `script` (saved in `dir`) with `args` and returns its stdout; a
/// non-zero exit fails the test with the script's stderr.
inline std::string run_python(const std::string& dir, const std::string& script,
                              const std::string& args) {
  const std::string py = dir + "/script.py";
  spit(py, script);
  const std::string err = dir + "/stderr.txt";
  const std::string cmd = "/usr/bin/python3 " + py + " " + args + " 2>" + err;
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int rc = pclose(p);
  EXPECT_EQ(rc, 0) << out << slurp(err);
  return out;
}

}  // namespace spinesim::mesh::test
