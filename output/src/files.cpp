#include "spinesim/output/files.hpp"
#include "spinesim/mss/simulator.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/provenance.hpp"
#include "spinesim/mss/quantities.hpp"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include <unistd.h>

namespace spinesim::output {
namespace fs = std::filesystem;

void write_text_file(const std::string& path, const std::string& text) {
  write_text_atomically(path, text);
}

void write_json_file(const std::string& path, const nlohmann::json& j, int indent) {
  write_text_atomically(path, with_provenance(j).dump(indent) + "\n");
}

void write_csv_file(const std::string& path, const std::string& csv) {
  write_text_atomically(path, csv_provenance_line() + csv);
}

std::string markdown_provenance() {
  const nlohmann::json p = run_provenance();
  if (p.is_null()) return "";
  std::string md = "\n## Provenance\n\nMade by spinesim " + p["version"].get<std::string>() +
                   " (commit `" + p["commit"].get<std::string>() + "`) with\n\n```\n" +
                   p["command"].get<std::string>() + "\n```\n\nin `" +
                   p["working_directory"].get<std::string>() + "`.\n";
  if (!p["inputs"].empty()) {
    md += "\n| input | bytes | SHA-256 |\n|---|---:|---|\n";
    for (const auto& in : p["inputs"])
      md += "| `" + in["path"].get<std::string>() + "` | " + in["bytes"].dump() + " | `" +
            (in["sha256"].is_string() ? in["sha256"].get<std::string>() : "-") + "` |\n";
  }
  return md;
}

void require_output_folder(const std::string& path, const std::string& option) {
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir))
    throw std::invalid_argument(option + " " + path + ": folder " + dir.string() +
                                " does not exist");
  require_replaceable(option, path);  // a device, FIFO or link is refused before the work
}

void prepare_output_folder(const std::string& path, const std::string& option) {
  if (path.empty()) throw std::invalid_argument(option + ": give an output folder");
  const fs::path dir(path);
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw std::invalid_argument(option + " " + path + ": exists and is not a folder");
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw std::invalid_argument(option + " " + path + ": cannot create the folder (" +
                                (ec ? ec.message() : std::string("not a folder")) + ")");
  // Writable? A probe file, made and removed (permissions, read-only mounts).
  const fs::path probe = dir / (".spinesim-write-probe-" + std::to_string(::getpid()));
  {
    std::ofstream os(probe);
    os << "probe";
    os.flush();
    if (!os) {
      fs::remove(probe, ec);
      throw std::invalid_argument(option + " " + path + ": the folder cannot be written");
    }
  }
  fs::remove(probe, ec);
}

namespace {

/// `<parent>/<stem>.staged-PID`: the series' staging folder, created empty.
std::string make_staging_folder(const fs::path& pvd) {
  const fs::path dir =
      pvd.parent_path() / (pvd.stem().string() + ".staged-" + std::to_string(::getpid()));
  fs::remove_all(dir);  // a folder of this process's name can only be a leftover of its own
  fs::create_directory(dir);
  return dir.string();
}

/// True for "<stem>_NNNNNN.vtu": a frame of a series named `stem`.
bool is_frame_of(const std::string& file, const std::string& stem) {
  if (file.size() != stem.size() + 11 || file.compare(0, stem.size() + 1, stem + "_") != 0 ||
      file.compare(file.size() - 4, 4, ".vtu") != 0)
    return false;
  for (std::size_t k = stem.size() + 1; k < file.size() - 4; ++k)
    if (!std::isdigit(static_cast<unsigned char>(file[k]))) return false;
  return true;
}

}  // namespace

VtuSeries::VtuSeries(const std::string& pvd_path) : pvd_path_(pvd_path) {
  const fs::path p(pvd_path);
  if (p.extension() != ".pvd")
    throw std::invalid_argument("time series " + pvd_path + ": the name must end in .pvd");
  require_output_folder(pvd_path, "time series");
  stem_ = p.stem().string();
  folder_ = (p.parent_path() / stem_).string();
  if (fs::exists(fs::symlink_status(folder_)) && !fs::is_directory(fs::symlink_status(folder_)))
    throw std::invalid_argument("time series " + pvd_path + ": " + folder_ +
                                " exists and is not a folder: refusing to replace it");
  const SignalBlock quiet;  // no kill between creating the staging folder and registering it
  staging_ = make_staging_folder(p);
  pending_ = PendingOutput(staging_, PendingOutput::Kind::folder);
}

void VtuSeries::add(double time_s, const mss::MssModel& model, const Eigen::VectorXd& x_mm) {
  add(time_s, 0, [&](const std::string& path) {
    const mss::StateFields f = mss::state_fields(model, x_mm);
    mesh::write_vtu(path, model.mesh(), f.point, f.cell);
  });
}

void VtuSeries::add(double time_s, int part, const std::function<void(const std::string&)>& write) {
  char name[64];
  std::snprintf(name, sizeof name, "_%06zu.vtu", entries_.size());
  write((fs::path(staging_) / (stem_ + name)).string());
  entries_.push_back({time_s, stem_ + "/" + stem_ + name, part});
}

VtuSeries::~VtuSeries() {
  if (finished_) return;
  try {
    discard();
  } catch (...) {  // a destructor does not throw; what could not be removed stays
  }
}

void VtuSeries::finish() {
  // The PVD first, staged: if it cannot be written, nothing has moved.
  const std::string staged_pvd = (fs::path(staging_) / (stem_ + ".pvd")).string();
  mesh::write_pvd(staged_pvd, entries_);
  const SignalBlock whole;  // the frames and the PVD change together
  fs::create_directories(folder_);
  std::set<std::string> ours;
  for (const auto& e : entries_) {
    const std::string file = fs::path(e.file).filename().string();
    fs::rename(fs::path(staging_) / file, fs::path(folder_) / file);
    ours.insert(file);
  }
  // Frames of an earlier series of this name that this one does not have; nothing else is touched.
  for (const auto& e : fs::directory_iterator(folder_)) {
    const std::string file = e.path().filename().string();
    if (is_frame_of(file, stem_) && !ours.count(file)) fs::remove(e.path());
  }
  fs::rename(staged_pvd, pvd_path_);
  finished_ = true;
  fs::remove(staging_);
  pending_.release();
}

void VtuSeries::discard() {
  finished_ = true;  // nothing left to clean up
  entries_.clear();
  std::error_code ec;
  fs::remove_all(staging_, ec);
  pending_.release();
}

std::vector<std::string> VtuSeries::frame_paths() const {
  std::vector<std::string> out;
  const fs::path base = fs::path(pvd_path_).parent_path();
  for (const auto& e : entries_) out.push_back((base / e.file).string());
  return out;
}

}  // namespace spinesim::output
