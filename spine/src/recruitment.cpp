// Static-optimisation muscle recruitment through Ipopt's TNLP interface (recruitment.hpp).
// Variables x = [F (muscles, N), r (joint shares, N·mm), t (min–max only)]; constraints
// arm·F + r = b (one per recruited joint axis) and, for min–max, F_i/F_max,i − t ≤ 0,
// r/R⁺ − t ≤ 0 and −r/R⁻ − t ≤ 0.
#include "spinesim/spine/recruitment.hpp"

#include "spinesim/common/timer.hpp"

#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

#include <cmath>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace spinesim::spine {
namespace {

constexpr double kMinMaxRegularisation = 1e-3;  // makes the min–max optimum unique

/// Activation of a joint axis carrying r: r/R⁺ (flexion side) or −r/R⁻, and its derivatives.
struct JointStrength {
  double pos = 1, neg = 1;  // N·mm
  double activation(double r) const { return r >= 0 ? r / pos : -r / neg; }
  double slope(double r) const { return r >= 0 ? 1 / pos : -1 / neg; }  // d activation / dr
};

class RecruitmentNlp : public Ipopt::TNLP {
 public:
  RecruitmentNlp(const Eigen::MatrixXd& arm, const Eigen::VectorXd& b, const Eigen::VectorXd& fmax,
                 std::vector<JointStrength> strength, const RecruitmentOptions& o, double floor,
                 double tone)
      : floor_(floor),
        tone_(tone),
        arm_(arm),
        b_(b),
        fmax_(fmax),
        strength_(std::move(strength)),
        o_(o),
        nm_(int(fmax.size())),
        nr_(int(b.size())),
        minmax_(o.criterion == Criterion::MinMax) {
    for (int c = 0; c < nm_; ++c)
      for (int r = 0; r < nr_; ++r)
        if (arm_(r, c) != 0) nz_.push_back({r, c});
  }

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac, Ipopt::Index& nnz_h,
                    IndexStyleEnum& style) override {
    n = nm_ + nr_ + (minmax_ ? 1 : 0);
    m = nr_ + (minmax_ ? nm_ + 2 * nr_ : 0);
    nnz_jac = Ipopt::Index(nz_.size()) + nr_ + (minmax_ ? 2 * nm_ + 4 * nr_ : 0);
    nnz_h = nm_ + nr_;  // diagonal
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* xl, Ipopt::Number* xu, Ipopt::Index m,
                       Ipopt::Number* gl, Ipopt::Number* gu) override {
    for (int i = 0; i < nm_; ++i) {
      xl[i] = floor_ * fmax_[i];
      xu[i] = fmax_[i];
    }
    for (int i = nm_; i < nm_ + nr_; ++i) {
      xl[i] = -2e19;
      xu[i] = 2e19;
    }
    if (minmax_) {
      xl[n - 1] = 0;
      xu[n - 1] = 2e19;
    }
    for (int k = 0; k < nr_; ++k) gl[k] = gu[k] = b_[k];
    for (int k = nr_; k < m; ++k) {
      gl[k] = -2e19;
      gu[k] = 0;
    }
    return true;
  }

  bool get_starting_point(Ipopt::Index n, bool, Ipopt::Number* x, bool, Ipopt::Number*,
                          Ipopt::Number*, Ipopt::Index, bool, Ipopt::Number*) override {
    for (int i = 0; i < nm_; ++i) x[i] = (floor_ + 0.05 * (1 - floor_)) * fmax_[i];
    for (int i = nm_; i < nm_ + nr_; ++i) x[i] = 0;
    if (minmax_) x[n - 1] = 0.1;
    return true;
  }

  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    f = 0;
    for (int i = 0; i < nm_; ++i) {
      const double a = x[i] / fmax_[i] - tone_;  // the tone is not recruited
      f += minmax_ ? kMinMaxRegularisation * a * a : std::pow(std::max(a, 0.0), o_.power);
    }
    for (int k = 0; k < nr_; ++k) {
      const double a = strength_[std::size_t(k)].activation(x[nm_ + k]);
      f += minmax_ ? kMinMaxRegularisation * a * a : std::pow(a, o_.power);
    }
    if (minmax_) f += x[nm_ + nr_];
    return true;
  }

  bool eval_grad_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number* g) override {
    for (int i = 0; i < nm_; ++i) {
      const double a = std::max(x[i] / fmax_[i] - tone_, 0.0);
      g[i] = minmax_ ? 2 * kMinMaxRegularisation * a / fmax_[i]
                     : o_.power * std::pow(a, o_.power - 1) / fmax_[i];
    }
    for (int k = 0; k < nr_; ++k) {
      const JointStrength& s = strength_[std::size_t(k)];
      const double r = x[nm_ + k], a = s.activation(r);
      g[nm_ + k] =
          (minmax_ ? 2 * kMinMaxRegularisation * a : o_.power * std::pow(a, o_.power - 1)) *
          s.slope(r);
    }
    if (minmax_) g[nm_ + nr_] = 1;
    return true;
  }

  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Number* g) override {
    for (int k = 0; k < nr_; ++k) g[k] = x[nm_ + k];
    for (const auto& [r, c] : nz_) g[r] += arm_(r, c) * x[c];
    if (minmax_) {
      const double t = x[nm_ + nr_];
      for (int i = 0; i < nm_; ++i) g[nr_ + i] = x[i] / fmax_[i] - tone_ - t;
      for (int k = 0; k < nr_; ++k) {
        g[nr_ + nm_ + 2 * k] = x[nm_ + k] / strength_[std::size_t(k)].pos - t;
        g[nr_ + nm_ + 2 * k + 1] = -x[nm_ + k] / strength_[std::size_t(k)].neg - t;
      }
    }
    return true;
  }

  bool eval_jac_g(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Index,
                  Ipopt::Index* rows, Ipopt::Index* cols, Ipopt::Number* values) override {
    std::size_t e = 0;
    if (values == nullptr) {
      for (const auto& [r, c] : nz_) {
        rows[e] = r;
        cols[e] = c;
        ++e;
      }
      for (int k = 0; k < nr_; ++k) {
        rows[e] = k;
        cols[e] = nm_ + k;
        ++e;
      }
      if (minmax_) {
        for (int i = 0; i < nm_; ++i) {
          rows[e] = nr_ + i;
          cols[e] = i;
          ++e;
          rows[e] = nr_ + i;
          cols[e] = nm_ + nr_;
          ++e;
        }
        for (int k = 0; k < 2 * nr_; ++k) {
          rows[e] = nr_ + nm_ + k;
          cols[e] = nm_ + k / 2;
          ++e;
          rows[e] = nr_ + nm_ + k;
          cols[e] = nm_ + nr_;
          ++e;
        }
      }
    } else {
      for (const auto& [r, c] : nz_) values[e++] = arm_(r, c);
      for (int k = 0; k < nr_; ++k) values[e++] = 1;
      if (minmax_) {
        for (int i = 0; i < nm_; ++i) {
          values[e++] = 1 / fmax_[i];
          values[e++] = -1;
        }
        for (int k = 0; k < nr_; ++k) {
          values[e++] = 1 / strength_[std::size_t(k)].pos;
          values[e++] = -1;
          values[e++] = -1 / strength_[std::size_t(k)].neg;
          values[e++] = -1;
        }
      }
    }
    return true;
  }

  bool eval_h(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number sigma, Ipopt::Index,
              const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Index* rows, Ipopt::Index* cols,
              Ipopt::Number* values) override {
    if (values == nullptr) {
      for (int i = 0; i < nm_ + nr_; ++i) rows[i] = cols[i] = i;
      return true;
    }
    for (int i = 0; i < nm_; ++i) {
      const double a = std::max(x[i] / fmax_[i] - tone_, 0.0);
      const double h = minmax_ ? 2 * kMinMaxRegularisation
                               : o_.power * (o_.power - 1) * std::pow(a, o_.power - 2);
      values[i] = sigma * h / (fmax_[i] * fmax_[i]);
    }
    for (int k = 0; k < nr_; ++k) {
      const JointStrength& s = strength_[std::size_t(k)];
      const double r = x[nm_ + k], a = s.activation(r), d = s.slope(r);
      const double h = minmax_ ? 2 * kMinMaxRegularisation
                               : o_.power * (o_.power - 1) * std::pow(a, o_.power - 2);
      values[nm_ + k] = sigma * h * d * d;
    }
    return true;
  }

  bool intermediate_callback(Ipopt::AlgorithmMode, Ipopt::Index iter, Ipopt::Number, Ipopt::Number,
                             Ipopt::Number, Ipopt::Number, Ipopt::Number, Ipopt::Number,
                             Ipopt::Number, Ipopt::Number, Ipopt::Index, const Ipopt::IpoptData*,
                             Ipopt::IpoptCalculatedQuantities*) override {
    iterations = iter;
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index n, const Ipopt::Number* x,
                         const Ipopt::Number*, const Ipopt::Number*, Ipopt::Index m,
                         const Ipopt::Number* g, const Ipopt::Number*, Ipopt::Number obj,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    solution = Eigen::Map<const Eigen::VectorXd>(x, n);
    objective = obj;
    violation = 0;
    for (int k = 0; k < nr_ && k < m; ++k) violation = std::max(violation, std::abs(g[k] - b_[k]));
  }

  Eigen::VectorXd solution;
  double objective = 0, violation = 0;
  int iterations = 0;

 private:
  double floor_, tone_;  ///< the muscles' least activation; the part of it not recruited
  const Eigen::MatrixXd& arm_;
  const Eigen::VectorXd& b_;
  const Eigen::VectorXd& fmax_;
  std::vector<JointStrength> strength_;
  RecruitmentOptions o_;
  int nm_, nr_;
  bool minmax_;
  std::vector<std::pair<int, int>> nz_;
};

std::string status_name(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
      return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level:
      return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected:
      return "Infeasible_Problem_Detected";
    case Ipopt::Maximum_Iterations_Exceeded:
      return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed:
      return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation:
      return "Error_In_Step_Computation";
    case Ipopt::Invalid_Number_Detected:
      return "Invalid_Number_Detected";
    default:
      return "Ipopt_status_" + std::to_string(int(s));
  }
}

// Debian's Ipopt solves with sequential MUMPS, whose Fortran state is not safe to share between
// threads; recruitment is a few milliseconds, so concurrent solves take turns here.
std::mutex& ipopt_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

Recruitment recruit(const SpineModel& m, const Eigen::MatrixXd& arm,
                    const Eigen::VectorXd& load_moment_nmm, const RecruitmentOptions& options) {
  const Timer timer;
  if (!(options.power >= 2 && options.power <= 10))
    throw std::invalid_argument("recruitment power must be in [2, 10], got " +
                                std::to_string(options.power));
  if (!(options.passive_strength_scale > 0) || options.max_iterations < 1 ||
      !(options.tolerance > 0))
    throw std::invalid_argument(
        "recruitment: passive strength scale and tolerance must be > 0, iterations >= 1");
  // The rows are the recruited, non-fused joints in order (recruitment_problem); each axis's
  // strength is its spring's moment at the range-of-motion limit.
  std::vector<JointStrength> strength;
  for (int j : m.recruited_joints) {
    const Joint& jt = m.joints[std::size_t(j)];
    if (jt.fused) continue;
    const double s = options.passive_strength_scale;
    strength.push_back({s * jt.k_flexion * jt.rom_flexion, s * jt.k_extension * jt.rom_extension});
    strength.push_back({s * jt.k_torsion * jt.rom_torsion, s * jt.k_torsion * jt.rom_torsion});
    strength.push_back({s * jt.k_lateral * jt.rom_lateral, s * jt.k_lateral * jt.rom_lateral});
  }
  for (const auto& st : strength)
    if (!(st.pos > 0 && st.neg > 0))
      throw std::invalid_argument("recruit: a recruited joint has zero range of motion");
  const Eigen::Index nm = Eigen::Index(m.muscles.size());
  if (arm.cols() != nm || arm.rows() != load_moment_nmm.size() ||
      arm.rows() != Eigen::Index(strength.size()))
    throw std::invalid_argument(
        "recruit: arm must be (3·recruited joints) × muscles, matching the load moments");
  if (!arm.allFinite() || !load_moment_nmm.allFinite())
    throw std::invalid_argument("recruit: non-finite input");
  Eigen::VectorXd fmax(nm);
  for (Eigen::Index i = 0; i < nm; ++i) fmax[i] = m.muscles[std::size_t(i)].max_force_n();

  Recruitment out;
  out.force_n = Eigen::VectorXd::Zero(nm);
  out.activation = Eigen::VectorXd::Zero(nm);
  out.reserve_nmm = load_moment_nmm;
  out.passive_activation = Eigen::VectorXd::Zero(load_moment_nmm.size());
  if (nm == 0 || arm.rows() == 0) {  // nothing to recruit: every moment is left to the joints
    out.success = true;
    out.status = nm == 0 ? "no muscles" : "no recruited joints";
    return out;
  }
  if (!(m.muscle_floor >= 0 && m.muscle_floor < 1) || !(m.muscle_tone >= 0 && m.muscle_tone < 1))
    throw std::invalid_argument("recruit: muscle floor and tone must lie in [0, 1)");
  Ipopt::SmartPtr<RecruitmentNlp> nlp =
      new RecruitmentNlp(arm, load_moment_nmm, fmax, strength, options,
                         std::max(m.muscle_floor, m.muscle_tone), m.muscle_tone);
  {
    std::lock_guard<std::mutex> lock(ipopt_mutex());
    Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
    app->Options()->SetIntegerValue("print_level", 0);
    app->Options()->SetStringValue("sb", "yes");
    app->Options()->SetIntegerValue("max_iter", options.max_iterations);
    app->Options()->SetNumericValue("tol", options.tolerance);
    app->Options()->SetStringValue("mu_strategy", "adaptive");
    std::istringstream no_option_file;  // never read ./ipopt.opt
    if (app->Initialize(no_option_file) != Ipopt::Solve_Succeeded) {
      out.status = "Ipopt_Initialisation_Failed";
      return out;
    }
    const Ipopt::ApplicationReturnStatus st = app->OptimizeTNLP(nlp);
    out.status = status_name(st);
    out.success = st == Ipopt::Solve_Succeeded || st == Ipopt::Solved_To_Acceptable_Level;
  }
  out.iterations = nlp->iterations;
  if (nlp->solution.size() >= nm + arm.rows()) {
    out.force_n = nlp->solution.head(nm).cwiseMax(0.0).cwiseMin(fmax);
    out.activation = out.force_n.cwiseQuotient(fmax);
    out.reserve_nmm = nlp->solution.segment(nm, arm.rows());
    out.passive_activation.resize(arm.rows());
    for (Eigen::Index k = 0; k < arm.rows(); ++k)
      out.passive_activation[k] = strength[std::size_t(k)].activation(out.reserve_nmm[k]);
    out.objective = nlp->objective;
    out.max_constraint_violation_nmm = nlp->violation;
  }
  out.seconds = timer.seconds();
  return out;
}

}  // namespace spinesim::spine
