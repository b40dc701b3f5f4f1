// libFuzzer target: the tuned-parameter reader (a tuned disc of either kind, or a tuned set of
// all levels) on arbitrary bytes, then everything a run does with what it read: the check that
// the parameters apply to a mesh (the T7-T8 structured disc, the haptic resolution) and, when they
// do, the tuned mass-spring model built from them. Every input must be used or refused with
// std::invalid_argument; a crash, a hang, a leak or undefined behaviour (a huge number read
// into an integer field) is a finding.
#include "fuzz_input.hpp"
#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace {

const spinesim::mesh::TetMesh& disc() {
  // As `spinesim mesh disc --level T7-T8 --structured` makes it, so that the seed files
  // calibrated on that mesh (per-spring ones included) apply to it.
  namespace m3 = spinesim::mesh;
  static const m3::TetMesh m =
      m3::mesh_structured_disc(m3::disc_dimensions("T7-T8", SPINESIM_DATA_DIR), {},
                               m3::disc_frame_in_spine("T7-T8", SPINESIM_DATA_DIR));
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = spinesim::fuzz::input_file("tuned", data, size);
  namespace cal = spinesim::calibration;
  try {
    const cal::TunedDisc t = cal::read_tuned_for_mesh(path, &disc());
    (void)cal::build_tuned_model(t, disc(), t.materials());
  } catch (const std::invalid_argument&) {}
  return 0;
}
