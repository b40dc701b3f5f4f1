#include "spinesim/studies/files.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/mss/quantities.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace spinesim::studies {
namespace fs = std::filesystem;

void write_text_file(const std::string& path, const std::string& text) {
  write_text_atomically(path, text);
}

void require_output_folder(const std::string& path, const std::string& option) {
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir))
    throw std::invalid_argument(option + " " + path + ": folder " + dir.string() +
                                " does not exist");
  require_replaceable(option, path);  // a device, FIFO or link is refused before the work
}

VtuSeries::VtuSeries(const std::string& pvd_path) : pvd_path_(pvd_path) {
  const fs::path p(pvd_path);
  if (p.extension() != ".pvd")
    throw std::invalid_argument("time series " + pvd_path + ": the name must end in .pvd");
  require_output_folder(pvd_path, "time series");
  stem_ = p.stem().string();
  folder_ = (p.parent_path() / stem_).string();
  fs::create_directories(folder_);
}

void VtuSeries::add(double time_s, const mss::MssModel& model, const Eigen::VectorXd& x_mm) {
  char name[64];
  std::snprintf(name, sizeof name, "_%06zu.vtu", entries_.size());
  const std::string rel = stem_ + "/" + stem_ + name;
  const mss::StateFields f = mss::state_fields(model, x_mm);
  mesh::write_vtu((fs::path(folder_) / (stem_ + name)).string(), model.mesh(), f.point, f.cell);
  entries_.push_back({time_s, rel});
}

VtuSeries::~VtuSeries() {
  if (finished_) return;
  try {
    discard();
  } catch (...) {  // a destructor does not throw; what could not be removed stays
  }
}

void VtuSeries::finish() {
  mesh::write_pvd(pvd_path_, entries_);
  finished_ = true;
}

void VtuSeries::discard() {
  finished_ = true;  // nothing left to clean up
  std::error_code ec;
  for (const std::string& f : frame_paths()) fs::remove(f, ec);
  entries_.clear();
  fs::remove(folder_, ec);  // only if empty
}

std::vector<std::string> VtuSeries::frame_paths() const {
  std::vector<std::string> out;
  const fs::path base = fs::path(pvd_path_).parent_path();
  for (const auto& e : entries_) out.push_back((base / e.file).string());
  return out;
}

}  // namespace spinesim::studies
