// libFuzzer target: the haptic trajectory reader (a `--script` for the sim device, or a
// `--record` file for replay) on arbitrary bytes, then what a run does with it: the sim hand and
// the replay device driven through it for a few hundred ticks. Every input must be used or
// refused with std::invalid_argument; a crash, a hang, a non-finite position from an accepted
// file, a leak or undefined behaviour is a finding.
#include "fuzz_input.hpp"
#include "spinesim/haptics/device.hpp"

#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = spinesim::fuzz::input_file("trajectory", data, size, ".csv");
  namespace sh = spinesim::haptics;
  try {
    const sh::Trajectory t = sh::read_trajectory(path);
    const auto& caps = sh::device_model("touch");
    for (auto make : {0, 1}) {
      auto d = make ? sh::make_replay_device(t, caps, 1e-3) : sh::make_sim_device(t, caps, 1e-3);
      d->open();
      sh::DeviceState s;
      for (int k = 0; k < 300; ++k) {
        d->read(s);
        if (!s.position_mm.allFinite() || !s.velocity_mm_s.allFinite()) std::abort();
        d->write_force(Eigen::Vector3d(0.1, -0.2, 0.3));
      }
    }
  } catch (const std::invalid_argument&) {}
  return 0;
}
