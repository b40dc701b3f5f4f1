// The fibre-reinforced disc on the command line: `fem --formulation mixed` writes the pressure
// and the annulus fibre field; `view --vectors` draws the fibres; `study disc-validation` sets
// the disc beside in-vitro tests; `study disc-identify` fits its material; `study mss-fibres`
// fits the mass-spring disc to the nonlinear one; bad options are one line.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <stb_image.h>

#include <nlohmann/json.hpp>

#include "spinesim/mesh/io.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

namespace spinesim::test_cli {
namespace {

/// A structured L4-L5 disc (fast to mesh and to solve), made once.
const std::string& disc_vtu() {
  static const std::string path = [] {
    const std::string p = tmp("fibre_disc.vtu");
    const CliRun r = run_spinesim("mesh disc --level L4-L5 --structured --quiet --out '" + p + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    return p;
  }();
  return path;
}

/// `fem` on it with the fibre-reinforced material, mixed, under compression; the result VTU.
const std::string& fibre_result() {
  static const std::string path = [] {
    const std::string p = tmp("fibre_result.vtu");
    const CliRun r = run_spinesim("fem --mesh '" + disc_vtu() +
                                  "' --material fibre-reinforced --formulation mixed --case "
                                  "compression --json --out '" +
                                  p + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["formulation"], "mixed");
    EXPECT_EQ(j["fibres"], true);
    EXPECT_GT(j["nucleus_pressure_mpa"].get<double>(), 0.0);
    // The field summary: the stored energy is the plate's work -1/2 reaction . q (q in rad).
    const auto q = j["plate_motion"].get<std::vector<double>>();
    const auto w = j["reaction_wrench"].get<std::vector<double>>();
    double work = 0;
    for (int k = 0; k < 6; ++k) work -= 0.5 * w[std::size_t(k)] * q[std::size_t(k)] * (k < 3 ? 1.0 : M_PI / 180);
    EXPECT_NEAR(j["fields"]["strain_energy_mj"].get<double>(), work, 1e-6 * work);
    EXPECT_GT(j["fields"]["max_von_mises_mpa"].get<double>(), 0.0);
    EXPECT_GT(j["fields"]["max_fibre_stress_mpa"].get<double>(), 0.0);
    return p;
  }();
  return path;
}

TEST(CliFibres, MixedFemWritesThePressureAndTheFibreField) {
  std::vector<mesh::DataArray> points, cells;
  const mesh::TetMesh m = mesh::read_vtu(fibre_result(), &points, &cells);
  const auto find = [](const std::vector<mesh::DataArray>& v, const std::string& name) {
    for (const auto& a : v)
      if (a.name == name) return &a;
    return static_cast<const mesh::DataArray*>(nullptr);
  };
  const mesh::DataArray* p = find(points, "pressure");
  const mesh::DataArray* f1 = find(cells, "fibre_direction_1");
  const mesh::DataArray* f2 = find(cells, "fibre_direction_2");
  const mesh::DataArray* depth = find(cells, "annulus_depth");
  ASSERT_TRUE(p && f1 && f2 && depth);
  ASSERT_EQ(f1->values.rows(), m.num_tets());
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    if (m.region(t) == 1) {
      EXPECT_NEAR(f1->values.row(t).norm(), 1.0, 1e-9);
      EXPECT_NEAR(f2->values.row(t).norm(), 1.0, 1e-9);
      EXPECT_GE(depth->values(t, 0), 0.0);
      EXPECT_LE(depth->values(t, 0), 1.0);
    } else {
      EXPECT_EQ(f1->values.row(t).norm(), 0.0);
      EXPECT_EQ(depth->values(t, 0), -1.0);
    }
  }
  // The nucleus is pressurised by the compression.
  double nucleus = 0;
  int n = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    if (m.region(t) == 2)
      for (int a = 0; a < 4; ++a) nucleus += p->values(m.T(t, a), 0), ++n;
  EXPECT_GT(nucleus / n, 0.0);
}

TEST(CliFibres, FemWritesStressStrainAndFibreFieldsThatVtkReadsWhole) {
  std::vector<mesh::DataArray> points, cells;
  const mesh::TetMesh m = mesh::read_vtu(fibre_result(), &points, &cells);
  std::map<std::string, const mesh::DataArray*> by_name;
  for (const auto& a : cells) by_name[a.name] = &a;
  for (const char* name : {"stress_MPa", "von_mises_MPa", "pressure_MPa", "strain", "principal_strain",
                           "principal_strain_direction_1", "strain_energy_density_MPa",
                           "fibre_stretch", "fibre_stress_MPa"})
    ASSERT_TRUE(by_name.count(name)) << name;
  const Eigen::MatrixXd& stress = by_name["stress_MPa"]->values;
  const Eigen::MatrixXd& fibre_stress = by_name["fibre_stress_MPa"]->values;
  ASSERT_EQ(stress.cols(), 6);
  double nucleus_pressure = 0, volume = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    // Pressure is the stress's negative mean; fibres carry stress in the annulus only.
    EXPECT_NEAR(by_name["pressure_MPa"]->values(t, 0), -stress.row(t).head<3>().sum() / 3, 1e-12);
    if (m.region(t) == 2) {
      EXPECT_EQ(fibre_stress.row(t).norm(), 0.0);
      nucleus_pressure += by_name["pressure_MPa"]->values(t, 0) * mesh::tet_volume(m, t);
      volume += mesh::tet_volume(m, t);
    }
  }
  EXPECT_GT(fibre_stress.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(nucleus_pressure / volume, 0.0);  // compressed
  if (std::system("/usr/bin/python3 -c 'import vtk' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3-vtk9 not available";
  // VTK itself reads every array with one tuple per cell or point (and the field data whole).
  const std::string script = tmp("vtk_counts.py"), out = tmp("vtk_counts.txt");
  std::ofstream(script) << "import sys, vtk\n"
                           "r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(sys.argv[1]); r.Update()\n"
                           "g = r.GetOutput()\n"
                           "for kind, d in (('cell', g.GetCellData()), ('point', g.GetPointData()), "
                           "('field', g.GetFieldData())):\n"
                           "    for i in range(d.GetNumberOfArrays()):\n"
                           "        a = d.GetAbstractArray(i)\n"
                           "        print(kind, a.GetName(), a.GetNumberOfTuples(), a.GetNumberOfComponents())\n";
  ASSERT_EQ(std::system(("/usr/bin/python3 '" + script + "' '" + fibre_result() + "' > '" + out + "'").c_str()), 0);
  std::ifstream in(out);
  std::map<std::string, std::pair<long, long>> vtk;
  for (std::string kind, name; in >> kind >> name;) {
    long tuples = 0, components = 0;
    in >> tuples >> components;
    vtk[kind + ":" + name] = {tuples, components};
  }
  for (const auto& a : cells)
    EXPECT_EQ(vtk["cell:" + a.name], std::make_pair(long(m.num_tets()), long(a.values.cols()))) << a.name;
  for (const auto& a : points)
    EXPECT_EQ(vtk["point:" + a.name], std::make_pair(long(m.num_vertices()), long(a.values.cols()))) << a.name;
  EXPECT_EQ(vtk["field:disc_frame"], std::make_pair(1L, 12L));
  EXPECT_EQ(vtk["field:provenance"].second, 1L);  // the JSON text, as bytes
  EXPECT_EQ(vtk.size(), cells.size() + points.size() + 2 /* region, surface */ +
                            3 /* frame, source, provenance */);
}

TEST(CliFibres, NonlinearFemWritesItsFieldsAndBalancesTheCase) {
  const std::string out = tmp("nonlinear_flexion.vtu");
  const CliRun r = run_spinesim("fem --mesh '" + disc_vtu() +
                                "' --material fibre-reinforced --case flexion --nonlinear --order 1 "
                                "--increments 4 --json --out '" + out + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["model"], "nonlinear");
  EXPECT_EQ(j["volumetric_form"], "nodal average");
  std::vector<mesh::DataArray> points, cells;
  const mesh::TetMesh m = mesh::read_vtu(out, &points, &cells);
  // The plate holds the case's 7.5 N·m about the disc's lateral axis.
  const Eigen::Vector3d M(j["reaction_wrench"][3], j["reaction_wrench"][4], j["reaction_wrench"][5]);
  EXPECT_NEAR(M.dot(m.frame.axes.col(0)), -7500.0, 1e-3);
  std::map<std::string, const mesh::DataArray*> by_name;
  for (const auto& a : cells) by_name[a.name] = &a;
  for (const char* name : {"cauchy_stress_MPa", "von_mises_MPa", "pressure_MPa",
                           "green_lagrange_strain", "principal_stretch",
                           "principal_stretch_direction_1", "principal_stretch_direction_2",
                           "principal_stretch_direction_3", "fibre_stretch",
                           "fibre_stress_MPa", "volume_ratio", "strain_energy_density_MPa"})
    ASSERT_TRUE(by_name.count(name)) << name;
  ASSERT_EQ(points.size(), 1u);
  // Flexion stretches the posterior annulus's fibres and compresses the anterior disc.
  EXPECT_GT(by_name["fibre_stretch"]->values.maxCoeff(), 1.0);
  EXPECT_LT(by_name["volume_ratio"]->values.minCoeff(), 1.0);
  EXPECT_NEAR(by_name["von_mises_MPa"]->values.maxCoeff(),
              j["fields"]["max_von_mises_mpa"].get<double>(), 1e-9);
  expect_refused(run_spinesim("fem --mesh '" + disc_vtu() + "' --nonlinear --formulation mixed"),
                 "mixed");
}

TEST(CliFibres, BadFormulationsAreOneLine) {
  expect_refused(run_spinesim("fem --mesh '" + disc_vtu() + "' --formulation mixed --order 1"),
                 "needs --order 2");
  expect_refused(run_spinesim("fem --mesh '" + disc_vtu() + "' --formulation penalty"),
                 "unknown formulation");
  expect_refused(run_spinesim("study disc-validation --formulation penalty"),
                 "unknown formulation");
}

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

TEST(CliFibres, TheViewerDrawsTheFibresAsRods) {
  expect_refused(run_spinesim("view --play '" + fibre_result() + "' --vectors stress"),
                 "fibre_direction_1, fibre_direction_2");
  expect_refused(run_spinesim("view --play '" + fibre_result() + "' --camera 10"), "--camera");
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run missing (apt-get install xvfb)";
  const std::string png = tmp("fibres.png");
  std::filesystem::remove(png);
  const CliRun r = run_spinesim(
      "view --play '" + fibre_result() +
          "' --field fibre_angle_deg --vectors fibre_direction_1,fibre_direction_2 --camera "
          "-60,35 --width 480 --height 360 --no-panel --frames 2 --json --screenshot '" +
          png + "'",
      "xvfb-run -a -s '-screen 0 640x480x24' ");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["series"]["glyphs"].get<int>(), 100);
  int width = 0, height = 0, channels = 0;
  std::unique_ptr<unsigned char, void (*)(void*)> rgb(
      stbi_load(png.c_str(), &width, &height, &channels, 3), stbi_image_free);
  ASSERT_TRUE(rgb);
  int orange = 0, cyan = 0;  // the two families' rods
  for (int i = 0; i < width * height; ++i) {
    const unsigned char* q = rgb.get() + 3 * i;
    orange += q[0] > 180 && q[1] > 70 && q[1] < 160 && q[2] < 80;
    cyan += q[2] > 180 && q[1] > 140 && q[0] < 120;
  }
  EXPECT_GT(orange, 100);
  EXPECT_GT(cyan, 100);
}

TEST(CliFibres, DiscValidationSetsTheDiscBesideInVitroTests) {
  const CliRun r = run_spinesim("study disc-validation --mesh '" + disc_vtu() + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 6u);
  for (const auto& row : j["rows"]) {
    EXPECT_TRUE(row["verdict"] == "MATCH" || row["verdict"] == "MISS") << row.dump();
    EXPECT_FALSE(row["source"].get<std::string>().empty());
  }
  expect_refused(run_spinesim("study disc-validation --level L9-L10"), "L9-L10");
  expect_refused(run_spinesim("study disc-validation --targets /nonexistent.json"),
                 "/nonexistent.json");
  expect_refused(run_spinesim("study disc-validation --material nothing"), "unknown material");
}

// The nonlinear disc in the study: six rows, the load paths as CSV, and with --out the JSON, the
// figure and report.html; its options refused with the linear model, a bad value refused, and
// nothing written.
TEST(CliFibres, DiscValidationRunsTheNonlinearDisc) {
  const std::string paths = tmp("paths.csv");
  std::filesystem::remove(paths);
  const std::string out = tmp("disc-validation-out");
  std::filesystem::remove_all(out);
  const CliRun r = run_spinesim("study disc-validation --mesh '" + disc_vtu() +
                                "' --model nonlinear --increments 3 --paths '" + paths +
                                "' --out '" + out + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 6u);
  for (const auto& row : j["rows"]) EXPECT_TRUE(row["ours"].is_number()) << row.dump();
  EXPECT_EQ(count_lines(csv_table(paths)), 1 + 5 * 3);
  for (const char* file : {"disc_validation.json", "disc_validation.csv", "disc_paths.csv",
                           "report.html", "plots/disc_paths.png"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + file)) << file << "\n" << r.err;

  const std::string unwritten = tmp("unwritten.csv");
  std::filesystem::remove(unwritten);
  expect_refused(
      run_spinesim("study disc-validation --model nonlinear --order 3 --paths '" + unwritten + "'"),
      "--order must be 1 or 2");
  expect_refused(run_spinesim("study disc-validation --model nonlinear --fibre-k2 -1"),
                 "--fibre-k2");
  expect_refused(run_spinesim("study disc-validation --order 2"), "need --model nonlinear");
  expect_refused(run_spinesim("study disc-validation --preload 500"), "need --model nonlinear");
  expect_refused(run_spinesim("study disc-validation --model nonlinear --preload -5"),
                 "preload must be 0 to 10000 N");
  expect_refused(run_spinesim("study disc-validation --model nonlinear --formulation mixed"),
                 "--formulation is for --model linear");
  expect_refused(run_spinesim("study disc-validation --model quadratic"), "--model must be");
  EXPECT_FALSE(std::filesystem::exists(unwritten));
}

// The identified parameters as options: the shipped identified material is the preset with
// its fibre moduli doubled (59, 136 to 118, 272 MPa), k2 100 and nucleus E 1.26 MPa, so the
// preset with those options gives its numbers to the bit; a stiffer annulus stiffens every case;
// bad values and a material without fibres are refused.
TEST(CliFibres, DiscValidationTakesTheIdentifiedParametersAsOptions) {
  auto rows = [](const std::string& options) {
    const CliRun r = run_spinesim("study disc-validation --mesh '" + disc_vtu() +
                                  "' --model nonlinear --increments 2 --json " + options);
    EXPECT_EQ(r.status, 0) << r.err;
    std::vector<double> out;
    const auto j = nlohmann::json::parse(r.out);
    for (const auto& row : j["rows"]) out.push_back(row["ours"]);
    return out;
  };
  const auto identified = rows("--material disc-identified");
  const auto by_options = rows("--annulus-E 4.2 --fibre-scale 2 --fibre-k2 100 --nucleus-E 1.26");
  ASSERT_EQ(identified.size(), 6u);
  EXPECT_EQ(identified, by_options);
  const auto softer = rows("--annulus-E 2.1 --fibre-scale 2 --fibre-k2 100 --nucleus-E 1.26");
  for (std::size_t i = 0; i + 1 < 6; ++i) EXPECT_LT(softer[i], identified[i]) << i;
  expect_refused(run_spinesim("study disc-validation --nucleus-E 0"), "--nucleus-E");
  expect_refused(run_spinesim("study disc-validation --material rubber --fibre-scale 2"),
                 "'rubber' is not one");
}

// The identification on the small structured disc (fine = coarse: seconds), and its
// leave-one-out on two targets:
// parameters with bounds and sources, six rows with the disc's values, the held-out rows, the
// folder's files and a preset that the material reader takes. Bad input: one line, nothing
// written.
TEST(CliFibres, DiscIdentifyFitsTheMaterialAndWritesAPreset) {
  const std::string out = tmp("disc-identify-out");
  std::filesystem::remove_all(out);
  const CliRun r =
      run_spinesim("study disc-identify --mesh '" + disc_vtu() +
                   "' --fine-order 1 --increments 2 --no-leave-one-out --out '" + out + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["success"].get<bool>());
  ASSERT_EQ(j["parameters"].size(), 4u);
  for (const auto& p : j["parameters"]) {
    EXPECT_GE(p["identified"].get<double>(), p["lower"].get<double>()) << p.dump();
    EXPECT_LE(p["identified"].get<double>(), p["upper"].get<double>()) << p.dump();
    EXPECT_FALSE(p["bounds_source"].get<std::string>().empty());
  }
  ASSERT_EQ(j["targets"].size(), 6u);
  for (const auto& row : j["targets"]) {
    EXPECT_TRUE(row["identified"].is_number()) << row.dump();
    EXPECT_TRUE(row["leave_one_out"].is_null()) << row.dump();
  }

  // Leave-one-out on two targets (two quick fits): each row predicted by the fit to the other.
  const std::string two = tmp("two_targets.json");
  std::ofstream(two) << R"({"targets": [
      {"quantity": "torsion", "units": "N m/deg", "low": 2.29, "high": 4.07},
      {"quantity": "flexion", "units": "N m/deg", "low": 2.3, "high": 3.3}]})";
  const CliRun l = run_spinesim("study disc-identify --mesh '" + disc_vtu() + "' --targets '" +
                                two + "' --fine-order 1 --increments 2 --json");
  ASSERT_EQ(l.status, 0) << l.err;
  const auto lj = nlohmann::json::parse(l.out);
  for (const auto& row : lj["targets"]) EXPECT_TRUE(row["leave_one_out"].is_number()) << row.dump();
  for (const auto& p : lj["parameters"]) EXPECT_EQ(p["leave_one_out"].size(), 2u) << p.dump();
  EXPECT_EQ(j["held_out"].size(), 4u);
  for (const char* file : {"disc_identification.json", "disc_identification.md",
                           "disc-identified.json", "report.html", "plots/disc_identification.png"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + file)) << file;
  const CliRun v =
      run_spinesim("study disc-validation --mesh '" + disc_vtu() + "' --material '" + out +
                   "/disc-identified.json' --model nonlinear --increments 2 --json");
  EXPECT_EQ(v.status, 0) << v.err;

  const std::string unwritten = tmp("unwritten-preset.json");
  std::filesystem::remove(unwritten);
  expect_refused(run_spinesim("study disc-identify --fine-order 3 --preset '" + unwritten + "'"),
                 "orders must be 1 or 2");
  expect_refused(run_spinesim("study disc-identify --material annulus-nucleus"),
                 "needs an annulus with fibres and a nucleus");
  expect_refused(run_spinesim("study disc-identify --level L9-L10"), "L9-L10");
  expect_refused(run_spinesim("study disc-identify --cell-size -1"), "--cell-size");
  EXPECT_FALSE(std::filesystem::exists(unwritten));
}

// The mass-spring disc fitted to the nonlinear FEM disc (small structured disc, P1, three cases
// at two levels): a row per case and level with its set, both networks' fits lower the training
// objective they start from, the files are written; bad requests are one line, nothing written.
TEST(CliFibres, MssFibresFitsBothNetworksToTheNonlinearDisc) {
  const std::string out = tmp("mss-fibres-out");
  std::filesystem::remove_all(out);
  const CliRun r = run_spinesim("study mss-fibres --mesh '" + disc_vtu() +
                                "' --cases compression,torsion,flexion --train compression,torsion"
                                " --levels 0.1,1 --increments 2 --curve-levels 0.5,1 --out '" +
                                out + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["reference"].size(), 6u);
  EXPECT_GT(j["fibre_springs"].get<int>(), 0);
  EXPECT_EQ(j["fibre_stretch"], "isochoric");  // the default: the FEM's measure
  for (const char* network : {"region", "fibre"}) {
    const auto& fit = j[network];
    EXPECT_TRUE(fit["success"].get<bool>()) << network;
    ASSERT_EQ(fit["cases"].size(), 6u) << network;
    double start = 0;
    int trained = 0;
    for (const auto& c : fit["cases"]) {
      const bool train = c["set"] == "train";
      EXPECT_EQ(train, c["case"] != "flexion") << c.dump();
      EXPECT_TRUE(c["converged"].get<bool>()) << c.dump();
      EXPECT_TRUE(std::isfinite(c["reaction_error"].get<double>())) << c.dump();
      if (!train) continue;
      const double er = c["reaction_error_untuned"], eu = c["displacement_error_untuned"];
      start += er * er + eu * eu;
      ++trained;
    }
    ASSERT_EQ(trained, 4) << network;
    // The reaction error is |S (R - R*)| / |S R*| of the wrenches written beside it.
    const double rho = j["plate_rms_radius_mm"].get<double>();
    for (std::size_t i = 0; i < fit["cases"].size(); ++i) {
      const auto &mss = fit["cases"][i]["reaction_wrench"],
                 &fem = j["reference"][i]["reaction_wrench"];
      double diff = 0, norm = 0;
      for (int k = 0; k < 6; ++k) {
        const double s = k < 3 ? 1.0 : 1.0 / rho, f = fem[k].get<double>();
        diff += std::pow(s * (mss[k].get<double>() - f), 2);
        norm += std::pow(s * f, 2);
      }
      EXPECT_NEAR(std::sqrt(diff / norm), fit["cases"][i]["reaction_error"].get<double>(), 1e-9)
          << network << " " << i;
    }
    EXPECT_LE(fit["objective"].get<double>(), 0.5 * start / trained) << network;
  }
  EXPECT_TRUE(j["fibre"]["scales"].contains("fibre")) << j["fibre"]["scales"].dump();
  EXPECT_FALSE(j["region"]["scales"].contains("fibre")) << j["region"]["scales"].dump();
  // Curves of the two moment cases at the curve levels: the FEM's moment along its axis is the
  // applied one (the reaction is −W − ½ θ × W, whose second part is normal to W), rotations and
  // every network's moments grow with the level; the in-vitro windows of both cases beside them.
  ASSERT_EQ(j["curves"].size(), 2u);
  for (const auto& c : j["curves"]) {
    double standard_nm = 0;
    for (const auto& ref : j["reference"])
      if (ref["case"] == c["case"] && ref["level"] == 1.0)
        for (int k = 3; k < 6; ++k) standard_nm += std::pow(ref["wrench"][k].get<double>(), 2);
    standard_nm = std::sqrt(standard_nm) / 1000.0;
    ASSERT_GT(standard_nm, 0) << c.dump();
    ASSERT_EQ(c["rotation_deg"].size(), 2u);
    const double levels[2] = {0.5, 1.0};
    for (int k = 0; k < 2; ++k)
      EXPECT_NEAR(c["fem_moment_nm"][k].get<double>(), levels[k] * standard_nm, 1e-6 * standard_nm)
          << c.dump();
    for (const char* key : {"rotation_deg", "region_moment_nm", "fibre_moment_nm"})
      EXPECT_GT(c[key][1].get<double>(), c[key][0].get<double>()) << key << c.dump();
    EXPECT_GT(c["fibre_moment_nm"][0].get<double>(), 0) << c.dump();
  }
  EXPECT_EQ(j["corridors"].size(), 2u) << j["corridors"].dump();
  for (const char* file :
       {"mss_fibres.json", "mss_fibres.md", "report.html", "plots/mss_fibres_curves.png"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + file)) << file;

  const std::string unwritten = tmp("mss-fibres-unwritten");
  std::filesystem::remove_all(unwritten);
  const std::string o = " --out '" + unwritten + "'";
  expect_refused(run_spinesim("study mss-fibres --material annulus-nucleus" + o), "has no fibres");
  expect_refused(run_spinesim("study mss-fibres --levels 0,1" + o), "load levels");
  expect_refused(run_spinesim("study mss-fibres --curve-levels 0.5,3" + o), "load levels");
  expect_refused(run_spinesim("study mss-fibres --cases torsion --train torsion" + o),
                 "none is held out");
  expect_refused(run_spinesim("study mss-fibres --train bending" + o), "'bending'");
  expect_refused(run_spinesim("study mss-fibres --fem-order 3" + o), "--fem-order");
  expect_refused(run_spinesim("study mss-fibres --terms springs" + o), "--terms 'springs'");
  expect_refused(run_spinesim("study mss-fibres --cell-size 0" + o), "--cell-size");
  expect_refused(run_spinesim("study mss-fibres --fibre-stretch length" + o), "--fibre-stretch");
  EXPECT_FALSE(std::filesystem::exists(unwritten));
}

}  // namespace
}  // namespace spinesim::test_cli
