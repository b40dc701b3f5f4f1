// The tuned-disc file (tuned.json): what it keeps through JSON, how it identifies meshes and
// levels, what it refuses to load, and when it refuses to apply.
#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/mesh/io.hpp"

#include "calibration_fixtures.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <string>

namespace spinesim::calibration {
namespace {

using fixtures::all_terms;
using fixtures::two_materials;
using fixtures::two_region_disc;
using nlohmann::json;

mesh::TetMesh l4l5_mesh() {
  mesh::TetMesh m = two_region_disc();
  m.source = "parametric disc L4-L5";
  return m;
}

/// A tuned disc for `m`: every term on, factors off their defaults, a distinct scale per knob.
TunedDisc sample_tuned(const mesh::TetMesh& m) {
  TunedDisc t;
  t.level = disc_level(m);
  t.material_name = two_materials().name;
  t.material = material_signature(two_materials());
  t.mesh = fingerprint(m);
  t.fem_order = 1;
  t.options = all_terms();
  t.options.radial_factor = 1.25;
  t.options.volume_factor = 0.75;
  t.options.disc_volume_factor = 3.0;
  int j = 0;
  for (const Knob& k : available_knobs(t.options)) t.scales[knob_name(k)] = 0.1 + 1.0 / 3.0 * ++j;
  t.report = {{"ipopt", {{"status", "Solve_Succeeded"}}}, {"note", "free form"}};
  return t;
}

void expect_same(const TunedDisc& a, const TunedDisc& b) {
  EXPECT_EQ(a.level, b.level);
  EXPECT_EQ(a.material_name, b.material_name);
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.mesh, b.mesh);
  EXPECT_EQ(a.fem_order, b.fem_order);
  EXPECT_EQ(a.scales, b.scales);  // bit-exact: JSON numbers round-trip doubles
  EXPECT_EQ(a.edge_multipliers, b.edge_multipliers);
  EXPECT_EQ(a.kind(), b.kind());
  EXPECT_EQ(a.report, b.report);
  EXPECT_EQ(a.options.radial_springs, b.options.radial_springs);
  EXPECT_EQ(a.options.torsion_springs, b.options.torsion_springs);
  EXPECT_EQ(a.options.volume_term, b.options.volume_term);
  EXPECT_EQ(a.options.disc_volume_term, b.options.disc_volume_term);
  EXPECT_EQ(a.options.radial_factor, b.options.radial_factor);
  EXPECT_EQ(a.options.volume_factor, b.options.volume_factor);
  EXPECT_EQ(a.options.disc_volume_factor, b.options.disc_volume_factor);
  EXPECT_EQ(a.options.fibre_springs, b.options.fibre_springs);
  EXPECT_EQ(a.options.isochoric_fibres, b.options.isochoric_fibres);
}

std::string temp_path(const std::string& name) {
  const auto dir =
      std::filesystem::path(SPINESIM_TEST_TMP) / ("tuned-disc-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

// --- JSON round trip ----------------------------------------------------------------------------

TEST(TunedDisc, JsonRoundTripKeepsEverything) {
  const TunedDisc t = sample_tuned(l4l5_mesh());
  expect_same(t, tuned_disc_from_json(to_json(t)));
  expect_same(t, tuned_disc_from_json(json::parse(to_json(t).dump(2))));  // through text
}

TEST(TunedDisc, FileRoundTrip) {
  const TunedDisc t = sample_tuned(l4l5_mesh());
  const std::string path = temp_path("tuned.json");
  std::ofstream(path) << to_json(t).dump(2);
  expect_same(t, read_tuned_disc(path));
}

TEST(TunedDisc, ThesisOnlyFileRoundTrips) {
  TunedDisc t = sample_tuned(l4l5_mesh());
  t.options = mss::MssOptions();
  t.options.isochoric_fibres = false;                            // either stretch round-trips
  t.scales = {{"main.annulus", 0.5}, {"torsion.nucleus", 2.0}};  // a subset: the rest stay 1
  expect_same(t, tuned_disc_from_json(to_json(t)));
}

TEST(TunedDisc, MaterialsRebuildTheFittedConstants) {
  const TunedDisc t = sample_tuned(l4l5_mesh());
  const mesh::RegionMaterials rebuilt = t.materials(), original = two_materials();
  EXPECT_EQ(rebuilt.name, original.name);
  for (const auto r : {mesh::Region::annulus, mesh::Region::nucleus}) {
    EXPECT_EQ(rebuilt.at(int(r)).youngs_modulus_mpa, original.at(int(r)).youngs_modulus_mpa);
    EXPECT_EQ(rebuilt.at(int(r)).poisson_ratio, original.at(int(r)).poisson_ratio);
    EXPECT_EQ(rebuilt.at(int(r)).density_kg_m3, original.at(int(r)).density_kg_m3);
  }
  EXPECT_NO_THROW(check_applies(t, l4l5_mesh(), rebuilt));
}

// --- mesh identity and level ----------------------------------------------------------------------

TEST(Fingerprint, StableForTheSameMesh) {
  const mesh::TetMesh m = l4l5_mesh();
  const MeshFingerprint f = fingerprint(m);
  EXPECT_EQ(f.nodes, m.num_vertices());
  EXPECT_EQ(f.tets, m.num_tets());
  EXPECT_EQ(f.hash.size(), 16u);
  EXPECT_EQ(f.hash.find_first_not_of("0123456789abcdef"), std::string::npos) << f.hash;
  EXPECT_EQ(fingerprint(m), f);
  mesh::TetMesh copy = m;
  copy.source = "another provenance";  // not part of the identity
  EXPECT_EQ(fingerprint(copy), f);
}

TEST(Fingerprint, SurvivesAVtuRoundTrip) {
  const mesh::TetMesh m = l4l5_mesh();
  const std::string path = temp_path("fingerprint.vtu");
  mesh::write_vtu(path, m);
  EXPECT_EQ(fingerprint(mesh::read_vtu(path)), fingerprint(m));
}

TEST(Fingerprint, ChangesWithACoordinateALabelOrTheConnectivity) {
  const mesh::TetMesh m = l4l5_mesh();
  const MeshFingerprint f = fingerprint(m);
  for (int axis = 0; axis < 3; ++axis) {
    mesh::TetMesh moved = m;
    moved.V(m.num_vertices() / 2, axis) += 1e-3;  // one micrometre
    EXPECT_NE(fingerprint(moved).hash, f.hash) << "axis " << axis;
    EXPECT_EQ(fingerprint(moved).nodes, f.nodes);
  }
  mesh::TetMesh surface = m;
  surface.surface(0) = surface.surface(0) == 1 ? 3 : 1;
  EXPECT_NE(fingerprint(surface).hash, f.hash);
  mesh::TetMesh region = m;
  region.region(0) = region.region(0) == 1 ? 2 : 1;
  EXPECT_NE(fingerprint(region).hash, f.hash);
  mesh::TetMesh flipped = m;
  std::swap(flipped.T(0, 0), flipped.T(0, 1));
  EXPECT_NE(fingerprint(flipped).hash, f.hash);
}

TEST(DiscLevel, ReadFromTheBuildersProvenance) {
  mesh::TetMesh m = two_region_disc();
  const auto level_of = [&m](const std::string& source) {
    m.source = source;
    return disc_level(m);
  };
  EXPECT_EQ(level_of("parametric disc L4-L5"), "L4-L5");
  EXPECT_EQ(level_of("parametric disc L5-S1"), "L5-S1");
  EXPECT_EQ(level_of("structured disc T12-L1 (12 sectors, 3 rings, 2 layers)"), "T12-L1");
  EXPECT_EQ(level_of("structured disc T7-T8 (12 sectors, 3 rings, 2 layers, area-matched)"),
            "T7-T8");
  EXPECT_EQ(level_of("disc between vertebrae"), "");
  EXPECT_EQ(level_of(""), "");
  // A foreign VTU's source is its path: a folder name is not a checked level.
  EXPECT_EQ(level_of("/data/scans/L4-L5/disc.vtu"), "");
}

// --- refusals on load -----------------------------------------------------------------------------

/// tuned_disc_from_json of `file` (default: the sample file) after `edit` throws
/// std::invalid_argument whose message contains `needle`, on one line.
void expect_refused(const std::function<void(json&)>& edit, const std::string& needle,
                    json j = to_json(sample_tuned(l4l5_mesh()))) {
  edit(j);
  try {
    tuned_disc_from_json(j);
    ADD_FAILURE() << "accepted; expected a refusal mentioning '" << needle << "'";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(TunedDiscRefuses, WrongFormatTag) {
  expect_refused([](json& j) { j["format"] = "spinesim-tuned-disc-set"; }, "spinesim-tuned-disc");
  expect_refused([](json& j) { j.erase("format"); }, "format");
  expect_refused([](json& j) { j = json::array({j}); }, "format");
}

TEST(TunedDiscRefuses, WrongVersion) {
  expect_refused([](json& j) { j["version"] = 2; }, "version 2");
  expect_refused([](json& j) { j["version"] = 0; }, "version");
  expect_refused([](json& j) { j["version"] = 1.5; }, "version");
  expect_refused([](json& j) { j["version"] = (std::int64_t(1) << 32) + 1; }, "version");
  expect_refused([](json& j) { j.erase("version"); }, "version");
}

TEST(TunedDiscRefuses, UnknownKnob) {
  expect_refused([](json& j) { j["scales"]["torsion.cortex"] = 1.0; }, "torsion.cortex");
  expect_refused([](json& j) { j["scales"]["disc_volume.nucleus"] = 1.0; }, "disc_volume.nucleus");
}

TEST(TunedDiscRefuses, ScaleNotPositiveAndFinite) {
  for (const double bad : {0.0, -0.5, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()})
    expect_refused([bad](json& j) { j["scales"]["radial.nucleus"] = bad; }, "radial.nucleus");
  expect_refused([](json& j) { j["scales"]["radial.nucleus"] = "2"; }, "malformed");
  expect_refused([](json& j) { j["scales"]["radial.nucleus"] = nullptr; },
                 "malformed");  // a NaN written to text
  expect_refused([](json& j) { j["scales"] = json::object(); }, "no scales");
}

TEST(TunedDiscRefuses, ScaleOfASwitchedOffTerm) {
  const std::pair<const char*, const char*> cases[] = {{"volume_term", "'volume."},
                                                       {"disc_volume_term", "'disc_volume'"},
                                                       {"radial_springs", "'radial."},
                                                       {"torsion_springs", "'torsion."}};
  for (const auto& [term, knob] : cases) {
    expect_refused([term = term](json& j) { j["terms"][term] = false; }, std::string(knob));
    expect_refused([term = term](json& j) { j["terms"][term] = false; }, "switches off");
  }
  // Switching off a term whose scales are gone is fine.
  json j = to_json(sample_tuned(l4l5_mesh()));
  j["terms"]["volume_term"] = false;
  j["scales"].erase("volume.annulus");
  j["scales"].erase("volume.nucleus");
  EXPECT_FALSE(tuned_disc_from_json(j).mss_options().volume_term);
}

TEST(TunedDiscRefuses, UnknownKind) {
  expect_refused([](json& j) { j["kind"] = "spring"; }, "kind 'spring'");
  expect_refused([](json& j) { j["kind"] = 3; }, "malformed");
}

TEST(TunedDiscRefuses, BadFactorsMaterialOrOrder) {
  expect_refused([](json& j) { j["terms"]["volume_factor"] = 0.0; }, "factor");
  expect_refused([](json& j) { j["terms"]["radial_factor"] = -1.0; }, "factor");
  expect_refused([](json& j) { j["material"]["regions"]["nucleus"].erase("E_mpa"); }, "E_mpa");
  expect_refused([](json& j) { j["material"]["regions"]["annulus"]["E_mpa"] = "3.2"; }, "E_mpa");
  expect_refused([](json& j) { j["material"]["regions"]["annulus"]["nu"] = 0.5; }, "Poisson");
  expect_refused([](json& j) { j["material"]["regions"].erase("annulus"); }, "malformed");
  expect_refused([](json& j) { j["fem_order"] = 3; }, "fem_order");
  expect_refused([](json& j) { j.erase("terms"); }, "terms");
}

TEST(TunedDiscRefuses, UnreadableOrCorruptFileNamesIt) {
  const std::string missing = temp_path("no-such-tuned.json");
  std::filesystem::remove(missing);
  try {
    read_tuned_disc(missing);
    ADD_FAILURE() << "read a missing file";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string corrupt = temp_path("corrupt-tuned.json");
  const std::string text = to_json(sample_tuned(l4l5_mesh())).dump(2);
  std::ofstream(corrupt) << text.substr(0, text.size() / 2);  // truncated
  try {
    read_tuned_disc(corrupt);
    ADD_FAILURE() << "read a truncated file";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(corrupt), std::string::npos) << e.what();
  }
  const std::string wrong = temp_path("wrong-version-tuned.json");
  json j = to_json(sample_tuned(l4l5_mesh()));
  j["version"] = 7;
  std::ofstream(wrong) << j.dump();
  try {
    read_tuned_disc(wrong);
    ADD_FAILURE() << "read version 7";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(wrong), std::string::npos) << what;
    EXPECT_NE(what.find("version 7"), std::string::npos) << what;
  }
}

// --- does a file apply to this mesh and material? -------------------------------------------------

/// check_applies throws std::invalid_argument mentioning every one of `needles`.
void expect_not_applicable(const TunedDisc& t, const mesh::TetMesh& m,
                           const mesh::RegionMaterials& mat,
                           std::initializer_list<std::string> needles) {
  try {
    check_applies(t, m, mat);
    ADD_FAILURE() << "applied";
  } catch (const std::invalid_argument& e) {
    for (const auto& n : needles)
      EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
  }
}

TEST(CheckApplies, TheFittedMeshAndMaterial) {
  const mesh::TetMesh m = l4l5_mesh();
  EXPECT_EQ(check_applies(sample_tuned(m), m, two_materials()), "");
}

TEST(CheckApplies, RefusesAnotherMaterial) {
  const mesh::TetMesh m = l4l5_mesh();
  const TunedDisc t = sample_tuned(m);
  mesh::RegionMaterials renamed = two_materials();
  renamed.name = "rubber";
  expect_not_applicable(t, m, renamed, {"rubber", two_materials().name});
  mesh::RegionMaterials stiffer = two_materials();
  stiffer.by_region[int(mesh::Region::nucleus)].youngs_modulus_mpa *= 1.01;
  expect_not_applicable(t, m, stiffer, {two_materials().name});
  mesh::RegionMaterials softer = two_materials();
  softer.fallback.youngs_modulus_mpa *= 0.99;  // the annulus (label 1 uses the fallback)
  expect_not_applicable(t, m, softer, {two_materials().name});
  mesh::RegionMaterials other_nu = two_materials();
  other_nu.by_region[int(mesh::Region::nucleus)].poisson_ratio = 0.45;
  expect_not_applicable(t, m, other_nu, {two_materials().name});
}

// A file fitted with fibre elements carries its fibres: it rebuilds the fibre material (so the
// fibre elements can be built from the file alone) and refuses the same matrix with other fibres.
TEST(CheckApplies, AFibreFileCarriesAndComparesItsFibres) {
  const mesh::TetMesh m = l4l5_mesh();
  mesh::RegionMaterials fibred = two_materials();
  mesh::FibreReinforcement f;
  f.modulus_inner_mpa = 59, f.modulus_outer_mpa = 136;
  f.angle_inner_deg = 45, f.angle_outer_deg = 28;
  f.toe_k2 = 12.5;
  fibred.fibres[int(mesh::Region::annulus)] = f;
  TunedDisc t = sample_tuned(m);
  t.material = material_signature(fibred);
  t.options.fibre_springs = true;
  t.scales["fibre"] = 0.9;
  const TunedDisc back = tuned_disc_from_json(to_json(t));
  const mesh::RegionMaterials rebuilt = back.materials();
  ASSERT_TRUE(rebuilt.has_fibres());
  const mesh::FibreReinforcement& g = rebuilt.fibres.at(int(mesh::Region::annulus));
  EXPECT_EQ(g.modulus_inner_mpa, 59);
  EXPECT_EQ(g.modulus_outer_mpa, 136);
  EXPECT_EQ(g.angle_inner_deg, 45);
  EXPECT_EQ(g.angle_outer_deg, 28);
  EXPECT_EQ(g.toe_k2, 12.5);
  EXPECT_EQ(check_applies(back, m, fibred), "");
  for (auto change : {+[](mesh::FibreReinforcement& x) { x.toe_k2 = 10; },
                      +[](mesh::FibreReinforcement& x) { x.angle_outer_deg = 30; },
                      +[](mesh::FibreReinforcement& x) { x.modulus_outer_mpa = 100; }}) {
    mesh::RegionMaterials other = fibred;
    change(other.fibres.at(int(mesh::Region::annulus)));
    expect_not_applicable(back, m, other, {two_materials().name});
  }
}

TEST(CheckApplies, RefusesAnotherLevel) {
  const TunedDisc t = sample_tuned(l4l5_mesh());
  mesh::TetMesh t12 = two_region_disc();
  t12.source = "structured disc T12-L1 (12 sectors, 3 rings, 2 layers)";
  expect_not_applicable(t, t12, two_materials(), {"L4-L5", "T12-L1"});
}

TEST(CheckApplies, SameLevelOnAnotherMeshTransfers) {
  const TunedDisc t = sample_tuned(l4l5_mesh());
  mesh::TetMesh finer =
      spinesim::mesh::box_mesh(7, 4, 5, 20.0, 8.0, 16.0, Eigen::Vector3d(-10.0, 0.0, -8.0));
  finer.source = "structured disc L4-L5 (12 sectors, 3 rings, 2 layers)";
  ASSERT_FALSE(fingerprint(finer) == t.mesh);
  EXPECT_EQ(check_applies(t, finer, two_materials()), "");
  EXPECT_NO_THROW(mss::MssModel(finer, two_materials(), t.mss_options()));
}

TEST(CheckApplies, NotesWhatItCouldNotCheck) {
  const TunedDisc t = sample_tuned(l4l5_mesh());
  mesh::TetMesh unknown =
      spinesim::mesh::box_mesh(6, 3, 4, 20.0, 8.0, 16.0, Eigen::Vector3d(-10.0, 0.0, -8.0));
  unknown.source = "disc between vertebrae";
  const std::string note = check_applies(t, unknown, two_materials());
  EXPECT_NE(note.find("unknown"), std::string::npos) << note;
  EXPECT_NE(note.find("L4-L5"), std::string::npos) << note;

  // Fitted on a mesh of unknown level: silent on that very mesh, a note on any other.
  mesh::TetMesh patient = two_region_disc();
  patient.source = "disc between vertebrae";
  const TunedDisc p = sample_tuned(patient);
  ASSERT_EQ(p.level, "");
  EXPECT_EQ(check_applies(p, patient, two_materials()), "");
  EXPECT_NE(check_applies(p, unknown, two_materials()), "");
  mesh::TetMesh other_l4l5 = unknown;
  other_l4l5.source = "parametric disc L4-L5";
  EXPECT_NE(check_applies(p, other_l4l5, two_materials()).find("L4-L5"), std::string::npos);
  // ... but the material is checked all the same.
  mesh::RegionMaterials renamed = two_materials();
  renamed.name = "rubber";
  expect_not_applicable(p, patient, renamed, {"rubber"});
}

// --- the model options the file selects -------------------------------------------------------------

TEST(TunedDisc, MssOptionsPutEachScaleInItsSlot) {
  const TunedDisc t = sample_tuned(l4l5_mesh());
  const mss::MssOptions o = t.mss_options();
  for (const Knob& k : available_knobs(t.options))
    EXPECT_EQ(o.scales[std::size_t(k.term)].by_region[std::size_t(k.region)],
              t.scales.at(knob_name(k)))
        << knob_name(k);
  EXPECT_EQ(o.scales[std::size_t(mss::Term::disc_volume)].by_region[1], 1.0);  // no such knob
  // Every slot holds a different value: no two knobs share one.
  std::set<double> seen;
  for (const auto& s : o.scales)
    for (double v : s.by_region) seen.insert(v);
  EXPECT_EQ(seen.size(), t.scales.size() + 1);  // + the unused disc_volume nucleus slot (1)
  EXPECT_EQ(o.radial_factor, t.options.radial_factor);
  EXPECT_EQ(o.volume_factor, t.options.volume_factor);
  EXPECT_EQ(o.disc_volume_factor, t.options.disc_volume_factor);
  EXPECT_TRUE(o.volume_term && o.disc_volume_term && o.radial_springs && o.torsion_springs);
}

TEST(TunedDisc, MssOptionsLeaveUnlistedKnobsAtOne) {
  TunedDisc t = sample_tuned(l4l5_mesh());
  t.options.scales[int(mss::Term::main)].by_region = {
      7.0, 7.0};  // stale values in `options` do not leak
  t.scales = {{"torsion.nucleus", 0.25}};
  const mss::MssOptions o = t.mss_options();
  for (int term = 0; term < mss::kNumTerms; ++term)
    for (int r = 0; r < 2; ++r) {
      const bool listed = term == int(mss::Term::torsion) && r == 1;
      EXPECT_EQ(o.scales[std::size_t(term)].by_region[std::size_t(r)], listed ? 0.25 : 1.0)
          << term << "," << r;
    }
}

// The scales act on the model as the knobs' names say: the energy of a deformation is linear in
// each scale, so scaling one knob by 2 changes the energy by that knob's term-and-region part.
TEST(TunedDisc, MssOptionsScaleTheNamedTermAndRegion) {
  const mesh::TetMesh m = l4l5_mesh();
  TunedDisc t = sample_tuned(m);
  for (auto& [name, s] : t.scales) s = 1.0;
  const mss::MssModel base(m, two_materials(), t.mss_options());
  Eigen::VectorXd x = base.rest_positions_mm();
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += 0.05 * std::sin(1.7 * double(i));
  for (const Knob& k : available_knobs(t.options)) {
    TunedDisc doubled = t;
    doubled.scales[knob_name(k)] = 2.0;
    const mss::MssModel scaled(m, two_materials(), doubled.mss_options());
    const double part = base.term_energy(x, k.term, k.region);
    EXPECT_GT(part, 0.0) << knob_name(k);
    EXPECT_NEAR(scaled.energy(x) - base.energy(x), part, 1e-9 * base.energy(x)) << knob_name(k);
  }
}

// --- per-spring files ---------------------------------------------------------------------------

/// The sample file for `m` with one distinct multiplier per edge spring of the model on `m`.
TunedDisc sample_per_spring(const mesh::TetMesh& m) {
  TunedDisc t = sample_tuned(m);
  const mss::MssModel model(m, two_materials(), t.mss_options());
  for (Eigen::Index e = 0; e < model.num_edge_springs(); ++e)
    t.edge_multipliers.push_back(0.5 + 1.0 / double(e + 3));
  t.edge_order = edge_order_hash(model);
  return t;
}

TEST(PerSpringFile, RoundTripKeepsEveryMultiplier) {
  const TunedDisc t = sample_per_spring(l4l5_mesh());
  ASSERT_TRUE(t.per_spring());
  const json j = to_json(t);
  EXPECT_EQ(j.at("kind"), "per-spring");
  EXPECT_EQ(j.at("version"), 1);
  EXPECT_EQ(j.at("edge_springs").get<std::size_t>(), t.edge_multipliers.size());
  expect_same(t, tuned_disc_from_json(j));
  expect_same(t, tuned_disc_from_json(json::parse(j.dump(2))));  // through text, bit-exact
  const std::string path = temp_path("per-spring.json");
  std::ofstream(path) << j.dump(2);
  expect_same(t, read_tuned_disc(path));

  // A region-level file says so and carries no multipliers.
  const json region = to_json(sample_tuned(l4l5_mesh()));
  EXPECT_EQ(region.at("kind"), "region");
  EXPECT_FALSE(region.contains("edge_multipliers"));
  EXPECT_FALSE(tuned_disc_from_json(region).per_spring());
}

/// expect_refused on the per-spring sample.
void expect_per_spring_refused(const std::function<void(json&)>& edit, const std::string& needle) {
  expect_refused(edit, needle, to_json(sample_per_spring(l4l5_mesh())));
}

TEST(PerSpringFile, RefusesBadMultipliers) {
  expect_per_spring_refused([](json& j) { j.erase("edge_multipliers"); }, "edge_multipliers");
  expect_per_spring_refused([](json& j) { j["edge_multipliers"] = json::array(); },
                            "no edge_multipliers");
  for (const double bad : {0.0, -1.0, std::numeric_limits<double>::infinity()})
    expect_per_spring_refused([bad](json& j) { j["edge_multipliers"][3] = bad; },
                              "finite numbers in [1e-6, 1e6]");
  expect_per_spring_refused([](json& j) { j["edge_multipliers"][3] = 1e300; }, "[1e-6, 1e6]");
  expect_per_spring_refused([](json& j) { j["edge_multipliers"][3] = nullptr; },
                            "malformed");  // a NaN written to text
  expect_per_spring_refused([](json& j) { j["edge_multipliers"][3] = "1"; }, "malformed");
  expect_per_spring_refused([](json& j) { j["edge_springs"] = j["edge_springs"].get<int>() + 1; },
                            "edge_springs");
  expect_per_spring_refused([](json& j) { j.erase("edge_springs"); }, "edge_springs");
  // The kind decides: multipliers in a region-level file are an error, not silently ignored.
  expect_per_spring_refused([](json& j) { j["kind"] = "region"; }, "per-spring");
}

TEST(PerSpringFile, AppliesToTheFittedMeshOnly) {
  const mesh::TetMesh m = l4l5_mesh();
  const TunedDisc t = sample_per_spring(m);
  EXPECT_EQ(check_applies(t, m, two_materials()), "");
  const mss::MssOptions o = t.mss_options();
  EXPECT_EQ(o.edge_multipliers, t.edge_multipliers);
  const mss::MssModel model(m, two_materials(), o);
  EXPECT_EQ(model.edge_springs()[5].multiplier, t.edge_multipliers[5]);

  // Another mesh of the same disc level: a region-level file transfers, a per-spring one not.
  mesh::TetMesh finer =
      spinesim::mesh::box_mesh(7, 4, 5, 20.0, 8.0, 16.0, Eigen::Vector3d(-10.0, 0.0, -8.0));
  finer.source = "structured disc L4-L5 (12 sectors, 3 rings, 2 layers)";
  EXPECT_EQ(check_applies(sample_tuned(m), finer, two_materials()), "");
  expect_not_applicable(t, finer, two_materials(),
                        {"per-spring", "region-level tuned files transfer",
                         "fingerprint " + t.mesh.hash, "fingerprint " + fingerprint(finer).hash});
  // Same counts, one vertex moved by a micrometre: another mesh all the same.
  mesh::TetMesh moved = m;
  moved.V(moved.num_vertices() / 2, 1) += 1e-3;
  expect_not_applicable(t, moved, two_materials(), {"per-spring", "do not apply"});
  // A mesh of unknown level is no exception.
  mesh::TetMesh unknown = finer;
  unknown.source = "disc between vertebrae";
  expect_not_applicable(t, unknown, two_materials(), {"per-spring"});
  // The refusal is one line.
  try {
    check_applies(t, finer, two_materials());
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
  // The material is still checked on the fitted mesh.
  mesh::RegionMaterials renamed = two_materials();
  renamed.name = "rubber";
  expect_not_applicable(t, m, renamed, {"rubber"});
}

// The multipliers are indexed by the model's edge order: a file whose recorded order is not the
// model's is refused when the model is built, never applied to the wrong springs.
TEST(PerSpringFile, AnotherEdgeOrderIsRefusedWhenTheModelIsBuilt) {
  const mesh::TetMesh m = l4l5_mesh();
  TunedDisc t = sample_per_spring(m);
  const mss::MssModel model = build_tuned_model(t, m, two_materials());
  EXPECT_EQ(model.edge_springs()[7].multiplier, t.edge_multipliers[7]);
  t.edge_order = "0123456789abcdef";
  try {
    build_tuned_model(t, m, two_materials());
    FAIL() << "a per-spring file with another edge order was applied";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ordering of the edge springs"), std::string::npos)
        << e.what();
  }
  expect_per_spring_refused([](json& j) { j.erase("edge_order"); }, "edge_order");
}

TEST(PerSpringFile, ATunedSetRefusesIt) {
  TunedSet set;
  set.material_name = two_materials().name;
  set.levels.emplace("L4-L5", sample_tuned(l4l5_mesh()));
  EXPECT_NO_THROW(tuned_set_from_json(to_json(set)));
  set.levels["L4-L5"] = sample_per_spring(l4l5_mesh());
  try {
    tuned_set_from_json(to_json(set));
    ADD_FAILURE() << "a tuned set took a per-spring entry";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("per-spring"), std::string::npos) << e.what();
  }
}

TEST(TunedSet, StructuredResolutionIsTheRecordedOneOrTheDefault) {
  TunedSet set;
  const mesh::StructuredDiscOptions defaults;
  mesh::StructuredDiscOptions r = structured_resolution(set);
  EXPECT_EQ(r.sectors, defaults.sectors);
  EXPECT_EQ(r.rings, defaults.rings);
  EXPECT_EQ(r.layers, defaults.layers);
  EXPECT_EQ(r.match_area, defaults.match_area);
  set.settings["structured"] = {{"sectors", 24}, {"rings", 4}, {"layers", 4}, {"match_area", true}};
  r = structured_resolution(set);
  EXPECT_EQ(r.sectors, 24);
  EXPECT_EQ(r.rings, 4);
  EXPECT_EQ(r.layers, 4);
  EXPECT_TRUE(r.match_area);
  // It survives the file.
  set.material_name = two_materials().name;
  set.levels.emplace("L4-L5", sample_tuned(l4l5_mesh()));
  EXPECT_EQ(structured_resolution(tuned_set_from_json(to_json(set))).sectors, 24);
}

TEST(TunedSet, MalformedStructuredResolutionIsRefusedInOneLine) {
  for (const json bad : {json({{"sectors", 24}, {"rings", 4}}),
                         json({{"sectors", "24"}, {"rings", 4}, {"layers", 4}}),
                         json({{"sectors", 5}, {"rings", 4}, {"layers", 4}}),
                         json({{"sectors", 24}, {"rings", 1}, {"layers", 4}}), json(3)}) {
    TunedSet set;
    set.settings["structured"] = bad;
    try {
      structured_resolution(set);
      ADD_FAILURE() << "accepted " << bad.dump();
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(TunedSet, ParamsNameTheFirstShippedSetAShippedNameOrAFile) {
  const std::vector<ShippedSet> shipped = {{"real-disc", "/data/a.json"},
                                           {"fibre-reinforced", "/data/b.json"}};
  EXPECT_EQ(tuned_set_path("", shipped), "/data/a.json");
  EXPECT_EQ(tuned_set_path("real-disc", shipped), "/data/a.json");
  EXPECT_EQ(tuned_set_path("fibre-reinforced", shipped), "/data/b.json");
  const std::string file =
      (std::filesystem::temp_directory_path() / "tuned_set_path.json").string();
  std::ofstream(file) << "{}";
  EXPECT_EQ(tuned_set_path(file, shipped), file);
  std::filesystem::remove(file);
  try {
    tuned_set_path("fibre", shipped);
    ADD_FAILURE() << "accepted an unknown name";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("real-disc, fibre-reinforced"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(tuned_set_path("", {}), std::invalid_argument);
}

// A file whose "format" is not a string (found by the fuzzer: the set-or-disc dispatch threw
// nlohmann's type_error, which ended the program) is refused in one line like any bad file.
TEST(TunedDiscRefuses, FormatThatIsNotAStringInAFile) {
  const std::string path = temp_path("tuned_format.json");
  for (const json format : {json(3), json::array({"x"}), json(nullptr), json::object()}) {
    json j = to_json(sample_tuned(l4l5_mesh()));
    j["format"] = format;
    std::ofstream(path) << j.dump();
    try {
      read_tuned_for_mesh(path, nullptr);
      ADD_FAILURE() << "accepted format " << format.dump();
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace spinesim::calibration
