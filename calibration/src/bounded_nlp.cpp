#include "bounded_nlp.hpp"

#include "spinesim/common/timer.hpp"

#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace spinesim::calibration::detail {

namespace {

const char* status_name(Ipopt::ApplicationReturnStatus s) {
  using namespace Ipopt;
  switch (s) {
    case Solve_Succeeded:
      return "Solve_Succeeded";
    case Solved_To_Acceptable_Level:
      return "Solved_To_Acceptable_Level";
    case Infeasible_Problem_Detected:
      return "Infeasible_Problem_Detected";
    case Search_Direction_Becomes_Too_Small:
      return "Search_Direction_Becomes_Too_Small";
    case Diverging_Iterates:
      return "Diverging_Iterates";
    case User_Requested_Stop:
      return "User_Requested_Stop";
    case Feasible_Point_Found:
      return "Feasible_Point_Found";
    case Maximum_Iterations_Exceeded:
      return "Maximum_Iterations_Exceeded";
    case Restoration_Failed:
      return "Restoration_Failed";
    case Error_In_Step_Computation:
      return "Error_In_Step_Computation";
    case Maximum_CpuTime_Exceeded:
      return "Maximum_CpuTime_Exceeded";
    case Not_Enough_Degrees_Of_Freedom:
      return "Not_Enough_Degrees_Of_Freedom";
    case Invalid_Problem_Definition:
      return "Invalid_Problem_Definition";
    case Invalid_Option:
      return "Invalid_Option";
    case Invalid_Number_Detected:
      return "Invalid_Number_Detected";
    case Unrecoverable_Exception:
      return "Unrecoverable_Exception";
    case NonIpopt_Exception_Thrown:
      return "NonIpopt_Exception_Thrown";
    case Insufficient_Memory:
      return "Insufficient_Memory";
    case Internal_Error:
      return "Internal_Error";
  }
  return "Unknown_Status";
}

/// min f(p), ln lower <= p <= ln upper, for Ipopt.
class BoundedNlp : public Ipopt::TNLP {
 public:
  BoundedNlp(const NlpFunction& f, Eigen::VectorXd start, Eigen::VectorXd lower,
             Eigen::VectorXd upper, HessianKind hessian, const IpoptSettings& settings,
             const Progress& progress)
      : f_(f),
        start_(std::move(start)),
        lower_(std::move(lower)),
        upper_(std::move(upper)),
        hessian_(hessian),
        settings_(settings),
        progress_(progress) {}

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g,
                    Ipopt::Index& nnz_h_lag, IndexStyleEnum& index_style) override {
    n = Ipopt::Index(start_.size());
    m = 0, nnz_jac_g = 0;
    nnz_h_lag = hessian_ == HessianKind::dense ? n * (n + 1) / 2 : 0;  // dense lower triangle
    index_style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index,
                       Ipopt::Number*, Ipopt::Number*) override {
    for (Ipopt::Index i = 0; i < n; ++i) x_l[i] = lower_(i), x_u[i] = upper_(i);
    return true;
  }
  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z,
                          Ipopt::Number*, Ipopt::Number*, Ipopt::Index, bool init_lambda,
                          Ipopt::Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    for (Ipopt::Index i = 0; i < n; ++i) x[i] = start_(i);
    return true;
  }
  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    if (!evaluate(n, x)) return false;
    f = last_.value;
    return true;
  }
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number* g) override {
    if (!evaluate(n, x)) return false;
    for (Ipopt::Index i = 0; i < n; ++i) g[i] = last_.gradient(i);
    return true;
  }
  bool eval_g(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Number*) override {
    return true;
  }
  bool eval_jac_g(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Index,
                  Ipopt::Index*, Ipopt::Index*, Ipopt::Number*) override {
    return true;
  }
  bool eval_h(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number obj_factor, Ipopt::Index,
              const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Index* rows, Ipopt::Index* cols,
              Ipopt::Number* values) override {
    if (hessian_ != HessianKind::dense) return false;  // limited memory: never asked
    Ipopt::Index e = 0;
    if (!values) {
      for (Ipopt::Index i = 0; i < n; ++i)
        for (Ipopt::Index j = 0; j <= i; ++j) rows[e] = i, cols[e] = j, ++e;
      return true;
    }
    if (!evaluate(n, x)) return false;
    for (Ipopt::Index i = 0; i < n; ++i)
      for (Ipopt::Index j = 0; j <= i; ++j) values[e++] = obj_factor * last_.hessian(i, j);
    return true;
  }
  bool intermediate_callback(Ipopt::AlgorithmMode mode, Ipopt::Index iter, Ipopt::Number obj_value,
                             Ipopt::Number, Ipopt::Number inf_du, Ipopt::Number, Ipopt::Number,
                             Ipopt::Number, Ipopt::Number, Ipopt::Number, Ipopt::Index,
                             const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    iterations_ = int(iter);
    if (progress_) progress_(int(iter), obj_value, inf_du);
    return !stalled(mode, obj_value);
  }
  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index n, const Ipopt::Number* x,
                         const Ipopt::Number*, const Ipopt::Number*, Ipopt::Index,
                         const Ipopt::Number*, const Ipopt::Number*, Ipopt::Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    final_ = Eigen::Map<const Eigen::VectorXd>(x, n);
  }

  const Eigen::VectorXd& final_point() const { return final_; }
  bool stopped_stalled() const { return stall_count_ >= settings_.stall_iterations && stall_on(); }
  int evaluations() const { return evaluations_; }
  int iterations() const { return iterations_; }
  double evaluation_seconds() const { return eval_seconds_; }

 private:
  bool stall_on() const { return settings_.stall_iterations > 0; }

  /// IpoptSettings' stall rule: true once the objective's relative change per regular
  /// iteration has stayed below stall_change stall_iterations times in a row.
  bool stalled(Ipopt::AlgorithmMode mode, double objective) {
    if (!stall_on() || mode != Ipopt::RegularMode) return false;
    if (has_objective_ && std::abs(objective - last_objective_) <=
                              settings_.stall_change * std::max(std::abs(objective), 1e-300))
      ++stall_count_;
    else
      stall_count_ = 0;
    has_objective_ = true;
    last_objective_ = objective;
    return stall_count_ >= settings_.stall_iterations;
  }

  /// f, grad f (and the Hessian) at x, cached: Ipopt asks for them at the same point.
  bool evaluate(Ipopt::Index n, const Ipopt::Number* x) {
    const Eigen::Map<const Eigen::VectorXd> p(x, n);
    if (has_last_ && p == last_p_) return last_ok_;
    const Timer t0;
    last_p_ = p;
    has_last_ = true;
    try {
      last_ = f_(last_p_);
      last_ok_ = std::isfinite(last_.value) && last_.gradient.allFinite();
    } catch (const std::runtime_error&) {
      last_ok_ = false;  // K not positive definite: Ipopt shortens the step
    }
    ++evaluations_;
    eval_seconds_ += t0.seconds();
    return last_ok_;
  }

  const NlpFunction& f_;
  Eigen::VectorXd start_, lower_, upper_, final_, last_p_;
  HessianKind hessian_;
  IpoptSettings settings_;
  bool has_objective_ = false;
  double last_objective_ = 0;
  int stall_count_ = 0;
  Progress progress_;
  NlpValues last_;
  bool has_last_ = false, last_ok_ = false;
  int evaluations_ = 0, iterations_ = 0;
  double eval_seconds_ = 0;
};

}  // namespace

NlpRun run_bounded_nlp(const NlpFunction& f, const Eigen::VectorXd& start, HessianKind hessian,
                       const IpoptSettings& settings, const Progress& progress,
                       double objective_scaling) {
  const Eigen::Index n = start.size();
  return run_bounded_nlp(f, start, Eigen::VectorXd::Constant(n, std::log(settings.lower_scale)),
                         Eigen::VectorXd::Constant(n, std::log(settings.upper_scale)), hessian,
                         settings, progress, objective_scaling);
}

NlpRun run_bounded_nlp(const NlpFunction& f, const Eigen::VectorXd& start,
                       const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                       HessianKind hessian, const IpoptSettings& settings, const Progress& progress,
                       double objective_scaling) {
  NlpRun out;
  Ipopt::SmartPtr<BoundedNlp> nlp =
      new BoundedNlp(f, start, lower, upper, hessian, settings, progress);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetStringValue("hessian_approximation",
                                 hessian == HessianKind::dense ? "exact" : "limited-memory");
  app->Options()->SetIntegerValue("max_iter", settings.max_iterations);
  app->Options()->SetNumericValue("tol", settings.tolerance);
  app->Options()->SetNumericValue("acceptable_tol", settings.acceptable_tolerance);
  app->Options()->SetIntegerValue("acceptable_iter", settings.acceptable_iterations);
  app->Options()->SetIntegerValue("print_level", settings.print_level);
  app->Options()->SetNumericValue("obj_scaling_factor", objective_scaling);
  app->Options()->SetStringValue("sb", "yes");  // no banner
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  // BFGS's initial scaling from the last step's curvature (scalar2), not sᵀy/sᵀs (scalar1): on the
  // per-spring test problem 223 iterations and 250 evaluations instead of 294 and 1,195 (line
  // searches backtracked 4x per iteration).
  if (hessian == HessianKind::limited_memory)
    app->Options()->SetStringValue("limited_memory_initialization", "scalar2");
  std::istringstream no_option_file;  // never read ./ipopt.opt: runs must not depend on the folder
  if (app->Initialize(no_option_file) != Ipopt::Solve_Succeeded) {
    out.status = "Ipopt_Initialisation_Failed";
    return out;
  }
  const Ipopt::ApplicationReturnStatus st = app->OptimizeTNLP(nlp);
  out.status = status_name(st);
  out.success = st == Ipopt::Solve_Succeeded || st == Ipopt::Solved_To_Acceptable_Level;
  if (st == Ipopt::User_Requested_Stop && nlp->stopped_stalled()) {
    out.status = "Objective_Stalled";
    out.success = true;
  }
  out.iterations = nlp->iterations();
  out.evaluations = nlp->evaluations();
  out.evaluation_seconds = nlp->evaluation_seconds();
  out.final_point = nlp->final_point();
  return out;
}

}  // namespace spinesim::calibration::detail
