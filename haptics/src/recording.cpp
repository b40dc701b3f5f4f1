#include "spinesim/haptics/recording.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/common/provenance.hpp"
#include "spinesim/output/format.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/spine/scoliosis.hpp"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace spinesim::haptics {

using output::fixed;
using output::one_line;
using output::significant;

namespace {

constexpr int kCommonColumns = 13, kHookColumns = 11, kVertebrae = 17;
constexpr int kDragColumns = kCommonColumns + kHookColumns + 6 * kVertebrae;
constexpr int kSixDofColumns = 9;  // rotation, torque, and with the stage the spine's moment
constexpr const char* kSixDofHeader = ",rx_deg,ry_deg,rz_deg,tx_nmm,ty_nmm,tz_nmm";
constexpr const char* kSpineMomentHeader = ",spine_mx_nmm,spine_my_nmm,spine_mz_nmm";

void fnv(std::uint64_t& h, double v) {
  unsigned char b[sizeof v];
  std::memcpy(b, &v, sizeof v);
  for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
}

}  // namespace

std::string spine_model_fingerprint(const spine::SpineModel& m) {
  std::uint64_t h = 1469598103934665603ull;
  for (const auto& v : m.vertebrae)
    for (int a = 0; a < 3; ++a) fnv(h, v.centre_mm[a]);
  for (const auto& j : m.joints) {
    for (int a = 0; a < 3; ++a) fnv(h, j.point_mm[a]);
    fnv(h, j.fused ? 1.0 : 0.0);
  }
  // A curved spine's rest posture (the motions are recorded from it); a straight spine has none,
  // so its fingerprint is what it always was.
  for (Eigen::Index i = 0; i < m.rest_posture.size(); ++i) fnv(h, m.rest_posture[i]);
  char out[17];
  std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
  return out;
}

HapticRecordingWriter::HapticRecordingWriter(const std::string& path,
                                             const std::string& description,
                                             const spine::SpineModel* model,
                                             const std::string& response, bool disc, bool six_dof)
    : path_(path), disc_(disc), six_dof_(six_dof) {
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) throw std::runtime_error("--record " + path + ": cannot write there");
  std::fprintf(
      file_,
      "# spinesim haptics recording 1: every servo tick; %s\n"
      "# units: s, mm, N, N mm, deg; frame x lateral (right = -x), y superior, z anterior. "
      "Columns 1-5 are a trajectory (--device replay --replay FILE plays them)\n",
      description.c_str());
  std::fputs(csv_provenance_line().c_str(), file_);  // what made the recording
  if (model)
    std::fprintf(file_,
                 "# spine model %s; compliant stage %s; vertebra motion: the F.1 centre's "
                 "displacement (mm) and the rotation vector (deg) from the reference posture\n",
                 spine_model_fingerprint(*model).c_str(), response.c_str());
  if (model)  // whose spine: spine discs rebuilds the model (and the discs) for this body
    std::fprintf(file_, "# body: height_m %.17g, body_mass_kg %.17g, sex %s\n",
                 model->subject.height_m, model->subject.body_mass_kg,
                 spine::sex_name(model->subject.sex));
  if (model && model->scoliosis.cobb_deg != 0) {  // and its curve: the discs rest wedged in it
    const spine::ScoliosisCurve& c = model->scoliosis;
    std::fprintf(file_,
                 "# scoliosis: type %s, cobb_deg %.17g, upper_end %s, apex %s, lower_end %s, "
                 "apical_rotation_deg %.17g, convex %s\n",
                 c.type.c_str(), c.cobb_deg, c.upper_end.c_str(), c.apex.c_str(),
                 c.lower_end.c_str(), c.apical_rotation_deg, c.convex_right ? "right" : "left");
  }
  std::fprintf(file_,
               "t_s,x_mm,y_mm,z_mm,button,fx_n,fy_n,fz_n,proxy_x_mm,proxy_y_mm,proxy_z_mm,"
               "contact,tick");
  if (disc)
    std::fprintf(file_,
                 ",disc_contact,disc_probe_x_mm,disc_probe_y_mm,disc_probe_z_mm,disc_fx_n,"
                 "disc_fy_n,disc_fz_n,disc_volume_change,disc_indentation_mm");
  if (model) {
    std::fprintf(file_,
                 ",attached,hook_vertebra,hook_ref_x_mm,hook_ref_y_mm,hook_ref_z_mm,"
                 "hook_x_mm,hook_y_mm,hook_z_mm,spine_fx_n,spine_fy_n,spine_fz_n");
    for (const auto& v : model->vertebrae) {
      centres_.push_back(v.centre_mm);
      for (const char* c : {"tx_mm", "ty_mm", "tz_mm", "rx_deg", "ry_deg", "rz_deg"})
        std::fprintf(file_, ",%s_%s", v.name.c_str(), c);
    }
  }
  if (six_dof) std::fprintf(file_, "%s%s", kSixDofHeader, model ? kSpineMomentHeader : "");
  std::fputc('\n', file_);
  if (std::fflush(file_) != 0) failed_ = true;
}

HapticRecordingWriter::~HapticRecordingWriter() {
  if (file_) std::fclose(file_);
}

void HapticRecordingWriter::append(const haptics::TickRecord* rows, std::size_t n) {
  if (!file_) return;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = rows[i];
    std::fprintf(file_, "%.6f,%.4f,%.4f,%.4f,%u,%.5f,%.5f,%.5f,%.4f,%.4f,%.4f,%d,%lld", r.t_s,
                 r.probe_mm.x(), r.probe_mm.y(), r.probe_mm.z(), r.buttons & 1u, r.force_n.x(),
                 r.force_n.y(), r.force_n.z(), r.proxy_mm.x(), r.proxy_mm.y(), r.proxy_mm.z(),
                 r.contact ? 1 : 0, static_cast<long long>(r.tick));
    if (disc_)
      std::fprintf(file_, ",%d,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f,%.7f,%.5f", r.disc_contact ? 1 : 0,
                   r.disc_probe_mm.x(), r.disc_probe_mm.y(), r.disc_probe_mm.z(),
                   r.disc_force_n.x(), r.disc_force_n.y(), r.disc_force_n.z(), r.disc_volume_change,
                   r.disc_indentation_mm);
    if (!centres_.empty()) {
      const auto& h = r.hook;
      std::fprintf(file_, ",%d,%d,%.5f,%.5f,%.5f,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f", h.attached ? 1 : 0,
                   h.load.vertebra, h.load.point_mm.x(), h.load.point_mm.y(), h.load.point_mm.z(),
                   h.hook_mm.x(), h.hook_mm.y(), h.hook_mm.z(), h.load.force_n.x(),
                   h.load.force_n.y(), h.load.force_n.z());
      for (std::size_t v = 0; v < centres_.size(); ++v) {
        const Eigen::Matrix3d R = r.R[v].cast<double>();
        const Eigen::Vector3d d = R * centres_[v] + r.t[v].cast<double>() - centres_[v];
        const Eigen::Vector3d rot = spine::rotation_log(R) * kDegPerRad;
        std::fprintf(file_, ",%.5f,%.5f,%.5f,%.5f,%.5f,%.5f", d.x(), d.y(), d.z(), rot.x(), rot.y(),
                     rot.z());
      }
    }
    if (six_dof_) {
      std::fprintf(file_, ",%.5f,%.5f,%.5f,%.4f,%.4f,%.4f", r.rotation_deg.x(), r.rotation_deg.y(),
                   r.rotation_deg.z(), r.torque_nmm.x(), r.torque_nmm.y(), r.torque_nmm.z());
      if (!centres_.empty())
        std::fprintf(file_, ",%.3f,%.3f,%.3f", r.hook.load.moment_nmm.x(),
                     r.hook.load.moment_nmm.y(), r.hook.load.moment_nmm.z());
    }
    std::fputc('\n', file_);
  }
  rows_ += std::int64_t(n);
  // A block on disk before the next: a killed run keeps everything up to here.
  if (std::fflush(file_) != 0 || ::fdatasync(::fileno(file_)) != 0) failed_ = true;
}

void HapticRecordingWriter::finish(const std::string& stopped_early) {
  if (!file_) return;
  if (stopped_early.empty())
    std::fprintf(file_, "%s%lld ticks\n", kEndLine, static_cast<long long>(rows_));
  else
    std::fprintf(file_, "%s%lld ticks; stopped early: %s\n", kEndLine,
                 static_cast<long long>(rows_), one_line(stopped_early).c_str());
  const bool ok = std::fflush(file_) == 0 && ::fdatasync(::fileno(file_)) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (failed_ || !ok || !closed) {
    // A write that failed (a full disk) leaves no half file under the output's name: what is
    // on disk ends mid-row and its rows are not all the run's.
    std::remove(path_.c_str());
    throw std::runtime_error("--record " + path_ + ": write failed (disk full?); nothing kept");
  }
}

spine::Pose DragFrame::pose(const spine::SpineModel& m, int i) const {
  return spine::pose_from_displacement(m.vertebrae[std::size_t(i)].centre_mm,
                                       motion.row(i).head<3>().transpose(),
                                       motion.row(i).tail<3>().transpose());
}

namespace {

/// Parses one data row into `f` (with the 6-DOF columns when `six_dof`); false with `why` when a
/// cell is not a finite number.
bool parse_row(const std::string& line, bool six_dof, DragFrame& f, std::string& why) {
  double v[kDragColumns + kSixDofColumns];
  const int columns = kDragColumns + (six_dof ? kSixDofColumns : 0);
  const char* p = line.c_str();
  for (int k = 0; k < columns; ++k) {
    char* end = nullptr;
    errno = 0;
    v[k] = std::strtod(p, &end);
    if (end == p || !std::isfinite(v[k])) {
      why = "column " + std::to_string(k + 1) + " is not a finite number";
      return false;
    }
    p = end;
    if (k + 1 < columns) {
      if (*p != ',') {
        why = "expected " + std::to_string(columns) + " columns, got " + std::to_string(k + 1);
        return false;
      }
      ++p;
    }
  }
  while (*p == ' ' || *p == '\r') ++p;
  if (*p != '\0') {
    why = "more than " + std::to_string(columns) + " columns";
    return false;
  }
  // Counts become integers only when they are whole numbers in range (a cast of 1e40 is
  // undefined behaviour).
  if (!(v[12] >= 0 && v[12] <= 9007199254740992.0 && v[12] == std::floor(v[12]))) {
    why = "the tick (column 13) is not a whole number from 0 to 2^53";
    return false;
  }
  if (!(v[14] >= -1 && v[14] < kVertebrae && v[14] == std::floor(v[14]))) {
    why = "the hooked vertebra (column 15) is not -1 or a vertebra index 0.." +
          std::to_string(kVertebrae - 1);
    return false;
  }
  f.t_s = v[0];
  f.probe_mm = Eigen::Vector3d(v[1], v[2], v[3]);
  f.hand_force_n = Eigen::Vector3d(v[5], v[6], v[7]);
  f.proxy_mm = Eigen::Vector3d(v[8], v[9], v[10]);
  f.tick = std::int64_t(v[12]);
  f.attached = v[13] != 0;
  f.hook_vertebra = int(v[14]);
  f.hook_ref_mm = Eigen::Vector3d(v[15], v[16], v[17]);
  f.hook_mm = Eigen::Vector3d(v[18], v[19], v[20]);
  f.spine_force_n = Eigen::Vector3d(v[21], v[22], v[23]);
  for (int i = 0; i < kVertebrae; ++i)
    for (int c = 0; c < 6; ++c) f.motion(i, c) = v[kCommonColumns + kHookColumns + 6 * i + c];
  if (six_dof) {
    const double* t = v + kDragColumns;
    f.rotation_deg = Eigen::Vector3d(t[0], t[1], t[2]);
    f.torque_nmm = Eigen::Vector3d(t[3], t[4], t[5]);
    f.spine_moment_nmm = Eigen::Vector3d(t[6], t[7], t[8]);
  }
  return true;
}

}  // namespace

RecordedSpine recording_spine(const std::string& path) {
  std::ifstream in = open_regular_file(path, "the recording");
  std::string line;
  RecordedSpine r;
  while (std::getline(in, line) && !line.empty() && line[0] == '#') {
    if (line.rfind("# body: ", 0) == 0) {
      spine::Subject& s = r.subject;
      char sex[16] = {0};
      if (std::sscanf(line.c_str(), "# body: height_m %lf, body_mass_kg %lf, sex %15s", &s.height_m,
                      &s.body_mass_kg, sex) != 3 ||
          !std::isfinite(s.height_m) || !std::isfinite(s.body_mass_kg))
        throw std::invalid_argument(path + ": a malformed body line: " + line);
      s.sex = spine::parse_sex(sex);
    } else if (line.rfind("# scoliosis: ", 0) == 0) {
      spine::ScoliosisCurve& c = r.scoliosis;
      char type[32] = {0}, upper[8] = {0}, apex[8] = {0}, lower[8] = {0}, convex[8] = {0};
      if (std::sscanf(line.c_str(),
                      "# scoliosis: type %31[^,], cobb_deg %lf, upper_end %7[^,], apex %7[^,], "
                      "lower_end %7[^,], apical_rotation_deg %lf, convex %7s",
                      type, &c.cobb_deg, upper, apex, lower, &c.apical_rotation_deg, convex) != 7 ||
          (std::strcmp(convex, "right") != 0 && std::strcmp(convex, "left") != 0))
        throw std::invalid_argument(path + ": a malformed scoliosis line: " + line);
      c.type = type, c.upper_end = upper, c.apex = apex, c.lower_end = lower;
      c.convex_right = std::strcmp(convex, "right") == 0;
      try {
        spine::check_scoliosis_curve(c);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(path + ": the recorded curve: " + e.what());
      }
    }
  }
  return r;
}

DragRecording read_drag_recording(const std::string& path, const spine::SpineModel& model) {
  // Streamed: a recording near the size limit is never held in memory as text besides its rows.
  std::ifstream in = open_regular_file(path, "the recording");
  DragRecording rec;
  rec.path = path;
  std::string line;
  int line_no = 0;
  bool header = false;
  std::string end_line;
  const std::string ours = spine_model_fingerprint(model);
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    // A last line without its newline is a row the killed run did not finish: dropped.
    if (in.eof()) break;
    if (line.rfind("# spine model ", 0) == 0) {
      std::istringstream h(line.substr(14));
      h >> rec.fingerprint;
      if (!rec.fingerprint.empty() && rec.fingerprint.back() == ';') rec.fingerprint.pop_back();
      std::string word;
      h >> word >> word >> rec.response;
      if (!rec.response.empty() && rec.response.back() == ';') rec.response.pop_back();
      if (rec.fingerprint != ours)
        throw std::invalid_argument(where + ": recorded with another spine model (fingerprint " +
                                    rec.fingerprint + ", this model " + ours + ")");
      continue;
    }
    if (line.rfind(kEndLine, 0) == 0) {
      end_line = line;
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      if (rec.fingerprint.empty())
        throw std::invalid_argument(path +
                                    ": not a compliant-stage recording (no spine model "
                                    "line: record with haptics run --spine …)");
      header = true;
      const std::string six = std::string(kSixDofHeader) + kSpineMomentHeader;
      rec.six_dof =
          line.size() >= six.size() && line.compare(line.size() - six.size(), six.size(), six) == 0;
      continue;
    }
    DragFrame f;
    std::string why;
    if (!parse_row(line, rec.six_dof, f, why)) throw std::invalid_argument(where + ": " + why);
    if (!rec.frames.empty() && f.tick != rec.frames.back().tick + 1)
      throw std::invalid_argument(where + ": missing frames: tick " + std::to_string(f.tick) +
                                  " follows tick " + std::to_string(rec.frames.back().tick));
    if (!(f.spine_moment_nmm.norm() <= spine::kMaxMomentNmm) || !(f.rotation_deg.norm() <= 180.001))
      throw std::invalid_argument(where + ": a hook moment beyond " +
                                  std::to_string(int(spine::kMaxMomentNmm)) +
                                  " N mm, or a stylus turned past half a turn");
    if (!(f.spine_force_n.norm() <= spine::kMaxForceN))
      throw std::invalid_argument(where + ": a hook force beyond " +
                                  std::to_string(int(spine::kMaxForceN)) +
                                  " N, more than the spine solve accepts");
    if (f.hook_vertebra < -1 || f.hook_vertebra >= kVertebrae)
      throw std::invalid_argument(where + ": hook vertebra out of range");
    // A vertebra moved beyond any spine's reach is a corrupt row, not a posture.
    const double shift = f.motion.leftCols<3>().rowwise().norm().maxCoeff(),
                 turn = f.motion.rightCols<3>().rowwise().norm().maxCoeff();
    if (!(shift <= kMaxVertebraShiftMm) || !(turn <= kMaxVertebraTurnDeg))
      throw std::invalid_argument(where + ": a vertebra moved " + significant(shift, 3) +
                                  " mm / turned " + significant(turn, 3) + " deg, beyond " +
                                  fixed(kMaxVertebraShiftMm, 0) + " mm / " +
                                  fixed(kMaxVertebraTurnDeg, 0) + " deg");
    rec.frames.push_back(f);
  }
  if (rec.fingerprint.empty())
    throw std::invalid_argument(path +
                                ": not a compliant-stage recording (no spine model line: "
                                "record with haptics run --spine …)");
  if (rec.frames.size() < 2)
    throw std::invalid_argument(path + ": " + std::to_string(rec.frames.size()) +
                                " recorded tick(s): at least two are needed to step between");
  // Whole only when the end line counts exactly the rows read and the run ended by itself.
  const std::string clean = kEndLine + std::to_string(rec.frames.size()) + " ticks";
  if (end_line.empty())
    rec.incomplete_reason = "no end line (the run was killed, or the file cut)";
  else if (end_line.rfind(clean, 0) != 0 ||
           (end_line.size() > clean.size() && end_line.compare(clean.size(), 2, "; ") != 0))
    rec.incomplete_reason = "the end line (\"" + end_line + "\") does not count the " +
                            std::to_string(rec.frames.size()) + " rows read";
  else if (end_line.size() > clean.size())
    rec.incomplete_reason = end_line.substr(clean.size() + 2);
  rec.complete = rec.incomplete_reason.empty();
  return rec;
}

}  // namespace spinesim::haptics
