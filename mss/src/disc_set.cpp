#include "spinesim/mss/disc_set.hpp"
#include "spinesim/mss/simulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::mss {

struct DiscSet::Impl {
  struct Disc {
    std::unique_ptr<MssModel> model;  // stable address: the Simulator keeps a reference
    std::unique_ptr<Simulator> sim;
    State state;
  };
  int threads = 1;
  std::vector<Disc> discs;
  std::vector<StepReport> reports;
};

DiscSet::DiscSet(int threads) : impl_(std::make_unique<Impl>()) {
  if (threads < 1) throw std::invalid_argument("DiscSet: threads must be >= 1");
  impl_->threads = threads;
}
DiscSet::~DiscSet() = default;
DiscSet::DiscSet(DiscSet&&) noexcept = default;
DiscSet& DiscSet::operator=(DiscSet&&) noexcept = default;

int DiscSet::add(MssModel model, const DynamicsOptions& options) {
  Impl::Disc d;
  d.model = std::make_unique<MssModel>(std::move(model));
  d.sim = std::make_unique<Simulator>(*d.model, options);
  d.state = d.sim->rest_state();
  impl_->discs.push_back(std::move(d));
  impl_->reports.resize(impl_->discs.size());
  return size() - 1;
}

int DiscSet::size() const { return static_cast<int>(impl_->discs.size()); }
int DiscSet::threads() const { return impl_->threads; }
const MssModel& DiscSet::model(int i) const { return *impl_->discs.at(std::size_t(i)).model; }
const State& DiscSet::state(int i) const { return impl_->discs.at(std::size_t(i)).state; }

void DiscSet::set_state(int i, State state) {
  Impl::Disc& d = impl_->discs.at(std::size_t(i));
  if (state.x_mm.size() != d.model->num_dofs() || state.v_mm_s.size() != d.model->num_dofs())
    throw std::invalid_argument("DiscSet: disc " + std::to_string(i) + ": a state of " +
                                std::to_string(state.x_mm.size()) + " positions for " +
                                std::to_string(d.model->num_dofs()) + " degrees of freedom");
  if (!state.x_mm.allFinite() || !state.v_mm_s.allFinite() || !std::isfinite(state.time_s))
    throw std::invalid_argument("DiscSet: disc " + std::to_string(i) + ": non-finite state");
  d.state = std::move(state);
}

double DiscSet::total_tets() const {
  double n = 0;
  for (const auto& d : impl_->discs) n += double(d.model->mesh().num_tets());
  return n;
}

const std::vector<StepReport>& DiscSet::step(const std::vector<Boundary>& bcs) {
  if (bcs.size() != impl_->discs.size())
    throw std::invalid_argument("DiscSet: " + std::to_string(bcs.size()) + " boundaries for " +
                                std::to_string(impl_->discs.size()) + " discs");
  for_each([&](int i) {
    Impl::Disc& d = impl_->discs[std::size_t(i)];
    impl_->reports[std::size_t(i)] = d.sim->step(d.state, bcs[std::size_t(i)]);
  });
  return impl_->reports;
}

void DiscSet::for_each(const std::function<void(int)>& work) const {
  const int n = size();
#if defined(_OPENMP)
  if (impl_->threads > 1) {
    // Exceptions must not leave an OpenMP region: catch per disc, rethrow the first after it.
    std::vector<std::string> errors(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(dynamic) num_threads(impl_->threads)
    for (int i = 0; i < n; ++i) {
      try {
        work(i);
      } catch (const std::exception& e) {
        errors[std::size_t(i)] = e.what();
      }
    }
    for (const auto& e : errors)
      if (!e.empty()) throw std::runtime_error(e);
    return;
  }
#endif
  for (int i = 0; i < n; ++i) work(i);
}

}  // namespace spinesim::mss
