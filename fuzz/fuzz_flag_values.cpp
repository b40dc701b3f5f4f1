// libFuzzer target: every parser that turns the text of a command-line flag into a value, on
// arbitrary text — the command line's own (app/cli/flag_values.hpp: numbers, vertebra
// vectors, units, axes, integrators, lists) and the library parsers behind other flags (load
// cases and case lists, fusion levels, vertebra names, disc levels, stiffness knobs). The first
// byte picks the parser, the rest is the flag's text. Each must return a valid value or refuse
// with std::invalid_argument; a crash, a hang, a leak, undefined behaviour or a non-finite
// number let through is a finding. (How CLI11 splits argv into flags is covered by the
// command-line property test, tests/cli/test_cli_contract_property.cpp.)
#include "flag_values.hpp"

#include "spinesim/calibration/linear_mss.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/spine/model.hpp"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

void parse(std::uint8_t which, const std::string& text) {
  namespace cli = spinesim::cli;
  switch (which % 12) {
    case 0: {
      const int n = 1 + (which / 12) % 6;
      check(cli::parse_numbers(text, n, "--fuzz").allFinite());
      break;
    }
    case 1:
      for (const std::string& item : cli::split_list(text)) check(!item.empty());
      for (double v : cli::parse_number_list(text, "--values")) check(std::isfinite(v));
      break;
    case 2: {
      const auto [vertebra, v] = cli::parse_vertebra_vector(text, "--force", "Fx,Fy,Fz");
      check(vertebra >= 0 && vertebra < int(spinesim::spine::vertebra_names().size()));
      check(v.allFinite());
      break;
    }
    case 3:
      check(cli::units_to_mm(text) > 0);
      break;
    case 4:
      (void)cli::up_axis(text);
      break;
    case 5:
      (void)cli::parse_integrator(text);
      break;
    case 6: {
      const std::vector<int> joints = spinesim::spine::parse_fusion(text);
      check(!joints.empty());
      for (const int j : joints) check(j >= 0 && j < int(spinesim::spine::joint_names().size()));
      break;
    }
    case 7:
      (void)spinesim::spine::vertebra_index(text);
      break;
    case 8:
      (void)spinesim::fem::load_case(text);
      break;
    case 9:
      (void)spinesim::fem::parse_load_cases(text);
      break;
    case 10:
      check(spinesim::mesh::disc_dimensions(text, SPINESIM_DATA_DIR).level.size() > 0);
      break;
    case 11:
      (void)spinesim::calibration::knob_from_name(text);
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  try {
    parse(data[0], std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  } catch (const std::invalid_argument&) {}
  return 0;
}
