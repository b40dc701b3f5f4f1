#include "spinesim/haptics/scene_builder.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/tube.hpp"
#include "spinesim/mesh/vertebra_cache.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/spine/rib_cage.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

namespace spinesim::haptics {

namespace fs = std::filesystem;

namespace {

const char* kRealFolder = "artisynth-lss";

mesh::TriSurface transformed(const mesh::TriSurface& s, const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& t) {
  mesh::TriSurface out = s;
  out.V = (s.V * R.transpose()).rowwise() + t.transpose();
  return out;
}

fs::path real_folder(const std::string& testdata_dir) {
  const fs::path dir = fs::path(testdata_dir) / kRealFolder;
  if (testdata_dir.empty() || !fs::is_directory(dir))
    throw std::invalid_argument("--vertebrae real: the test data folder " + dir.string() +
                                " is absent (give --testdata DIR holding " + kRealFolder + "/)");
  return dir;
}

// The ArtiSynth files are in metres with z up; the mapping of io.hpp sends file x to anterior.
// Check that against the anatomy — the whole vertebra's centroid lies behind its body's (the
// neural arch) — and turn the surfaces about the vertical by 180° if it does not.
mesh::TriSurface read_real(const fs::path& dir, const std::string& file, bool flip) {
  mesh::TriSurface s = mesh::read_surface((dir / file).string(), 1000.0, mesh::UpAxis::z);
  if (flip) s.V.col(0) *= -1, s.V.col(2) *= -1;
  return s;
}

bool real_needs_flip(const fs::path& dir) {
  const Eigen::Vector3d body = mesh::surface_centroid(read_real(dir, "L3_body.obj", false));
  const Eigen::Vector3d whole =
      mesh::surface_centroid(read_real(dir, "L3_Schrumpfverpacken.obj", false));
  return whole.z() > body.z();
}

// Least-squares rigid motion in the sagittal plane (rotation about x, translation) taking
// points P to Q (2-D Kabsch on (y, z); x is translated by the mean difference).
void sagittal_kabsch(const std::vector<Eigen::Vector3d>& P, const std::vector<Eigen::Vector3d>& Q,
                     Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  Eigen::Vector3d pm = Eigen::Vector3d::Zero(), qm = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < P.size(); ++i) pm += P[i], qm += Q[i];
  pm /= double(P.size());
  qm /= double(Q.size());
  double sxx = 0, sxy = 0;  // Σ (p × q)·x and Σ p·q in the (y, z) plane
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Eigen::Vector2d p(P[i].y() - pm.y(), P[i].z() - pm.z());
    const Eigen::Vector2d q(Q[i].y() - qm.y(), Q[i].z() - qm.z());
    sxy += p.x() * q.y() - p.y() * q.x();
    sxx += p.dot(q);
  }
  const double angle = std::atan2(sxy, sxx);
  *R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
  *t = qm - *R * pm;
}

const std::vector<std::string>& real_names() {
  static const std::vector<std::string> names = {"L1", "L2", "L3", "L4", "L5", "S1"};
  return names;
}

Registration register_with(const fs::path& dir, bool flip, const std::string& data_dir) {
  std::vector<Eigen::Vector3d> real, model;
  Registration reg;
  for (const auto& name : real_names()) {
    real.push_back(mesh::surface_centroid(read_real(dir, name + "_body.obj", flip)));
    model.push_back(mesh::parametric_vertebra(name, data_dir).frame.origin_mm);
    reg.names.push_back(name);
  }
  sagittal_kabsch(real, model, &reg.R, &reg.t);
  double sum = 0;
  for (std::size_t i = 0; i < real.size(); ++i) {
    const double d = (reg.R * real[i] + reg.t - model[i]).norm();
    reg.residual_mm.push_back(d);
    sum += d * d;
  }
  reg.rms_mm = std::sqrt(sum / double(real.size()));
  return reg;
}

// A scene file: {"source": …, "bodies": [{"name": "L3", "surface": "L3.stl", "units": "mm",
// "up": "y", "transform": [[r00, r01, r02, t0], [..], [..]]}, …]}; the transform (a rotation and
// a translation in mm) takes the file's coordinates, after units and up axis, into the named
// vertebra's frame (origin at its body centre, x lateral, y along the body, z anterior).
struct SceneEntry {
  std::string name, file;
  mesh::TriSurface surface;  ///< in the vertebra's frame
};

std::vector<SceneEntry> read_scene_file(const std::string& path) {
  const nlohmann::json j = read_json_file(path, "the scene file");
  const auto refuse = [&](const std::string& why) {
    return std::invalid_argument("scene file '" + path + "': " + why);
  };
  if (!j.is_object() || !j.contains("bodies") || !j["bodies"].is_array() || j["bodies"].empty())
    throw refuse("needs a non-empty \"bodies\" array");
  std::vector<SceneEntry> out;
  std::set<std::string> seen;
  const auto& known = mesh::scene_body_names();
  for (std::size_t k = 0; k < j["bodies"].size(); ++k) {
    const auto& b = j["bodies"][k];
    const std::string where = "body " + std::to_string(k + 1);
    if (!b.is_object() || !b.contains("name") || !b["name"].is_string() || !b.contains("surface") ||
        !b["surface"].is_string())
      throw refuse(where + " needs \"name\" and \"surface\" strings");
    SceneEntry e;
    e.name = b["name"].get<std::string>();
    if (std::find(known.begin(), known.end(), e.name) == known.end())
      throw refuse(where + ": unknown vertebra '" + e.name + "' (T1…L5, S1)");
    if (!seen.insert(e.name).second) throw refuse(where + ": " + e.name + " appears twice");
    const std::string units = b.value("units", std::string("mm"));
    const std::map<std::string, double> scale = {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}};
    if (!scale.count(units)) throw refuse(where + ": units must be mm, cm or m");
    const std::string up = b.value("up", std::string("y"));
    const std::map<std::string, mesh::UpAxis> axes = {
        {"x", mesh::UpAxis::x},        {"y", mesh::UpAxis::y},
        {"z", mesh::UpAxis::z},        {"-x", mesh::UpAxis::minus_x},
        {"-y", mesh::UpAxis::minus_y}, {"-z", mesh::UpAxis::minus_z}};
    if (!axes.count(up)) throw refuse(where + ": up must be x, y, z, -x, -y or -z");
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    if (b.contains("transform")) {
      const auto& T = b["transform"];
      bool ok = T.is_array() && (T.size() == 3 || T.size() == 4);
      for (std::size_t r = 0; ok && r < 3; ++r) {
        ok = T[r].is_array() && T[r].size() == 4;
        for (std::size_t c = 0; ok && c < 4; ++c) {
          ok = T[r][c].is_number() && std::isfinite(T[r][c].get<double>());
          if (ok) (c < 3 ? R(long(r), long(c)) : t(long(r))) = T[r][c].get<double>();
        }
      }
      if (!ok) throw refuse(where + ": \"transform\" must be 3 or 4 rows of 4 finite numbers");
      if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
          R.determinant() < 0)
        throw refuse(where + ": the transform's 3x3 part is not a rotation (orthonormal, det +1)");
      if (t.norm() > 1e4) throw refuse(where + ": the translation is beyond 10 m");
    }
    e.file = (fs::path(path).parent_path() / b["surface"].get<std::string>()).string();
    e.surface = transformed(mesh::read_surface(e.file, scale.at(units), axes.at(up)), R, t);
    const auto c = e.surface.V.colwise().mean();
    if ((e.surface.V.rowwise() - c).rowwise().norm().maxCoeff() > 500)
      throw refuse(where + ": the surface spans more than a metre: wrong units?");
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace

Registration register_real_vertebrae(const std::string& testdata_dir, const std::string& data_dir) {
  const fs::path dir = real_folder(testdata_dir);
  return register_with(dir, real_needs_flip(dir), data_dir);
}

nlohmann::json registration_json(const Registration& r) {
  nlohmann::json per = nlohmann::json::object();
  for (std::size_t i = 0; i < r.names.size(); ++i) per[r.names[i]] = r.residual_mm[i];
  return {{"method",
           "one rigid motion (rotation about the lateral axis + translation) fitting the real "
           "body centroids to the model's body centres L1-L5, S1"},
          {"rotation_about_x_deg", std::atan2(r.R(2, 1), r.R(1, 1)) * kDegPerRad},
          {"translation_mm", {r.t.x(), r.t.y(), r.t.z()}},
          {"residual_mm", per},
          {"rms_mm", r.rms_mm}};
}

namespace {

/// The ribs (with their cartilage) and the sternum as tubes at the reference posture. Cross
/// sections: a rib's shaft about 12 × 6 mm, its cartilage 10 × 6 mm, the sternum 30 × 10 mm
/// (drawn and touched; the cage's mechanics do not depend on them).
void add_rib_cage_bodies(HapticScene& out, const std::string& data_dir,
                         const spine::Subject& subject) {
  spine::ModelOptions body;
  body.subject = subject;
  body.rib_cage = true;
  const spine::SpineModel model = spine::load_spine_model(data_dir, body);
  const spine::RibCage& cage = *model.rib_cage;
  mesh::TubeOptions o;
  o.width_direction = Eigen::Vector3d::UnitY();  // a rib's broad faces look in and out
  for (const spine::Rib& rib : cage.ribs) {
    std::vector<Eigen::Vector3d> p{rib.head_mm, rib.tubercle_mm, rib.lateral_mm, rib.front_mm};
    const double s = model.scale.length;  // the sections scale with the body too
    std::vector<double> w{5 * s, 6 * s, 6 * s, 6 * s}, d(4, 3 * s);
    if ((rib.cartilage_end_mm - rib.front_mm).norm() > 1) {
      p.push_back(rib.cartilage_end_mm);
      w.push_back(5 * s);
      d.push_back(3 * s);
    }
    out.scene.add_body(rib.name, mesh::tube_surface(p, w, d, o));
    out.sources.push_back("generated");
  }
  o.width_direction = Eigen::Vector3d::UnitX();
  o.sides = 16;
  const double s = model.scale.length;
  out.scene.add_body("sternum", mesh::tube_surface({cage.sternum_top_mm, cage.sternum_bottom_mm},
                                                   {18 * s, 13 * s}, {5 * s, 5 * s}, o));
  out.sources.push_back("generated");
}

std::string degrees(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}

/// Where each body of the spine goes, by name: the body's length scale s about the origin (the
/// model's scaling, spine/README.md), then its pose in a scoliotic curve's rest posture
/// (identity when straight, and for the sacrum).
struct Placement {
  double scale = 1;
  std::map<std::string, spine::Pose> poses;
  mesh::TriSurface place(const std::string& name, const mesh::TriSurface& s) const {
    const auto p = poses.find(name);
    const spine::Pose P = p == poses.end() ? spine::Pose() : p->second;
    return transformed(s, scale * P.R, P.t);
  }
};

spine::ModelOptions body_options(const HapticSceneRequest& r) {
  spine::ModelOptions o;
  o.gravity = o.muscles = false;
  o.subject = r.subject;
  o.scoliosis = r.scoliosis;
  return o;
}

Placement placement(const HapticSceneRequest& r, const std::string& data_dir) {
  Placement out;
  if (r.scene != "spine" ||
      (r.scoliosis.cobb_deg == 0 && r.subject.height_m == 0 && r.subject.body_mass_kg == 0))
    return out;
  const spine::SpineModel m = spine::load_spine_model(data_dir, body_options(r));
  out.scale = m.scale.length;
  if (m.rest_posture.size() == 0) return out;
  const std::vector<spine::Pose> P = spine::vertebra_poses(m, m.rest_posture);
  for (std::size_t i = 0; i < P.size(); ++i) out.poses[spine::vertebra_names()[i]] = P[i];
  return out;
}

/// "the spine T1-L5 + sacrum (WHAT) with the rib cage of a female body 1.6 m tall in a 30 deg
/// thoracic scoliosis", as much of it as the request asks for.
std::string spine_description(const HapticSceneRequest& r, const std::string& what) {
  std::string d = "the spine T1-L5 + sacrum (" + what + ")";
  if (r.rib_cage) d += " with the rib cage";
  const spine::Subject& b = r.subject;
  if (b.height_m != 0 || b.body_mass_kg != 0 || b.sex != spine::Sex::Male) {
    d += std::string(" of a ") + spine::sex_name(b.sex) + " body";
    if (b.height_m != 0) d += " " + degrees(b.height_m) + " m tall";
  }
  return d + (r.scoliosis.cobb_deg != 0 ? " in a " + degrees(r.scoliosis.cobb_deg) + " deg " +
                                              r.scoliosis.type + " scoliosis"
                                        : " at the reference posture");
}

}  // namespace

void check_scene_name(const std::string& scene) {
  if (scene != "plane" && scene != "vertebra" && scene != "spine" && scene != "disc")
    throw std::invalid_argument("--scene " + scene + ": give spine, vertebra, disc or plane");
}

HapticScene build_haptic_scene(const HapticSceneRequest& r, const std::string& data_dir,
                               const std::function<void(int, int)>& progress) {
  const Timer timer;
  HapticScene out;
  check_scene_name(r.scene);
  if (r.rib_cage && r.scene != "spine")
    throw std::invalid_argument("--rib-cage is for --scene spine");
  if (r.scoliosis.cobb_deg != 0 && r.scene != "spine")
    throw std::invalid_argument("--scoliosis is for --scene spine");
  if (r.scoliosis.cobb_deg != 0 && r.rib_cage)
    throw std::invalid_argument(
        "--scoliosis with --rib-cage: not modelled (the ribs' scoliotic shape is unknown)");
  std::vector<std::string> level_bodies;
  if (r.scene == "disc") {
    mesh::disc_dimensions(r.level, data_dir);  // a known level
    const std::size_t dash = r.level.find('-');
    level_bodies = {r.level.substr(0, dash), r.level.substr(dash + 1)};
  }
  if (r.triangles < 100 || r.triangles > 200000)
    throw std::invalid_argument("--triangles " + std::to_string(r.triangles) +
                                ": give 100 to 200,000 per vertebra");
  // Every source is read (and refused) before any meshing.
  std::map<std::string, std::pair<mesh::TriSurface, std::string>> given;  // world surfaces
  if (r.vertebrae == "real") {
    const fs::path dir = real_folder(r.testdata_dir);
    const bool flip = real_needs_flip(dir);
    out.registration = register_with(dir, flip, data_dir);
    out.registered = true;
    for (const auto& name : real_names())
      given[name] = {transformed(read_real(dir, name + "_Schrumpfverpacken.obj", flip),
                                 out.registration.R, out.registration.t),
                     "real"};
  } else if (r.vertebrae != "generated") {
    if (!fs::exists(r.vertebrae))
      throw std::invalid_argument("--vertebrae " + r.vertebrae +
                                  ": no such scene file (give generated, real, or a scene JSON "
                                  "file)");
    for (auto& e : read_scene_file(r.vertebrae)) {
      const auto frame = mesh::parametric_vertebra(e.name, data_dir).frame;
      given[e.name] = {transformed(e.surface, frame.axes, frame.origin_mm), e.file};
    }
  }

  if (r.scene == "plane") {
    out.scene.add_body("plane", haptics::square_plane(100, 2));
    out.sources.push_back("generated");
    out.description = "a plane z = 0 (100 x 100 mm, normal +z)";
  } else {
    const std::vector<std::string> names = r.scene == "spine"  ? mesh::scene_body_names()
                                           : r.scene == "disc" ? level_bodies
                                                               : std::vector<std::string>{"L3"};
    const Placement where = placement(r, data_dir);
    auto add = [&](const std::string& name, const mesh::TriSurface& surface) {
      out.scene.add_body(name, where.place(name, surface));
    };
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto it = given.find(names[i]);
      if (it != given.end()) {
        add(names[i], it->second.first);
        out.sources.push_back(it->second.second);
      } else {
        const auto v = mesh::parametric_vertebra(names[i], data_dir);
        bool hit = false;
        const std::string cache = r.cache_dir == "none" ? "" : r.cache_dir;
        add(names[i], mesh::cached_vertebra_surface(v, r.triangles, cache, &hit).surface);
        out.sources.push_back("generated");
        out.cached += hit;
      }
      if (progress) progress(int(i + 1), int(names.size()));
    }
    const std::string what = r.vertebrae == "generated" ? "parametric"
                             : r.vertebrae == "real" ? "real L1-S1 (ArtiSynth), parametric thoracic"
                                                     : "scene file + parametric";
    if (r.rib_cage) add_rib_cage_bodies(out, data_dir, r.subject);
    out.description = r.scene == "spine"  ? spine_description(r, what)
                      : r.scene == "disc" ? "the " + r.level + " disc between " + names[0] +
                                                " and " + names[1] + " (" + what + ")"
                                          : "L3 (" + what + ") at its reference posture";
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (int i = 0; i < out.scene.size(); ++i) {
    lo = lo.cwiseMin(out.scene.body(i).tree.bounds_min());
    hi = hi.cwiseMax(out.scene.body(i).tree.bounds_max());
  }
  out.center_mm = 0.5 * (lo + hi);
  out.seconds = timer.seconds();
  return out;
}

}  // namespace spinesim::haptics
