// The standing-gap study: the swelling pressure adds exactly its force to every posture (and
// scales with the disc's area for another body), each muscle mechanism raises standing the more
// the higher its level, and the bisected level brings standing to the in-vivo load.
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/standing_gap_study.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace sp = spinesim::spine;
namespace st = spinesim::studies;

namespace {
const std::string kData = SPINESIM_DATA_DIR;

const st::StandingGapCase& by_name(const st::StandingGapStudy& s, const std::string& start) {
  for (const auto& c : s.cases)
    if (c.name.rfind(start, 0) == 0) return c;
  throw std::logic_error("no case " + start);
}
}  // namespace

TEST(StandingGapStudy, EachMechanismIsMeasuredAndTheBisectionClosesStanding) {
  const st::StandingGapStudy s = st::run_standing_gap_study(kData, {}, 0.10);
  ASSERT_EQ(int(s.cases.size()), st::kStandingGapStages);
  const auto& none = by_name(s, "the model as it stands");
  const auto& swelling = by_name(s, "+ swelling pressure");
  EXPECT_NEAR(s.prestress_force_n, 0.10 * s.area_mm2, 1e-9);
  for (const auto& [with, without] : {std::pair{swelling.standing_n, none.standing_n},
                                      {swelling.sitting_n, none.sitting_n},
                                      {swelling.chair_n, none.chair_n},
                                      {swelling.crate_n, none.crate_n}})
    EXPECT_NEAR(with - without, s.prestress_force_n, 1e-6);
  EXPECT_LT(by_name(s, "co-contraction 2").standing_n, by_name(s, "co-contraction 5").standing_n);
  EXPECT_LT(none.standing_n, by_name(s, "co-contraction 2").standing_n);
  EXPECT_LT(by_name(s, "resting tone 2").standing_n, by_name(s, "resting tone 5").standing_n);
  for (const auto& c : s.cases)
    if (c.name.find("standing matched") != std::string::npos) {
      EXPECT_TRUE(c.found);
      EXPECT_NEAR(c.standing_n, s.standing_target_n, 2.0) << c.name;
      EXPECT_EQ(c.prestress_mpa, 0.10);
    }
  EXPECT_THROW(st::run_standing_gap_study(kData, {}, -0.1), std::invalid_argument);
}

TEST(StandingGapStudy, TheSwellingForceScalesWithTheBodysDiscArea) {
  sp::ModelOptions small;
  small.subject = sp::named_body(kData, "p5-female").subject;
  const st::SittingValidation v = st::run_posture_comparison(kData, small, 0.10);
  const double s = small.subject.height_m / sp::named_body(kData, "reference").subject.height_m;
  EXPECT_NEAR(v.swelling_n, 0.10 * v.disc_area_mm2 * s * s, 1e-9);
  const st::SittingValidation file = st::run_posture_comparison(kData);
  EXPECT_GT(file.swelling_mpa, 0);  // the validation file's pressure is the default
}
