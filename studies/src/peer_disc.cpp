#include "spinesim/studies/peer_disc.hpp"

#include "spinesim/mesh/fibre_field.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/studies/mesh_report.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <filesystem>

namespace spinesim::studies {
namespace {

/// Angle between two lines (unit vectors up to sign), deg.
double line_angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.dot(b)))) * 180.0 / M_PI;
}

void compare_fibres(PeerDiscResult& r, const std::string& data_dir) {
  mesh::TetMesh bare = r.mesh;  // ours: the field laid along the annulus geometry alone
  bare.fibre_paths = {};
  const mesh::ElementFibres ours =
      mesh::fibre_field(bare, mesh::load_material("fibre-reinforced", data_dir));
  const Eigen::Vector3d axis = r.mesh.frame.axes.col(1);
  double pair = 0, peer_incl = 0, our_incl = 0;
  Eigen::Index n = 0;
  for (Eigen::Index t = 0; t < r.mesh.num_tets(); ++t) {
    const Eigen::Vector3d p1 = r.fibres.direction_1.row(t), p2 = r.fibres.direction_2.row(t);
    if (p1.squaredNorm() == 0 || p2.squaredNorm() == 0 || ours.empty() || !(ours.stiffness_mpa(t) > 0))
      continue;
    const Eigen::Vector3d o1 = ours.direction_1.row(t), o2 = ours.direction_2.row(t);
    pair += 0.5 * std::min(line_angle_deg(o1, p1) + line_angle_deg(o2, p2),
                           line_angle_deg(o1, p2) + line_angle_deg(o2, p1));
    peer_incl += 0.5 * (90 - line_angle_deg(p1, axis) + 90 - line_angle_deg(p2, axis));
    our_incl += 0.5 * (90 - line_angle_deg(o1, axis) + 90 - line_angle_deg(o2, axis));
    ++n;
  }
  if (n == 0) return;
  r.mean_pair_angle_deg = pair / double(n);
  r.peer_inclination_deg = peer_incl / double(n);
  r.our_inclination_deg = our_incl / double(n);
}

}  // namespace

PeerDiscResult import_peer_disc(const PeerDiscRequest& rq, const std::string& data_dir) {
  mesh::artisynth_level_prefix(rq.level);  // a bad level before anything is read
  if (!std::filesystem::is_directory(rq.folder))
    throw std::invalid_argument("--artisynth '" + rq.folder + "': no such folder");
  if (!rq.out.empty()) require_output_folder(rq.out, "--out");
  PeerDiscResult r;
  r.mesh = mesh::read_artisynth_disc(rq.folder, rq.level);
  r.hexahedra = r.mesh.num_tets() / 6;
  r.quality = mesh::quality_report(r.mesh);
  r.fibres = mesh::peer_fibre_field(r.mesh, mesh::read_artisynth_fibres(rq.folder, rq.level));
  compare_fibres(r, data_dir);
  if (rq.fibre_paths) r.mesh.fibre_paths = {r.fibres.direction_1, r.fibres.direction_2};
  if (!rq.out.empty()) mesh::write_vtu(rq.out, r.mesh);
  return r;
}

nlohmann::json peer_disc_json(const PeerDiscResult& r, const PeerDiscRequest& rq) {
  nlohmann::json j = quality_json(r.quality);
  j["source"] = r.mesh.source;
  j["level"] = rq.level;
  j["hexahedra"] = r.hexahedra;
  j["disc_frame"] = {{"origin_mm", to_json(Eigen::VectorXd(r.mesh.frame.origin_mm))},
                     {"axes", to_json(Eigen::MatrixXd(r.mesh.frame.axes))}};
  j["fibres"] = {{"mean_pair_angle_to_ours_deg", r.mean_pair_angle_deg},
                 {"peer_inclination_deg", r.peer_inclination_deg},
                 {"our_inclination_deg", r.our_inclination_deg},
                 {"ours", "the fibre-reinforced preset's field on this mesh"},
                 {"fibre_paths", rq.fibre_paths ? "the peer's (a fibre material follows them)"
                                                : "none (a fibre material follows the "
                                                  "annulus geometry)"}};
  j["out"] = path_or_null(rq.out);
  return j;
}

}  // namespace spinesim::studies
