#include "playback.hpp"

#include "field_surface.hpp"

#include "spinesim/haptics/recording.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/spine/model.hpp"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

namespace spinesim::viewer {
namespace {

/// Cell arrays that label rather than measure.
bool is_label(const std::string& name) {
  return name == "region" || name == "disc" || name == "body" || name == "surface";
}

/// The fields a tetrahedral frame can be coloured by: point arrays (by their magnitude) and
/// one-component cell arrays that are not labels.
std::vector<std::string> fields_of(const mesh::VtuGrid& g) {
  std::vector<std::string> out;
  for (const auto& a : g.point_data)
    if (!is_label(a.name)) out.push_back(a.name);
  for (const auto& a : g.cell_data)
    if (!is_label(a.name) && a.values.cols() == 1) out.push_back(a.name);
  return out;
}

/// A .pvd's entries, or one .vtu as a series of one frame at t = 0.
std::vector<mesh::PvdEntry> series(const std::string& path) {
  const bool vtu = path.size() > 4 && path.compare(path.size() - 4, 4, ".vtu") == 0;
  if (!vtu) return mesh::read_pvd(path);
  mesh::PvdEntry e;
  e.time_s = 0;
  e.part = 0;
  e.file = path;
  return {e};
}

/// Three-component cell arrays.
std::vector<std::string> vector_fields_of(const mesh::VtuGrid& g) {
  std::vector<std::string> out;
  for (const auto& a : g.cell_data)
    if (a.values.cols() == 3) out.push_back(a.name);
  return out;
}

/// Rod colours for the vector fields, in order.
const Eigen::Vector3f kRodColors[] = {{1.0f, 0.55f, 0.1f}, {0.2f, 0.85f, 1.0f}, {1, 1, 1}};

struct Part {
  std::vector<mesh::PvdEntry> entries;  ///< by time
  FieldSurface surface;                 ///< tetrahedral parts
  Eigen::Index cells = -1;              ///< the surface's cell count
};

class PlaybackController final : public Controller {
 public:
  PlaybackController(const PlaybackRequest& request, const std::string& data_dir,
                     PlaybackResult& result)
      : request_(request), result_(result), playing_(!request.paused) {
    for (const mesh::PvdEntry& e : series(request.pvd)) {
      parts_[e.part].entries.push_back(e);
      times_.insert(e.time_s);
    }
    result.times = int(times_.size());
    result.first_s = *times_.begin();
    result.last_s = *times_.rbegin();
    if (!(request.speed > 0) || request.speed > 1000)
      throw std::invalid_argument("--speed must be > 0 and at most 1000");
    if (!(request.at_s >= result.first_s - 1e-12 && request.at_s <= result.last_s + 1e-12))
      throw std::invalid_argument("--at " + std::to_string(request.at_s) +
                                  " s is outside the series (" + std::to_string(result.first_s) +
                                  " to " + std::to_string(result.last_s) + " s)");
    time_ = std::max(request.at_s, result.first_s);
    // The fields the tetrahedral parts offer (from the first frame), and the one asked for.
    for (auto& [k, part] : parts_) {
      const mesh::VtuGrid g = mesh::read_vtu_grid(part.entries.front().file);
      if (g.cell_type == 10)
        for (const std::string& f : fields_of(g))
          if (std::find(fields_.begin(), fields_.end(), f) == fields_.end()) fields_.push_back(f);
    }
    result.fields = fields_;
    check_vectors();
    if (!fields_.empty()) {
      const auto it = std::find(fields_.begin(), fields_.end(), request.field);
      if (it == fields_.end()) {
        std::string list;
        for (const auto& f : fields_) list += (list.empty() ? "" : ", ") + f;
        throw std::invalid_argument("--field " + request.field + ": the series has " + list);
      }
      field_ = int(it - fields_.begin());
    }
    if (!request.recording.empty()) {
      model_ = std::make_unique<spine::SpineModel>(spine::load_spine_model(data_dir));
      recording_ = haptics::read_drag_recording(request.recording, *model_);
    }
  }

  void check_vectors() {
    std::vector<std::string> have;
    for (auto& [k, part] : parts_) {
      const mesh::VtuGrid g = mesh::read_vtu_grid(part.entries.front().file);
      if (g.cell_type == 10)
        for (const std::string& f : vector_fields_of(g)) have.push_back(f);
    }
    for (const std::string& v : request_.vectors)
      if (std::find(have.begin(), have.end(), v) == have.end()) {
        std::string list;
        for (const auto& f : have) list += (list.empty() ? "" : ", ") + f;
        throw std::invalid_argument("--vectors " + v + ": the series' cell vector fields are " +
                                    (list.empty() ? std::string("none") : list));
      }
  }

  void update(SceneFrame& scene, const Pointer&) override {
    const auto now = std::chrono::steady_clock::now();
    if (last_wall_) {
      const double dt = std::chrono::duration<double>(now - *last_wall_).count();
      if (playing_) time_ += dt * request_.speed;
      if (time_ >= result_.last_s) time_ = result_.last_s, playing_ = false;
    }
    last_wall_ = now;
    load(scene, time_);
    overlay(scene, time_);
  }

  void panel() override {
    ImGui::Text("%s", request_.pvd.c_str());
    if (ImGui::Button(playing_ ? "pause" : "play")) {
      if (!playing_ && time_ >= result_.last_s) time_ = result_.first_s;
      playing_ = !playing_;
    }
    ImGui::SameLine();
    float speed = float(request_.speed);
    ImGui::SetNextItemWidth(120);
    if (ImGui::SliderFloat("speed", &speed, 0.05f, 4.0f, "%.2fx")) request_.speed = speed;
    float t = float(time_);
    ImGui::SetNextItemWidth(320);
    if (ImGui::SliderFloat("t (s)", &t, float(result_.first_s), float(result_.last_s), "%.3f"))
      time_ = t, playing_ = false;
    ImGui::Text("frame %d of %d at %.3f s | %d frames read, %.1f ms each", index_ + 1,
                result_.times, shown_time_, result_.loads,
                result_.loads ? load_ms_ / result_.loads : 0.0);
    if (!fields_.empty()) {
      std::vector<const char*> names;
      for (const auto& f : fields_) names.push_back(f.c_str());
      if (ImGui::Combo("field", &field_, names.data(), int(names.size()))) shown_time_ = -1;
      color_legend(fields_[std::size_t(field_)].c_str(), lo_, hi_);
    }
    for (std::size_t k = 0; k < request_.vectors.size(); ++k) {
      const Eigen::Vector3f& c = kRodColors[std::min<std::size_t>(k, 2)];
      ImGui::TextColored(ImVec4(c.x(), c.y(), c.z(), 1), "rods: %s", request_.vectors[k].c_str());
    }
    if (recording_)
      ImGui::Text("recording %s: probe blue, hook yellow, spine force orange",
                  recording_->complete ? "complete" : "cut short");
  }

 private:
  PlaybackRequest request_;
  PlaybackResult& result_;
  std::map<int, Part> parts_;
  std::set<double> times_;
  std::vector<std::string> fields_;
  int field_ = 0, index_ = 0;
  bool playing_ = true;
  double time_ = 0, shown_time_ = -1, lo_ = 0, hi_ = 0, load_ms_ = 0;
  std::optional<std::chrono::steady_clock::time_point> last_wall_;
  std::unique_ptr<spine::SpineModel> model_;
  std::optional<haptics::DragRecording> recording_;
  std::vector<Marker> glyphs_;  ///< the vector rods of the frame shown

  /// The series' frame at or before `t`: each part's VTU, read when the frame changes.
  void load(SceneFrame& scene, double t) {
    const auto it = times_.upper_bound(t + 1e-12);
    const double at = it == times_.begin() ? *times_.begin() : *std::prev(it);
    if (at == shown_time_) return;
    index_ = int(std::distance(times_.begin(), times_.upper_bound(at + 1e-12))) - 1;
    const auto start = std::chrono::steady_clock::now();
    scene.bodies.resize(parts_.size());
    glyphs_.clear();
    std::size_t b = 0;
    for (auto& [k, part] : parts_) {
      // The part's last entry at or before `at` (a part may have fewer frames).
      const mesh::PvdEntry* e = &part.entries.front();
      for (const auto& x : part.entries)
        if (x.time_s <= at + 1e-12) e = &x;
      show(scene.bodies[b++], part, mesh::read_vtu_grid(e->file));
    }
    load_ms_ +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ++result_.loads;
    result_.mean_load_ms = load_ms_ / result_.loads;
    shown_time_ = at;
  }

  void show(Body& body, Part& part, const mesh::VtuGrid& g) {
    if (g.cell_type != 10) {  // a surface: the vertebrae
      body.name = "surface";
      body.V = g.V;
      body.F = g.cells;
      body.face_colors.resize(0, 3);
      ++body.revision;
      return;
    }
    if (part.cells != g.cells.rows())
      part.surface = FieldSurface(g.cells), part.cells = g.cells.rows();
    body.name = "tetrahedra";
    // A mesh without fields (`spinesim mesh disc --out`) is drawn in one colour.
    const std::string name = fields_.empty() ? "" : fields_[std::size_t(field_)];
    Eigen::VectorXd values;
    double floor = 0.01;
    for (const auto& a : g.point_data)
      if (a.name == name)
        values = part.surface.from_points(a.values.rowwise().norm()), floor = 0.05;
    for (const auto& a : g.cell_data)
      if (a.name == name && a.values.cols() == 1) values = part.surface.from_cells(a.values.col(0));
    if (values.size() == 0)  // this frame lacks the field: its lowest colour
      values = part.surface.from_cells(Eigen::VectorXd::Zero(g.cells.rows()));
    FieldSurface::range(values, floor, lo_, hi_);
    part.surface.fill(body, g.V, values, lo_, hi_);
    add_glyphs(part, g);
  }

  /// Rods along each requested cell vector, through the centroid of every boundary face (lifted
  /// a little off the surface), 0.7 of the face's mean edge long.
  void add_glyphs(const Part& part, const mesh::VtuGrid& g) {
    const Eigen::MatrixX3i& F = part.surface.faces();
    const Eigen::VectorXi& owner = part.surface.owners();
    for (std::size_t k = 0; k < request_.vectors.size(); ++k) {
      const mesh::DataArray* a = g.cell_array(request_.vectors[k]);
      if (a == nullptr || a->values.cols() != 3) continue;
      for (Eigen::Index f = 0; f < F.rows(); ++f) {
        const Eigen::Vector3d d = a->values.row(owner(f)).transpose();
        if (!d.allFinite() || !(d.norm() > 1e-12)) continue;
        const Eigen::Vector3d p0 = g.V.row(F(f, 0)), p1 = g.V.row(F(f, 1)), p2 = g.V.row(F(f, 2));
        const Eigen::Vector3d c = (p0 + p1 + p2) / 3, n = (p1 - p0).cross(p2 - p0).normalized();
        const double edge = ((p1 - p0).norm() + (p2 - p1).norm() + (p0 - p2).norm()) / 3;
        const Eigen::Vector3d half = 0.35 * edge * d.normalized();
        const Eigen::Vector3d lifted = c + 0.15 * edge * n;
        glyphs_.push_back({Marker::Kind::rod, lifted - half, lifted + half, 0.06 * edge,
                           kRodColors[std::min<std::size_t>(k, 2)]});
      }
    }
    result_.glyphs = int(glyphs_.size());
  }

  void overlay(SceneFrame& scene, double t) {
    scene.markers = glyphs_;
    if (!recording_ || recording_->frames.empty()) return;
    const auto& fr = recording_->frames;
    const auto it = std::lower_bound(
        fr.begin(), fr.end(), t, [](const haptics::DragFrame& f, double x) { return f.t_s < x; });
    const haptics::DragFrame& f = it == fr.end() ? fr.back() : *it;
    scene.markers.push_back({Marker::Kind::sphere, f.probe_mm, f.probe_mm, 4, {0.35f, 0.65f, 1}});
    if (f.attached) {
      scene.markers.push_back({Marker::Kind::sphere, f.hook_mm, f.hook_mm, 2, {1, 0.85f, 0.1f}});
      scene.markers.push_back({Marker::Kind::arrow, f.hook_mm, f.probe_mm, 0.8, {1, 0.85f, 0.1f}});
      if (f.spine_force_n.norm() > 1)
        scene.markers.push_back(
            {Marker::Kind::arrow, f.hook_mm, f.hook_mm + 0.1 * f.spine_force_n, 1.2, {1, 0.5f, 0}});
    }
  }
};

}  // namespace

PlaybackResult view_playback(const PlaybackRequest& request, const std::string& data_dir,
                             const ViewOptions& options) {
  check(options);
  PlaybackResult result;
  PlaybackController controller(request, data_dir, result);
  result.view = view(controller, options);
  return result;
}

}  // namespace spinesim::viewer
