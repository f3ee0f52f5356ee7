#include "hybridcont/orbit_trace.h"

#include <cmath>

namespace hybridcont {

OrbitTrace::OrbitTrace(const HybridModel& model, const Vector& u, const IntegratorOptions& options) {
  const ShootingLayout layout(model);
  const int k = layout.num_first_integrals();
  const Vector xi = u.segment(layout.xi_index(), k);
  segments_.resize(layout.num_segments());
  durations_.resize(layout.num_segments());
  for (int i = 0; i < layout.num_segments(); ++i) {
    const Phase& phase = model.phase(i);
    PhaseFlow flow(phase, options);
    durations_[i] = u(layout.time_index(i));
    std::vector<TraceNode>& nodes = segments_[i];
    PhaseFlowResult result;
    flow.Integrate(u.segment(layout.state_offset(i), layout.dim(i)), xi, durations_[i], false, &result,
                   [&](double t, const Eigen::Ref<const Vector>& x) {
                     TraceNode node{t, x, Vector()};
                     phase.UnfoldedVectorField(x, xi, &node.f, nullptr, nullptr);
                     nodes.push_back(std::move(node));
                   });
    if (!result.ok()) {
      message_ = "segment " + std::to_string(i + 1) + ": " + result.message;
      return;
    }
  }
}

Vector OrbitTrace::Interpolate(int i, int j, double t) const {
  const TraceNode& a = segments_[i][j];
  const TraceNode& b = segments_[i][j + 1];
  const double h = b.t - a.t;
  const double s = (t - a.t) / h;
  const double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s);
  const double h01 = s * s * (3 - 2 * s), h11 = s * s * (s - 1);
  return h00 * a.x + h10 * h * a.f + h01 * b.x + h11 * h * b.f;
}

std::vector<OrbitSample> OrbitTrace::Sample(int num_samples) const {
  std::vector<OrbitSample> samples;
  double total = 0.0;
  for (double d : durations_) total += std::abs(d);
  const double dt = total > 0.0 ? total / std::max(num_samples, 1) : 1.0;
  double offset = 0.0;
  for (int i = 0; i < num_segments(); ++i) {
    const std::vector<TraceNode>& nodes = segments_[i];
    samples.push_back({offset, i, nodes.front().x});
    const double d = durations_[i];
    const int count = static_cast<int>(std::floor(std::abs(d) / dt));
    std::size_t j = 0;
    for (int c = 1; c <= count; ++c) {
      const double t = std::copysign(c * dt, d);
      if (std::abs(t) >= std::abs(d)) break;
      while (j + 2 < nodes.size() && std::abs(nodes[j + 1].t) < std::abs(t)) ++j;
      samples.push_back({offset + std::abs(t), i, Interpolate(i, static_cast<int>(j), t)});
    }
    if (nodes.size() > 1) samples.push_back({offset + std::abs(d), i, nodes.back().x});
    offset += std::abs(d);
  }
  return samples;
}

}  // namespace hybridcont
