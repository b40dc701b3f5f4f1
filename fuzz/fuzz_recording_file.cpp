// libFuzzer target: the compliant-stage recording reader (`spine discs --record`) on arbitrary
// bytes: the spine-model line, the end line and its count, the rows and their bounds, and the
// header's body and scoliosis lines (recording_spine). Every input
// must be read or refused with std::invalid_argument; an accepted recording must have at least two
// frames with finite, bounded vertebra motions. Anything else is a finding.
#include "fuzz_input.hpp"
#include "spinesim/haptics/recording.hpp"

#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const spinesim::spine::SpineModel model =
      spinesim::spine::load_spine_model(SPINESIM_DATA_DIR);
  const std::string path = spinesim::fuzz::input_file("recording", data, size, ".csv");
  namespace st = spinesim::haptics;
  try {
    const st::DragRecording r = st::read_drag_recording(path, model);
    if (r.frames.size() < 2 || r.complete != r.incomplete_reason.empty()) std::abort();
    for (const st::DragFrame& f : r.frames)
      if (!f.motion.allFinite() ||
          !(f.motion.leftCols<3>().rowwise().norm().maxCoeff() <= st::kMaxVertebraShiftMm))
        std::abort();
  } catch (const std::invalid_argument&) {}
  try {  // the header's body and scoliosis lines: read, or refused in one line
    const st::RecordedSpine spine = st::recording_spine(path);
    if (spine.scoliosis.cobb_deg != 0 &&
        !(spine.scoliosis.cobb_deg > 0 && spine.scoliosis.cobb_deg <= 120))
      std::abort();
  } catch (const std::invalid_argument&) {}
  return 0;
}
