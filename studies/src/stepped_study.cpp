#include "spinesim/studies/stepped_study.hpp"

#include "spinesim/mesh/io.hpp"

#include <cctype>
#include <filesystem>
#include <iomanip>
#include <stdexcept>

namespace spinesim::studies {
namespace fs = std::filesystem;

void check(const SteppedStudyOptions& o) {
  if (!std::isfinite(o.dynamics.dt_s) || o.dynamics.dt_s <= 0)
    throw std::invalid_argument("--dt must be a finite number > 0 s");
  if (o.frame_every < 1) throw std::invalid_argument("--frame-every must be >= 1");
  if (o.dynamics.newton_iterations < 1) throw std::invalid_argument("--newton must be >= 1");
}

SteppedRun::SteppedRun(const mss::MssModel& model, const SteppedStudyOptions& options,
                       const std::string& stem, const std::string& csv_header, int steps)
    : model_(model),
      frame_every_(options.frame_every),
      steps_(steps),
      sim_(model, options.dynamics),
      state_(sim_.rest_state()),
      frames_((fs::path(options.out) / (stem + ".pvd")).string()),
      csv_path_((fs::path(options.out) / (stem + ".csv")).string()) {
  frames_.add(0.0, model_, state_.x_mm);
  csv_ << std::setprecision(10) << csv_header << "\n";
}

bool SteppedRun::step(int k, const mss::Boundary& bc) {
  if (!stats_.step(sim_, state_, bc)) return false;
  if (k % frame_every_ == 0 || k == steps_) frames_.add(state_.time_s, model_, state_.x_mm);
  return true;
}

void SteppedRun::finish() {
  frames_.finish();
  write_csv_file(csv_path_, csv_.str());
}

nlohmann::json study_mesh_json(const mesh::TetMesh& m) {
  return {{"source", m.source},
          {"nodes", m.num_vertices()},
          {"tets", m.num_tets()},
          {"volume_mm3", mesh::mesh_volume(m)}};
}

std::string file_stem(const std::string& name) {
  std::string s = name;
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_') ch = '_';
  return s.empty() ? "material" : s;
}

}  // namespace spinesim::studies
