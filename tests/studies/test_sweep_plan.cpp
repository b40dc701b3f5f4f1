// Sweep plans: a grid is every combination in order, ranges are evenly spaced with exact ends,
// zip pairs lists, a Latin hypercube puts one point in every stratum of every parameter from a
// stream that is SplitMix64's published one; bad plans are refused naming the field.
#include "spinesim/studies/sweep_plan.hpp"

#include <gtest/gtest.h>

#include <set>

namespace st = spinesim::studies;
using nlohmann::json;

namespace {

st::SweepPlan plan(const json& j) { return st::parse_sweep_plan(j, "plan.json"); }

json base(const json& parameters) {
  return {{"spinesim_sweep", 1}, {"verb", "spine solve"}, {"parameters", parameters}};
}

void expect_refused(const json& j, const std::string& needle) {
  try {
    plan(j);
    ADD_FAILURE() << "accepted: " << j.dump() << "; expected: " << needle;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("plan.json"), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

}  // namespace

// The published SplitMix64 stream for seed 1234567 (Steele, Lea & Flood 2014; the reference
// C code of Vigna's xoshiro page), and uniform() in [0, 1) with mean 1/2.
TEST(SweepPlan, TheRandomStreamIsSplitMix64) {
  st::SplitMix64 r(1234567);
  EXPECT_EQ(r.next(), 6457827717110365317ull);
  EXPECT_EQ(r.next(), 3203168211198807973ull);
  EXPECT_EQ(r.next(), 9817491932198370423ull);
  st::SplitMix64 u(7);
  double sum = 0, lo = 1, hi = 0;
  for (int i = 0; i < 100000; ++i) {
    const double x = u.uniform();
    sum += x, lo = std::min(lo, x), hi = std::max(hi, x);
  }
  EXPECT_NEAR(sum / 100000, 0.5, 0.005);
  EXPECT_GE(lo, 0.0);
  EXPECT_LT(hi, 1.0);
}

TEST(SweepPlan, AGridIsEveryCombinationTheFirstParameterSlowest) {
  const st::SweepPlan p = plan(base(
      {{"height", {{"values", {1.6, 1.8}}}}, {"mass", {{"from", 50}, {"to", 100}, {"steps", 3}}}}));
  const auto points = st::expand_sweep(p);
  ASSERT_EQ(points.size(), 6u);
  // nlohmann keeps an object's keys sorted: "height" before "mass".
  const double mass[] = {50, 75, 100};
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(points[std::size_t(i)].index, i);
    EXPECT_EQ(points[std::size_t(i)].values["height"].get<double>(), i < 3 ? 1.6 : 1.8);
    EXPECT_EQ(points[std::size_t(i)].values["mass"].get<double>(), mass[i % 3]);
  }
  // The study of a point: the plan's options and the point's values.
  json j = base({{"mass", {{"values", {60}}}}});
  j["options"] = {{"force", {"T7:0,0,300"}}};
  const st::SweepPlan q = plan(j);
  const json s = st::point_study(q, st::expand_sweep(q).front());
  EXPECT_EQ(s["verb"], "spine solve");
  EXPECT_EQ(s["options"]["mass"], 60);
  EXPECT_EQ(s["options"]["force"][0], "T7:0,0,300");
}

TEST(SweepPlan, ARangesStepsAreEvenWithExactEnds) {
  const st::SweepPlan p = plan(base({{"x", {{"from", 0.1}, {"to", 0.7}, {"steps", 7}}}}));
  const auto& v = p.parameters.front().values;
  ASSERT_EQ(v.size(), 7u);
  EXPECT_EQ(v.front().get<double>(), 0.1);
  EXPECT_EQ(v.back().get<double>(), 0.7);
  for (std::size_t k = 1; k < v.size(); ++k)
    EXPECT_NEAR(v[k].get<double>() - v[k - 1].get<double>(), 0.1, 1e-15);
}

TEST(SweepPlan, ZipPairsTheListsInOrder) {
  json j = base({{"height", {{"values", {1.5, 1.7, 1.9}}}},
                 {"sex", {{"values", {"female", "male", "male"}}}}});
  j["design"] = "zip";
  const auto points = st::expand_sweep(plan(j));
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0].values["sex"], "female");
  EXPECT_EQ(points[2].values["height"].get<double>(), 1.9);
}

// One point in each of the n strata of every parameter; the same seed gives the same points,
// another seed others; a list parameter is drawn evenly by index.
TEST(SweepPlan, ALatinHypercubeHasOnePointInEveryStratum) {
  json j = base({{"a", {{"from", -1}, {"to", 3}}},
                 {"b", {{"from", 100}, {"to", 200}}},
                 {"c", {{"values", {"x", "y", "z", "w"}}}}});
  const int n = 40;
  j["design"] = {{"latin_hypercube", {{"points", n}, {"seed", 11}}}};
  const auto points = st::expand_sweep(plan(j));
  ASSERT_EQ(points.size(), std::size_t(n));
  for (const auto& [name, lo, hi] :
       {std::tuple<std::string, double, double>{"a", -1, 3}, {"b", 100, 200}}) {
    std::set<int> strata;
    for (const auto& p : points) {
      const double x = p.values[name].get<double>();
      ASSERT_GE(x, lo);
      ASSERT_LT(x, hi);
      strata.insert(int((x - lo) / (hi - lo) * n));
    }
    EXPECT_EQ(strata.size(), std::size_t(n)) << name;
  }
  std::map<std::string, int> drawn;
  for (const auto& p : points) ++drawn[p.values["c"].get<std::string>()];
  for (const char* c : {"x", "y", "z", "w"}) EXPECT_EQ(drawn[c], n / 4) << c;
  EXPECT_EQ(st::expand_sweep(plan(j))[7].values, points[7].values);
  j["design"]["latin_hypercube"]["seed"] = 12;
  EXPECT_NE(st::expand_sweep(plan(j))[7].values, points[7].values);
}

TEST(SweepPlan, OutputsAreReadByJsonPointerAndNullWhereMissing) {
  json j = base({{"mass", {{"values", {60}}}}});
  j["outputs"] = {{"L5-S1 axial (N)", "/joints/1/axial_n"}, {"absent", "/nothing/here"}};
  const json result = {{"joints", {{{"axial_n", 1.0}}, {{"axial_n", 2.5}}}}};
  const json out = st::point_outputs(plan(j), result);
  EXPECT_EQ(out["L5-S1 axial (N)"].get<double>(), 2.5);
  EXPECT_TRUE(out["absent"].is_null());
}

TEST(SweepPlan, BadPlansAreRefusedNamingTheField) {
  expect_refused(json::array(), "the plan");
  expect_refused({{"verb", "fem"}, {"parameters", {{"x", {{"values", {1}}}}}}}, "spinesim_sweep");
  json j = base({{"x", {{"values", {1}}}}});
  j["extra"] = 1;
  expect_refused(j, "extra");
  expect_refused(base(json::object()), "parameters");
  expect_refused(base({{"x", {{"values", json::array()}}}}), "parameters.x.values");
  expect_refused(base({{"x", {{"from", 2}, {"to", 1}, {"steps", 3}}}}), "from < to");
  expect_refused(base({{"x", {{"from", 0}, {"to", 1}, {"steps", 1}}}}), "steps");
  expect_refused(base({{"x", {{"from", 0}, {"to", 1}}}}), "latin_hypercube");
  expect_refused(base({{"x", {{"values", {1}}, {"from", 0}}}}), "not both");
  expect_refused(base({{"x", {{"valus", {1}}}}}), "parameters.x.valus");
  j = base({{"x", {{"values", {1}}}}});
  j["options"] = {{"x", 2}};
  expect_refused(j, "also a fixed option");
  j = base({{"x", {{"values", {1, 2}}}}, {"y", {{"values", {1}}}}});
  j["design"] = "zip";
  expect_refused(j, "one length");
  j["design"] = "random";
  expect_refused(j, "design");
  j["design"] = {{"latin_hypercube", {{"points", 1}}}};
  expect_refused(j, "points");
  j = base({{"x", {{"values", {1}}}}});
  j["outputs"] = {{"c", "joints/1"}};
  expect_refused(j, "JSON pointer");
  j = base({{"a", {{"from", 0}, {"to", 1}, {"steps", 1000}}},
            {"b", {{"from", 0}, {"to", 1}, {"steps", 1001}}}});
  expect_refused(j, "10^6");
}

// The sensitivity designs: Morris trajectories and Saltelli's blocks mapped onto the ranges;
// the sensitivity of a linear output is its slopes (Morris) and its variance shares (Sobol); an
// output missing at a point gets an error instead of numbers; lists are refused.
TEST(SweepPlan, SensitivityDesignsGiveTheSensitivityOfEachOutput) {
  json j = base({{"a", {{"from", 0}, {"to", 2}}}, {"b", {{"from", 10}, {"to", 30}}}});
  j["outputs"] = {{"y", "/y"}, {"z", "/z"}};
  j["design"] = {{"morris", {{"trajectories", 10}, {"seed", 4}}}};
  const st::SweepPlan m = plan(j);
  const auto points = st::expand_sweep(m);
  ASSERT_EQ(points.size(), 30u);
  std::vector<json> outputs;
  for (const auto& p : points) {
    const double a = p.values["a"].get<double>(), b = p.values["b"].get<double>();
    EXPECT_GE(a, 0);
    EXPECT_LE(a, 2);
    outputs.push_back({{"y", 3 * a - 0.5 * b}, {"z", p.index == 7 ? json() : json(a * b)}});
  }
  const json s = st::sweep_sensitivity(m, points, outputs);
  EXPECT_EQ(s["runs"], 30);
  EXPECT_NEAR(s["outputs"]["y"]["a"]["mu_star"].get<double>(), 3, 1e-9);
  EXPECT_NEAR(s["outputs"]["y"]["b"]["mu"].get<double>(), -0.5, 1e-9);
  EXPECT_NEAR(s["outputs"]["y"]["b"]["sigma"].get<double>(), 0, 1e-9);
  EXPECT_NE(s["outputs"]["z"]["error"].get<std::string>().find("point 7"), std::string::npos);

  j["design"] = {{"sobol", {{"base_points", 16384}, {"seed", 4}}}};
  const st::SweepPlan so = plan(j);
  const auto sp = st::expand_sweep(so);
  ASSERT_EQ(sp.size(), 16384u * 4);
  outputs.clear();
  for (const auto& p : sp)  // Var(3a) = 3, Var(0.1 b) = 1/3
    outputs.push_back(
        {{"y", 3 * p.values["a"].get<double>() + 0.1 * p.values["b"].get<double>()}, {"z", 1.0}});
  const json t = st::sweep_sensitivity(so, sp, outputs);
  EXPECT_NEAR(t["outputs"]["y"]["a"]["first"].get<double>(), 0.9, 0.03);
  EXPECT_NEAR(t["outputs"]["y"]["b"]["total"].get<double>(), 0.1, 0.03);
  const json& ci = t["outputs"]["y"]["a"]["first_interval"];  // 95 %: holds the true 0.9
  EXPECT_LT(ci[0].get<double>(), 0.9);
  EXPECT_GT(ci[1].get<double>(), 0.9);
  EXPECT_LT(ci[1].get<double>() - ci[0].get<double>(), 0.05);
  EXPECT_TRUE(t["outputs"]["z"].contains("error"));  // a constant output shares no variance
  EXPECT_TRUE(st::sweep_sensitivity(plan(base({{"a", {{"values", {1}}}}})), {}, {}).is_null());

  json bad = base({{"a", {{"values", {1, 2}}}}});
  bad["design"] = {{"sobol", {{"base_points", 64}}}};
  expect_refused(bad, "needs a range");
  bad = base({{"a", {{"from", 0}, {"to", 1}}}});
  bad["design"] = {{"morris", {{"trajectories", 5}, {"levels", 5}}}};
  expect_refused(bad, "even");
  bad["design"] = {{"morris", {{"levels", 4}}}};
  expect_refused(bad, "design.morris.trajectories");
  bad["design"] = {{"morris", {{"trajectories", 4}, {"confidence", 95}}}};
  expect_refused(bad, "design.morris.confidence");
  bad["design"] = {{"sobol", {{"base_points", 8}, {"resamples", 2}}}};
  expect_refused(bad, "design.sobol.resamples");

  // Windows: on a Latin hypercube only, of the plan's outputs, 0 < low < high.
  json w = base({{"a", {{"from", 0}, {"to", 1}}}});
  w["design"] = {{"latin_hypercube", {{"points", 4}}}};
  w["outputs"] = {{"y", "/y"}};
  w["windows"] = {{"y", {{"low", 1}, {"high", 2}, {"source", "s"}}}};
  const st::SweepPlan ok = plan(w);
  ASSERT_EQ(ok.windows.size(), 1u);
  EXPECT_EQ(ok.windows[0].name, "y");
  EXPECT_EQ(ok.window_sources[0], "s");
  w["windows"] = {{"z", {{"low", 1}, {"high", 2}}}};
  expect_refused(w, "windows.z");
  w["windows"] = {{"y", {{"low", 2}, {"high", 1}}}};
  expect_refused(w, "0 < low < high");
  w["windows"] = {{"y", {{"low", 1}, {"high", 2}, {"sauce", "s"}}}};
  expect_refused(w, "windows.y.sauce");
  w["windows"] = {{"y", {{"low", 1}, {"high", 2}}}};
  w["design"] = "grid";
  w["parameters"] = {{"a", {{"values", {1, 2}}}}};
  expect_refused(w, "latin_hypercube");
}
