// The displacement–force database regenerated for one vertebra (72 solves + baseline, a few
// seconds): it matches the shipped file, and solving on two threads gives bit-identical
// results to one (solve_spine is const on the model; recruit() serialises Ipopt).
#include "spinesim/spine/database.hpp"

#include <gtest/gtest.h>

namespace {
using namespace spinesim::spine;

const std::string kShipped = std::string(SPINESIM_DATA_DIR) + "/spine/displacement_db.json";

TEST(DatabaseSlow, RegeneratedT1MatchesTheShippedFile) {
  const DisplacementDatabase shipped = DisplacementDatabase::load(kShipped);
  const SpineModel m = load_spine_model(SPINESIM_DATA_DIR, shipped.info.model);
  GenerationOptions o;
  o.solve = shipped.info.solve;
  o.loaded_vertebrae = {0};
  o.tolerance = shipped.info.tolerance;
  const ResponseSamples s = sample_responses(m, o);
  const DisplacementDatabase db = DisplacementDatabase::fit(s, o.tolerance);
  // The same solves fail (a different build may differ at the convergence edge: report it).
  int failed_in_file = 0;
  for (const auto& f : shipped.info.failed) failed_in_file += f.vertebra == 0;
  EXPECT_EQ(int(s.failed.size()), failed_in_file);
  for (int d = 0; d < kDbDirections; ++d)
    for (double f : {100.0, 275.0, 500.0}) {
      const Eigen::Vector3d force = f * direction_vector(d);
      VertebraResponse a, b;
      db.evaluate(0, force, a);
      shipped.evaluate(0, force, b);
      const auto [mm, deg] = max_response_difference(a, b);
      EXPECT_LT(mm, 1e-3) << direction_names()[std::size_t(d)] << " " << f;
      EXPECT_LT(deg, 1e-3) << direction_names()[std::size_t(d)] << " " << f;
    }
}

TEST(DatabaseSlow, TwoThreadsSolveLikeOne) {
  const SpineModel m = load_spine_model(SPINESIM_DATA_DIR);
  std::vector<std::vector<ExternalLoad>> loads;
  for (int v : {0, 6, 14})
    for (int d = 0; d < kDbDirections; d += 1) {
      ExternalLoad l;
      l.vertebra = v;
      l.force_n = (150.0 + 50 * d) * direction_vector(d);
      loads.push_back({l});
    }
  std::vector<VertebraResponse> one, two;
  std::vector<std::string> errors_one, errors_two;
  solve_cases(m, loads, SolveOptions(), 1, one, errors_one);
  int reported = 0;
  solve_cases(m, loads, SolveOptions(), 2, two, errors_two, [&](int done, int total) {
    EXPECT_EQ(done, reported + 1);
    EXPECT_EQ(total, int(loads.size()));
    reported = done;
  });
  EXPECT_EQ(reported, int(loads.size()));
  for (std::size_t i = 0; i < loads.size(); ++i) {
    EXPECT_EQ(errors_one[i], errors_two[i]) << i;
    EXPECT_EQ(one[i], two[i]) << i;  // bit-identical: no shared mutable state between solves
  }
}

}  // namespace
