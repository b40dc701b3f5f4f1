// The palpated disc's set-up (`haptics run --scene disc`): which shipped parameters it takes by
// default and by name, and that the disc it builds is the network those parameters describe.
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/studies/disc_palpation_setup.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace spinesim::studies {
namespace {

const std::string kData = SPINESIM_DATA_DIR;

TEST(DiscPalpationSetup, TheDefaultIsTheFibreSetAndTheShippedSetsHaveNames) {
  EXPECT_EQ(palpation_params_path("", kData), calibration::shipped_fibre_tuned_set_path(kData));
  EXPECT_EQ(palpation_params_path("fibre-reinforced", kData),
            calibration::shipped_fibre_tuned_set_path(kData));
  EXPECT_EQ(palpation_params_path("real-disc", kData), calibration::shipped_tuned_set_path(kData));
  const std::string file = calibration::shipped_tuned_set_path(kData);  // any existing file
  EXPECT_EQ(palpation_params_path(file, kData), file);
  try {  // a name that is neither a shipped set nor a file says which names there are
    palpation_params_path("fibre", kData);
    ADD_FAILURE() << "an unknown name was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fibre-reinforced, real-disc"), std::string::npos)
        << e.what();
  }
}

// At 4 mm on L4-L5 (the budget check's coarsest disc): the default builds the fibre network of
// the nonlinear fibre disc, `real-disc` the linear set's network without fibre elements; both
// are measured and chosen (a fixed size is used whatever its step costs).
TEST(DiscPalpationSetup, TheDefaultDiscCarriesItsFibreElements) {
  DiscSceneRequest rq;
  rq.level = "L4-L5";
  rq.fixed_cell_size_mm = 4.0;
  const DiscSetup fibre = make_disc_setup(rq, kData);
  ASSERT_TRUE(fibre.model && fibre.palpation);
  EXPECT_EQ(fibre.tuned_file, calibration::shipped_fibre_tuned_set_path(kData));
  EXPECT_GT(fibre.model->num_fibre_springs(), 0);  // two per annulus tet
  EXPECT_LT(fibre.model->num_fibre_springs(), 2 * fibre.model->mesh().num_tets());
  EXPECT_TRUE(fibre.model->options().isochoric_fibres);
  ASSERT_EQ(fibre.tried.size(), 1u);
  EXPECT_GT(fibre.chosen.step_us.p50, 0.0);

  rq.params = "real-disc";
  const DiscSetup linear = make_disc_setup(rq, kData);
  EXPECT_EQ(linear.model->num_fibre_springs(), 0);
  EXPECT_EQ(linear.model->mesh().num_tets(), fibre.model->mesh().num_tets());

  rq.params = "fibre";  // not a shipped name: a file, which does not exist
  EXPECT_THROW(make_disc_setup(rq, kData), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::studies
