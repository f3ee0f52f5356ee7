#include "hybridcont/start_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "hybridcont/setup_evaluation.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {

namespace {

// At most this many entries of one block are named in a line; the rest are counted.
constexpr int kNamedEntries = 4;

}  // namespace

double SingularStartTolerance(const Vector& u) { return 1e-8 * (1.0 + (u.size() ? u.lpNorm<Eigen::Infinity>() : 0.0)); }

StartResidual ExplainStartResidual(const HybridModel& model, const StartSpec& start,
                                   const IntegratorOptions& integrator, const Vector* at) {
  StartResidual out;
  out.u = at != nullptr ? *at : StartPoint(model, start);
  const ShootingLayout layout(model);
  const std::vector<std::string>& names = layout.unknown_names();
  for (int i = 0; i < layout.num_unknowns(); ++i) {
    const std::string& name = names[i];
    if (i >= layout.xi_index(0) && i < layout.xi_index(0) + layout.num_first_integrals()) continue;  // 0 on orbits
    const bool given = std::any_of(start.values.begin(), start.values.end(),
                                   [&](const auto& v) { return v.first == name; });
    if (!given && at == nullptr) out.unset.push_back(name);
  }
  TimeBasedShooting shooting(model, integrator);
  shooting.set_threads(1);
  const EvaluationStatus status = shooting.Evaluate(out.u, &out.r, nullptr);
  if (!status.ok) {
    out.message = status.message;
    out.max_residual = std::numeric_limits<double>::infinity();
    out.r.resize(0);
    return out;
  }
  out.evaluated = true;
  out.max_residual = out.r.size() ? out.r.lpNorm<Eigen::Infinity>() : 0.0;
  const int segments = layout.num_segments();
  const int m = segments - 1;
  for (int i = 0; i < segments; ++i) {
    const int next = (i + 1) % segments;
    const Phase& phase = model.phase(i);
    const Phase& next_phase = model.phase(next);
    std::string line = fmt::format("segment {} (phase '{}', t{} = {:.6g})", i + 1, phase.name(), i + 1,
                                   out.u(layout.time_index(i)));
    line += i < m ? fmt::format(": at its end, after the reset into segment {},", next + 1)
                  : ": at its end (the return to the section),";
    std::vector<std::pair<std::string, double>> entries;
    const int row = layout.block_row(i);
    for (int c = 0; c < next_phase.dim(); ++c) {
      entries.push_back({fmt::format("x{}_{}", next + 1, next_phase.state_names()[c]), out.r(row + c)});
    }
    entries.push_back({i < m ? "event" : "anchor", out.r(row + next_phase.dim())});
    out.block_lines_.push_back(line);
    out.block_entries_.push_back(std::move(entries));
  }
  for (int j = 0; j < layout.num_first_integrals(); ++j) {
    const std::string level = j == 0 ? names[layout.H_index()] : fmt::format("H{}", j + 1);
    out.block_lines_.push_back(j == 0 ? fmt::format("the first integral at x1 differs from the level {} by", level)
                                      : fmt::format("first integral {} at x1 differs from its level {} by", j + 1, level));
    out.block_entries_.push_back({{"value", out.r(layout.first_integral_row() + j)}});
  }
  return out;
}

std::string StartResidual::Explain(double tolerance) const {
  std::string text;
  if (!evaluated) {
    text += "  the cycle cannot be integrated from it: " + message + "\n";
  } else {
    for (std::size_t b = 0; b < block_lines_.size(); ++b) {
      std::vector<std::pair<std::string, double>> off;
      for (const auto& entry : block_entries_[b]) {
        if (!(std::abs(entry.second) <= tolerance)) off.push_back(entry);
      }
      if (off.empty()) continue;
      std::stable_sort(off.begin(), off.end(),
                       [](const auto& a, const auto& c) { return std::abs(a.second) > std::abs(c.second); });
      std::string parts;
      for (std::size_t k = 0; k < off.size() && k < static_cast<std::size_t>(kNamedEntries); ++k) {
        const auto& [name, value] = off[k];
        if (!parts.empty()) parts += ",";
        if (name == "event") parts += fmt::format(" its event is {:.3g} (0 on an orbit)", value);
        else if (name == "anchor") parts += fmt::format(" the anchor is {:.3g} (0 on an orbit)", value);
        else if (name == "value") parts += fmt::format(" {:.3g}", value);
        else parts += fmt::format(" {} is off by {:.3g}", name, value);
      }
      if (off.size() > static_cast<std::size_t>(kNamedEntries)) {
        parts += fmt::format(" and {} more", off.size() - kNamedEntries);
      }
      text += "  " + block_lines_[b] + parts + "\n";
    }
  }
  if (!text.empty() && !unset.empty()) {
    std::string list;
    for (const std::string& name : unset) list += (list.empty() ? "" : ", ") + name;
    text += "  not given (taken as 0): " + list + "\n";
  }
  return text;
}

}  // namespace hybridcont
