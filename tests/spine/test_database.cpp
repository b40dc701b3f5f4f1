// The displacement–force database (spine/database.hpp): polynomial fits, evaluation by
// superposition, the shipped file against direct solves of the model, mirror symmetry, file
// errors. Fast: a handful of equilibrium solves (~30 ms each).
#include "spinesim/spine/database.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

namespace {
using namespace spinesim::spine;
using Eigen::Vector3d;

const std::string kShipped = std::string(SPINESIM_DATA_DIR) + "/spine/displacement_db.json";

const DisplacementDatabase& shipped() {
  static const DisplacementDatabase db = DisplacementDatabase::load(kShipped);
  return db;
}

/// The model the shipped file was generated from.
const SpineModel& model() {
  static const SpineModel m = load_spine_model(SPINESIM_DATA_DIR, shipped().info.model);
  return m;
}

std::string tmp_path(const std::string& name) {
  std::filesystem::create_directories(SPINESIM_TEST_TMP);
  return std::string(SPINESIM_TEST_TMP) + "/" + name;
}

void write_file(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

bool failed_in_file(const DisplacementDatabase& db, int v, int d, double f) {
  for (const auto& x : db.info.failed)
    if (x.vertebra == v && x.direction == d && x.force_n == f) return true;
  return false;
}

/// Solved response of the model (relative to gravity only), as the database defines it.
VertebraResponse direct_response(int v, const Vector3d& force_n) {
  static const VertebraResponse baseline =
      solve_spine(model(), {}, shipped().info.solve).displacement;
  ExternalLoad l;
  l.vertebra = v;
  l.force_n = force_n;
  return VertebraResponse(solve_spine(model(), {l}, shipped().info.solve).displacement) - baseline;
}

// --- fitting ---------------------------------------------------------------------------------

TEST(PolynomialFit, RecoversAnExactCubic) {
  Eigen::VectorXd f(12), y(12);
  for (int k = 0; k < 12; ++k) {
    f[k] = 50.0 * (k + 1);
    const double s = f[k] / 600.0;
    y[k] = 2.0 * s - 3.0 * s * s + 0.5 * s * s * s;
  }
  FitTolerance tight;
  tight.relative = 1e-10;
  tight.absolute = 1e-12;
  tight.quantum = 0;
  const PolynomialFit fit = fit_by_residual(f, y, 600.0, tight);
  ASSERT_EQ(fit.coefficients.size(), 3);  // the lowest degree that fits: not 4 or 5
  EXPECT_NEAR(fit.coefficients[0], 2.0, 1e-9);
  EXPECT_NEAR(fit.coefficients[1], -3.0, 1e-9);
  EXPECT_NEAR(fit.coefficients[2], 0.5, 1e-9);
  EXPECT_TRUE(fit.within_tolerance);
  EXPECT_LT(fit.max_residual, 1e-10);
}

TEST(PolynomialFit, PicksTheLowestDegreeWithinTolerance) {
  Eigen::VectorXd f(12), y(12);
  for (int k = 0; k < 12; ++k)
    f[k] = 50.0 * (k + 1), y[k] = 0.02 * f[k] + 1e-5 * std::sin(double(k));
  const PolynomialFit fit = fit_by_residual(f, y, 600.0);  // default: 1 % of range or 1e-3
  EXPECT_EQ(fit.coefficients.size(), 1);
  EXPECT_NEAR(fit.coefficients[0], 12.0, 1e-3);  // 0.02 mm/N over 600 N
  // Coefficients are rounded to the quantum the file stores, residuals include the rounding.
  EXPECT_EQ(fit.coefficients[0], round_to_quantum(fit.coefficients[0], FitTolerance().quantum));
}

TEST(PolynomialFit, RoundsToShortDecimals) {
  EXPECT_EQ(round_to_quantum(-295.289010999, 1e-5), -295.28901);
  EXPECT_EQ(round_to_quantum(0.123456789, 1e-5), 0.12346);
  EXPECT_FALSE(std::signbit(round_to_quantum(-1e-9, 1e-5)));  // no "-0" in the file
  EXPECT_EQ(round_to_quantum(0.3, 0), 0.3);
}

TEST(PolynomialFit, NoConstantTermAndHornerAgree) {
  const double c[] = {1.5, -0.25, 0.125};
  EXPECT_EQ(evaluate_polynomial(c, 3, 0.0), 0.0);
  const double s = 0.7;
  EXPECT_NEAR(evaluate_polynomial(c, 3, s), 1.5 * s - 0.25 * s * s + 0.125 * s * s * s, 1e-15);
}

TEST(PolynomialFit, RefusesBadSamples) {
  Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(4, 50, 200), y = Eigen::VectorXd::Zero(4);
  EXPECT_THROW(fit_zero_intercept(f, Eigen::VectorXd::Zero(3), 1, 600), std::invalid_argument);
  EXPECT_THROW(fit_zero_intercept(f, y, 5, 600), std::invalid_argument);  // 4 samples, degree 5
  y[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fit_zero_intercept(f, y, 2, 600), std::invalid_argument);
}

// --- fit + evaluate on synthetic samples (no solver) -----------------------------------------

/// Samples whose every series is a known polynomial of the force: sign-dependent per direction.
ResponseSamples synthetic(const std::vector<int>& loaded) {
  ResponseSamples s;
  for (int k = 0; k <= 12; ++k) s.forces_n.push_back(50.0 * k);
  s.loaded_vertebrae = loaded;
  s.responses.resize(kDbVertebrae);
  s.solved.resize(kDbVertebrae);
  for (int v : loaded)
    for (int d = 0; d < kDbDirections; ++d) {
      auto& r = s.responses[std::size_t(v)][std::size_t(d)];
      for (double f : s.forces_n) {
        const double x = f / 600.0;
        VertebraResponse m;
        for (int j = 0; j < kDbVertebrae; ++j)
          for (int c = 0; c < kDbComponents; ++c)
            m(j, c) =
                (d + 1) * (0.1 * (j + 1) * x + 0.01 * c * x * x) + (d == 4 ? 3.0 * x * x * x : 0.0);
        r.push_back(m);
      }
      s.solved[std::size_t(v)][std::size_t(d)].assign(s.forces_n.size(), true);
    }
  return s;
}

TEST(DisplacementDatabase, SuperposesTheAxisFitsBySign) {
  FitTolerance tight;
  tight.relative = tight.absolute = 1e-9;
  tight.quantum = 0;
  const DisplacementDatabase db = DisplacementDatabase::fit(synthetic({0, 6}), tight);
  ASSERT_TRUE(db.has_vertebra(0));
  ASSERT_FALSE(db.has_vertebra(3));
  EXPECT_EQ(db.degree(0, 4, 0, 0), 3);  // +z has the cubic term
  const Vector3d force(-120.0, 0.0, 300.0);
  VertebraResponse got;
  db.evaluate(6, force, got);
  for (int j = 0; j < kDbVertebrae; ++j)
    for (int c = 0; c < kDbComponents; ++c) {
      const double xm = 120.0 / 600.0, xz = 300.0 / 600.0;
      const double minus_x = 2 * (0.1 * (j + 1) * xm + 0.01 * c * xm * xm);  // direction 1 (-x)
      const double plus_z = 5 * (0.1 * (j + 1) * xz + 0.01 * c * xz * xz) + 3.0 * xz * xz * xz;
      EXPECT_NEAR(got(j, c), minus_x + plus_z, 1e-9) << j << "," << c;
    }
  EXPECT_EQ(db.info.residuals.fits, 2 * kDbDirections * kDbVertebrae * kDbComponents);
  EXPECT_EQ(db.info.residuals.fits_above_tolerance, 0);
}

TEST(DisplacementDatabase, FailedSolvesLimitTheRangeAndTooManyRefuse) {
  ResponseSamples s = synthetic({0});
  s.solved[0][2][12] = false;  // +y at 600 N failed
  s.failed.push_back({0, 2, 600.0, "did not converge"});
  const DisplacementDatabase db = DisplacementDatabase::fit(s, FitTolerance());
  EXPECT_EQ(db.solved_max_n(0, 2), 550.0);
  EXPECT_TRUE(db.in_range(Vector3d(0, 600, 0)));
  EXPECT_FALSE(db.in_range(0, Vector3d(0, 600, 0)));
  EXPECT_TRUE(db.in_range(0, Vector3d(0, -600, 0)));
  ASSERT_EQ(db.info.failed.size(), 1u);
  for (int k = 3; k <= 12; ++k) s.solved[0][2][std::size_t(k)] = false;
  EXPECT_THROW(DisplacementDatabase::fit(s, FitTolerance()), std::runtime_error);
}

// --- the shipped file ------------------------------------------------------------------------

TEST(ShippedDatabase, LoadsAndEvaluatesEveryVertebra) {
  const DisplacementDatabase& db = shipped();
  ASSERT_EQ(db.forces_n().size(), 13u);
  EXPECT_EQ(db.force_max_n(), 600.0);
  EXPECT_FALSE(db.info.generated_by.empty());
  EXPECT_TRUE(db.info.has_superposition);
  for (int v = 0; v < kDbVertebrae; ++v) {
    ASSERT_TRUE(db.has_vertebra(v)) << v;
    VertebraResponse r;
    db.evaluate(v, Vector3d(150, -200, 300), r);
    EXPECT_TRUE(r.allFinite());
    EXPECT_GT(r.norm(), 0.0);
  }
}

TEST(ShippedDatabase, ZeroForceGivesZero) {
  VertebraResponse r = VertebraResponse::Constant(7.0);
  shipped().evaluate(5, Vector3d::Zero(), r);
  EXPECT_EQ(r.cwiseAbs().maxCoeff(), 0.0);
}

TEST(ShippedDatabase, ReproducesDirectSolvesAtGridForces) {
  const DisplacementDatabase& db = shipped();
  // The gravity-only baseline first: the file must describe the current model.
  const auto [base_mm, base_deg] =
      max_response_difference(solve_spine(model(), {}, db.info.solve).displacement, db.baseline());
  EXPECT_LT(base_mm, 1e-3);
  EXPECT_LT(base_deg, 1e-3);
  struct Case {
    const char* vertebra;
    const char* direction;
    double force_n;
  };
  const Case cases[] = {{"T1", "+z", 300},
                        {"T7", "-x", 150},
                        {"L3", "+y", 450},
                        {"T12", "-z", 100},
                        {"L5", "+x", 600}};
  int checked = 0;
  for (const auto& c : cases) {
    const int v = vertebra_index(c.vertebra), d = direction_index(c.direction);
    if (failed_in_file(db, v, d, c.force_n)) continue;  // recorded in the file, not a sample
    const Vector3d f = c.force_n * direction_vector(d);
    VertebraResponse from_db;
    db.evaluate(v, f, from_db);
    const auto [mm, deg] = max_response_difference(from_db, direct_response(v, f));
    // The fit's own worst residual bounds it; the margin covers the solver tolerance.
    EXPECT_LE(mm, db.max_residual_translation_mm(v, d) + 2e-3)
        << c.vertebra << " " << c.direction << " " << c.force_n;
    EXPECT_LE(deg, db.max_residual_rotation_deg(v, d) + 2e-3)
        << c.vertebra << " " << c.direction << " " << c.force_n;
    ++checked;
  }
  EXPECT_GE(checked, 3);
}

/// Mirror in the sagittal plane (x → −x): tx flips; the rotation vector is axial, so rx stays
/// and ry, rz flip.
VertebraResponse mirrored(const VertebraResponse& r) {
  VertebraResponse m = r;
  m.col(0) *= -1;
  m.col(4) *= -1;
  m.col(5) *= -1;
  return m;
}

TEST(ShippedDatabase, LateralForcesGiveMirrorImages) {
  // The model is symmetric about the sagittal plane: direct solves mirror to round-off ...
  const int t1 = vertebra_index("T1");
  const VertebraResponse right = direct_response(t1, Vector3d(200, 0, 0));
  const VertebraResponse left = direct_response(t1, Vector3d(-200, 0, 0));
  const auto [mm, deg] = max_response_difference(mirrored(right), left);
  EXPECT_LT(mm, 1e-3 * (1 + right.leftCols<3>().cwiseAbs().maxCoeff()));
  EXPECT_LT(deg, 1e-3 * (1 + right.rightCols<3>().cwiseAbs().maxCoeff()));
  // ... and so do the two independently fitted directions of the database.
  const DisplacementDatabase& db = shipped();
  VertebraResponse plus, minus;
  db.evaluate(t1, Vector3d(200, 0, 0), plus);
  db.evaluate(t1, Vector3d(-200, 0, 0), minus);
  const auto [db_mm, db_deg] = max_response_difference(mirrored(plus), minus);
  EXPECT_LE(db_mm,
            db.max_residual_translation_mm(t1, 0) + db.max_residual_translation_mm(t1, 1) + 1e-3);
  EXPECT_LE(db_deg,
            db.max_residual_rotation_deg(t1, 0) + db.max_residual_rotation_deg(t1, 1) + 1e-3);
}

TEST(ShippedDatabase, RangeIsVisible) {
  const DisplacementDatabase& db = shipped();
  EXPECT_TRUE(db.in_range(Vector3d(600, -600, 600)));
  EXPECT_FALSE(db.in_range(Vector3d(0, 0, 600.5)));
  EXPECT_FALSE(db.in_range(Vector3d(0, 0, std::numeric_limits<double>::infinity())));
  // Beyond 600 N the polynomial is extrapolated, not clamped.
  VertebraResponse at600, at900;
  db.evaluate(0, Vector3d(0, 0, 600), at600);
  db.evaluate(0, Vector3d(0, 0, 900), at900);
  EXPECT_NE(at600, at900);
}

TEST(ShippedDatabase, RefusesBadInput) {
  const DisplacementDatabase& db = shipped();
  VertebraResponse r;
  EXPECT_THROW(db.evaluate(-1, Vector3d(1, 0, 0), r), std::invalid_argument);
  EXPECT_THROW(db.evaluate(17, Vector3d(1, 0, 0), r), std::invalid_argument);
  EXPECT_THROW(db.evaluate(0, Vector3d(std::nan(""), 0, 0), r), std::invalid_argument);
  EXPECT_THROW(db.evaluate(0, Vector3d(0, std::numeric_limits<double>::infinity(), 0), r),
               std::invalid_argument);
  EXPECT_THROW(direction_index("+w"), std::invalid_argument);
  const DisplacementDatabase part = DisplacementDatabase::fit(synthetic({2}), FitTolerance());
  EXPECT_THROW(part.evaluate(0, Vector3d(1, 0, 0), r), std::invalid_argument);  // T1 not in it
}

TEST(ShippedDatabase, SaveAndLoadRoundTrip) {
  const std::string path = tmp_path("db_roundtrip.json");
  shipped().save(path);
  const DisplacementDatabase again = DisplacementDatabase::load(path);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  for (int v : {0, 8, 16}) {
    VertebraResponse a, b;
    const Vector3d f(-333.3, 123.4, 456.7);
    shipped().evaluate(v, f, a);
    again.evaluate(v, f, b);
    EXPECT_EQ(a, b);
  }
  EXPECT_EQ(again.info.residuals.fits, shipped().info.residuals.fits);
  EXPECT_EQ(again.info.failed.size(), shipped().info.failed.size());
  EXPECT_EQ(again.info.superposition.cases.size(), shipped().info.superposition.cases.size());
  EXPECT_LT(std::filesystem::file_size(kShipped), 1u << 20);  // compact: well under 1 MB
}

// --- file errors -----------------------------------------------------------------------------

void expect_load_error(const std::string& path, const std::string& fragment) {
  try {
    DisplacementDatabase::load(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

TEST(DatabaseFile, MissingOrCorruptFilesGiveClearErrors) {
  expect_load_error(tmp_path("no_such_db.json"), "cannot read");
  const std::string truncated = tmp_path("db_truncated.json");
  std::ifstream in(kShipped);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_file(truncated, text.substr(0, text.size() / 2));
  expect_load_error(truncated, "not valid JSON");
  const std::string other = tmp_path("db_other_kind.json");
  write_file(other, R"({"kind": "something else"})");
  expect_load_error(other, "not a displacement database");
  // Well-formed JSON, wrong content: an unknown direction, a fit with too many coefficients.
  const auto corrupt = [&](const std::string& name, const std::string& from,
                           const std::string& to) {
    std::string bad = text;
    const std::size_t at = bad.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) bad.replace(at, from.size(), to);
    write_file(tmp_path(name), bad);
    return tmp_path(name);
  };
  expect_load_error(corrupt("db_direction.json", "\"direction\":\"+x\"", "\"direction\":\"+w\""),
                    "unknown direction");
  expect_load_error(corrupt("db_degree.json", "\"c\":[[[", "\"c\":[[[1,1,1,1,1,"), "coefficients");
}

TEST(DatabaseFile, SaveRefusesAnUnwritablePath) {
  EXPECT_THROW(shipped().save(tmp_path("no_such_folder/db.json")), std::runtime_error);
}

}  // namespace
