#include "spinesim/studies/cohort_study.hpp"

#include "spinesim/calibration/protocol.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/output/format.hpp"
#include "spinesim/output/table.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/mesh_disc.hpp"
#include "spinesim/studies/peer_disc.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <ostream>
#include <stdexcept>

namespace spinesim::studies {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Built {
  CohortMember member;
  mesh::TetMesh mesh;
};

bool lumbar(const std::string& level) {
  return level == "L1-L2" || level == "L2-L3" || level == "L3-L4" || level == "L4-L5" ||
         level == "L5-S1";
}

MeshDiscRequest parametric(const CohortRequest& r) {
  MeshDiscRequest m;
  m.level = r.level;
  m.cgal.cell_size_mm = r.cell_size_mm;
  return m;
}

/// Runs `make`; a failure leaves the member skipped with the reason.
template <class Make>
Built build(const std::string& name, const std::string& source, Make make) {
  Built b;
  b.member.name = name;
  b.member.source = source;
  try {
    b.mesh = make();
    b.member.tets = long(b.mesh.num_tets());
    b.member.volume_mm3 = mesh::mesh_volume(b.mesh);
  } catch (const std::exception& e) {
    b.member.skipped = e.what();
  }
  return b;
}

std::vector<Built> build_members(const CohortRequest& r, const std::string& data_dir,
                                 const StageHooks& hooks) {
  std::vector<Built> out;
  hooks.begin_stage("meshing the " + r.level + " discs");
  out.push_back(build("parametric", "the parametric disc (mesh disc --level)",
                      [&] { return run_mesh_disc(parametric(r), data_dir).mesh; }));
  const fs::path lss = fs::path(r.testdata_dir) / "artisynth-lss";
  const bool have = !r.testdata_dir.empty() && fs::is_directory(lss);
  const std::string upper = r.level.substr(0, r.level.find('-'));
  const std::string lower = r.level.substr(r.level.find('-') + 1);
  if (lumbar(r.level)) {
    out.push_back(build("vertebrae",
                        "between the real " + upper + " and " + lower +
                            " vertebral bodies (ArtiSynth lumbosacral model)",
                        [&]() -> mesh::TetMesh {
                          if (!have) throw std::runtime_error("no test data (artisynth-lss)");
                          MeshDiscRequest m;
                          m.inferior = (lss / (lower + "_body.obj")).string();
                          m.superior = (lss / (upper + "_body.obj")).string();
                          m.surface_mm_per_unit = 1000;
                          m.up = mesh::UpAxis::z;
                          m.cgal.cell_size_mm = r.cell_size_mm;
                          return run_mesh_disc(m, data_dir).mesh;
                        }));
    out.push_back(build("peer", "the peer model's hexahedral FE disc (ArtiSynth, as tets)",
                        [&]() -> mesh::TetMesh {
                          if (!have) throw std::runtime_error("no test data (artisynth-lss)");
                          PeerDiscRequest p;
                          p.folder = (lss / "fe-discs").string();
                          p.level = r.level;
                          return import_peer_disc(p, data_dir).mesh;
                        }));
  }
  for (const std::string& body : r.bodies)
    out.push_back(build(body, "the parametric disc of " + body + "'s spine", [&] {
      MeshDiscRequest m = parametric(r);
      m.subject = spine::named_body(data_dir, body).subject;
      return run_mesh_disc(m, data_dir).mesh;
    }));
  hooks.end_stage();
  return out;
}

/// Mean displacement error over the cases named in `names` (all cases when empty).
double mean_error(const calibration::MssFemComparison& c, const std::vector<std::string>& names) {
  double sum = 0;
  int n = 0;
  for (const auto& k : c.cases) {
    if (!names.empty() && std::find(names.begin(), names.end(), k.name) == names.end()) continue;
    sum += k.converged ? k.displacement_error : kNaN;
    ++n;
  }
  return n ? sum / n : kNaN;
}

std::vector<std::string> names_of(const std::vector<fem::LoadCase>& cases) {
  std::vector<std::string> out;
  for (const auto& c : cases) out.push_back(c.name);
  return out;
}

}  // namespace

int cohort_stages(const CohortRequest& request) { return 2 + (request.own_fits ? 1 : 0); }

CohortResult run_cohort_level(const CohortRequest& request, const std::string& data_dir,
                              const StageHooks& hooks) {
  Timer timer;
  CohortResult r;
  r.request = request;
  if (!(request.cell_size_mm > 0 && request.cell_size_mm <= 20))
    throw std::invalid_argument("cohort: the cell size must be within 0 … 20 mm");
  for (const auto& b : request.bodies) spine::named_body(data_dir, b);  // refuses unknown names
  const mesh::RegionMaterials materials = mesh::load_material(request.material, data_dir);
  std::vector<Built> built = build_members(request, data_dir, hooks);
  if (!built.front().member.skipped.empty())
    throw std::invalid_argument("cohort: " + built.front().member.skipped);

  calibration::CalibrationRequest rq;
  rq.train = fem::parse_load_cases("compression,shear-ap,flexion,torsion");
  rq.holdout = calibration::held_out_cases(rq.train);
  r.train = names_of(rq.train);
  r.holdout = names_of(rq.holdout);
  std::vector<std::size_t> carried;  // members carried as transfer meshes, in order
  for (std::size_t i = 1; i < built.size(); ++i)
    if (built[i].member.skipped.empty()) {
      rq.transfer_meshes.emplace_back(built[i].member.name, built[i].mesh);
      carried.push_back(i);
    }
  hooks.begin_stage("calibrating the parametric disc, its constants on " +
                    std::to_string(carried.size()) + " other discs");
  Timer reference_timer;
  const calibration::CalibrationOutcome ref =
      calibration::calibrate_disc(built[0].mesh, materials, rq);
  r.reference_converged = ref.result.success;
  CohortMember& p = built[0].member;
  p.untuned = mean_error(ref.untuned_check, r.holdout);
  p.untuned_all = mean_error(ref.untuned_check, {});
  p.transfer = p.own = mean_error(ref.tuned_check, r.holdout);
  p.transfer_all = p.own_all = mean_error(ref.tuned_check, {});
  p.own_fit_converged = ref.result.success;
  p.seconds = reference_timer.seconds();
  for (std::size_t k = 0; k < carried.size(); ++k) {
    CohortMember& m = built[carried[k]].member;
    m.untuned = mean_error(ref.transfer[k].untuned, r.holdout);
    m.untuned_all = mean_error(ref.transfer[k].untuned, {});
    m.transfer = mean_error(ref.transfer[k].tuned, r.holdout);
    m.transfer_all = mean_error(ref.transfer[k].tuned, {});
    m.own = m.own_all = kNaN;
  }
  hooks.end_stage();
  if (request.own_fits) {
    hooks.begin_stage("calibrating each of the " + std::to_string(carried.size()) +
                      " other discs on itself");
    calibration::CalibrationRequest own = rq;
    own.transfer_meshes.clear();
    for (std::size_t i : carried) {
      Timer t;
      const auto o = calibration::calibrate_disc(built[i].mesh, materials, own);
      built[i].member.own = mean_error(o.tuned_check, r.holdout);
      built[i].member.own_all = mean_error(o.tuned_check, {});
      built[i].member.own_fit_converged = o.result.success;
      built[i].member.seconds = t.seconds();
    }
    hooks.end_stage();
  }
  for (auto& b : built) r.members.push_back(b.member);
  r.seconds = timer.seconds();
  return r;
}

nlohmann::json cohort_json(const CohortResult& r) {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json members = nlohmann::json::object();
  for (const auto& m : r.members) {
    nlohmann::json j = {{"source", m.source}};
    if (!m.skipped.empty()) {
      j["skipped"] = m.skipped;
    } else {
      j.update({{"tets", m.tets},
                {"volume_mm3", m.volume_mm3},
                {"untuned_error", number(m.untuned)},
                {"transfer_error", number(m.transfer)},
                {"own_error", number(m.own)},
                {"untuned_error_all_cases", number(m.untuned_all)},
                {"transfer_error_all_cases", number(m.transfer_all)},
                {"own_error_all_cases", number(m.own_all)},
                {"own_fit_converged", m.own_fit_converged},
                {"seconds", m.seconds}});
    }
    members[m.name] = j;
  }
  return {{"level", r.request.level},
          {"material", r.request.material},
          {"cell_size_mm", r.request.cell_size_mm},
          {"train", r.train},
          {"holdout", r.holdout},
          {"error",
           "mean over the held-out cases of the nonlinear MSS's displacement error against the "
           "disc's own linear FEM at 0.1 x the standard loads (calibration/compare.hpp); "
           "transfer: the parametric disc's tuned constants; own: the disc's own fit"},
          {"reference_converged", r.reference_converged},
          {"members", members},
          {"seconds", r.seconds}};
}

void print_cohort(std::ostream& os, const CohortResult& r) {
  std::string holdout;
  for (const auto& h : r.holdout) holdout += (holdout.empty() ? "" : ", ") + h;
  os << "Disc cohort, " << r.request.level << ", material " << r.request.material
     << ": the MSS against each disc's own FEM (held-out cases " << holdout
     << "; displacement error, 0.1 x the standard loads)\n\n";
  TextTable t({"disc", "tets", "volume (mm^3)", "untuned", "parametric's constants", "own fit",
               "what it is"});
  auto pct = [](double v) { return std::isfinite(v) ? fixed(100 * v, 1) + " %" : "-"; };
  for (const auto& m : r.members) {
    if (!m.skipped.empty()) {
      t.add({m.name, "-", "-", "-", "-", "-", "skipped: " + m.skipped});
      continue;
    }
    t.add({m.name, std::to_string(m.tets), fixed(m.volume_mm3, 0), pct(m.untuned), pct(m.transfer),
           pct(m.own), m.source});
  }
  t.print(os, false);
  os << "\nThe parametric disc's own fit is its tuned constants; on the others they are the\n"
        "transfer error. "
     << fixed(r.seconds, 1) << " s.\n";
}

}  // namespace spinesim::studies
