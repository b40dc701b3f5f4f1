// The command-line contract as a property: random flag values drawn from valid, edge and absurd
// ranges (fixed seed), and for every run — exit status 0 or 1; on 1, stderr ends with one
// "spinesim: error:" line and every other line is a "spinesim: warning:"; on 0 with --json,
// stdout is one JSON object; and no file appears but the one --out names.
#include "cli_runner.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <random>
#include <set>
#include <sstream>
#include <vector>

using namespace spinesim::test_cli;

namespace {

/// A value from one of three ranges: valid, edge (0, negative, tiny, huge but finite) or absurd
/// (non-finite, overflowing, not a number).
std::string draw(std::mt19937& rng, double lo, double hi, int kind = -1) {
  static const std::vector<std::string> edge = {"0", "-1", "1e-300", "1e300", "-0", "1e-12"};
  static const std::vector<std::string> absurd = {"nan", "inf", "-inf", "1e999", "abc", "1,2", ""};
  if (kind < 0) kind = int(rng() % 3);
  if (kind == 1) return edge[rng() % edge.size()];
  if (kind == 2) return absurd[rng() % absurd.size()];
  std::ostringstream os;
  os << lo + (hi - lo) * std::uniform_real_distribution<double>(0, 1)(rng);
  return os.str();
}

/// Six values: all valid, or one of them edge or absurd (a third each).
std::string six(std::mt19937& rng, double scale) {
  const int kind = int(rng() % 3), which = int(rng() % 6);
  std::string s;
  for (int k = 0; k < 6; ++k) s += (k ? "," : "") + draw(rng, -scale, scale, k == which ? kind : 0);
  return s;
}

int runs_ok = 0, runs_refused = 0;

void check_contract(const std::string& args, const std::string& out) {
  SCOPED_TRACE(args);
  const auto before = files_in(tmp_dir());
  const CliRun r = run_spinesim(args);
  ASSERT_TRUE(r.status == 0 || r.status == 1) << "status " << r.status << ": " << r.err;
  ++(r.status == 0 ? runs_ok : runs_refused);
  std::vector<std::string> lines;
  std::istringstream err(r.err);
  for (std::string l; std::getline(err, l);) lines.push_back(l);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const bool last = k + 1 == lines.size();
    const bool warning = lines[k].rfind("spinesim: warning:", 0) == 0;
    const bool error = lines[k].rfind("spinesim: error:", 0) == 0;
    EXPECT_TRUE(warning || (last && error && r.status == 1)) << "stderr line: " << lines[k];
  }
  if (r.status == 1) {
    ASSERT_FALSE(lines.empty());
    EXPECT_EQ(lines.back().rfind("spinesim: error:", 0), 0u) << r.err;
  } else if (args.find("--json") != std::string::npos) {
    nlohmann::json parsed;
    EXPECT_NO_THROW(parsed = nlohmann::json::parse(r.out)) << r.out.substr(0, 200);
  }
  const auto after = new_files(before, out);
  EXPECT_TRUE(after.empty()) << "stray file: " << *after.begin();
  if (!out.empty()) fs::remove(out);
}

}  // namespace

TEST(CliContractProperty, RandomFlagValuesKeepTheContract) {
  const std::string disc = tmp("property-disc.vtu");
  ASSERT_EQ(run_spinesim("mesh disc --level T7-T8 --structured --out '" + disc + "'").status, 0);
  std::mt19937 rng(20261202);
  const std::string out = tmp("property-out.vtu");
  for (int trial = 0; trial < 12; ++trial) {
    check_contract("fem --mesh '" + disc + "' --order 1 --wrench '" + six(rng, 500) +
                       "' --json --out '" + out + "'",
                   out);
    check_contract("fem --mesh '" + disc + "' --order 1 --motion '" + six(rng, 0.5) + "' --json",
                   "");
    check_contract(
        "mss --mesh '" + disc + "' --wrench '" + six(rng, 300) + "' --json --out '" + out + "'",
        out);
    check_contract("mesh disc --level T7-T8 --structured --sectors '" + draw(rng, 6, 30) +
                       "' --rings '" + draw(rng, 2, 5) + "' --layers '" + draw(rng, 1, 4) +
                       "' --json --out '" + out + "'",
                   out);
    check_contract("mesh disc --level L4-L5 --cell-size '" + draw(rng, 3, 6) +
                       "' --facet-distance '" + draw(rng, 0.05, 0.5) + "' --json --out '" + out +
                       "'",
                   out);
    check_contract("spine solve --no-muscles --force 'T7:" + draw(rng, -300, 300) + "," +
                       draw(rng, -300, 300) + "," + draw(rng, -300, 300) + "' --json",
                   "");
  }
  std::printf("%d runs succeeded, %d were refused\n", runs_ok, runs_refused);
  EXPECT_GT(runs_ok, 10);  // the draw reaches the valid ranges, not only refusals
  EXPECT_GT(runs_refused, 10);
}
