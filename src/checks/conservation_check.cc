#include "hybridcont/conservation_check.h"

#include <cmath>
#include <sstream>

namespace hybridcont {
namespace {

std::string FormatState(const Phase& phase, const Vector& x) {
  std::ostringstream os;
  os.precision(6);
  os << "(";
  for (int k = 0; k < x.size(); ++k) os << (k ? ", " : "") << phase.state_names()[k] << " = " << x(k);
  os << ")";
  return os.str();
}

// x moved onto e(x) = 0 along ∇e (Newton); false if it does not converge.
bool ProjectOnGuard(const Phase& phase, Vector* x) {
  for (int it = 0; it < 30; ++it) {
    RowVector de;
    const double e = phase.Event(*x, &de);
    if (!std::isfinite(e) || !de.allFinite()) return false;
    const double scale = 1.0 + x->norm();
    if (std::abs(e) <= 1e-14 * scale) return true;
    const double n2 = de.squaredNorm();
    if (!(n2 > 0.0)) return false;
    *x -= (e / n2) * de.transpose();
  }
  return false;
}

void Record(ConservationEntry* entry, double measure, const std::string& where) {
  ++entry->num_states;
  if (!std::isfinite(measure)) return;  // the model is not defined there: the integrator reports it
  if (measure > entry->worst) {
    entry->worst = measure;
    entry->worst_state = where;
  }
}

}  // namespace

bool ConservationReport::passed() const { return FirstFailure().empty(); }

std::string ConservationReport::FirstFailure() const {
  for (const ConservationEntry& e : entries) {
    if (!e.passed(kTolerance)) {
      std::ostringstream os;
      os.precision(3);
      os << e.what << ": violated by " << e.worst << " (relative; tolerance " << kTolerance << ") at "
         << e.worst_state;
      return os.str();
    }
  }
  return "";
}

ConservationReport CheckConservation(const HybridModel& model, const std::vector<std::vector<Vector>>& states) {
  ConservationReport report;
  const int m = model.num_phases();
  for (int i = 0; i < m; ++i) {
    const Phase& phase = model.phase(i);
    const Phase& next = model.phase((i + 1) % m);
    std::vector<Vector> xs = i < static_cast<int>(states.size()) ? states[i] : std::vector<Vector>{};
    if (xs.empty()) xs.push_back(phase.typical_state());
    const int k = phase.num_first_integrals();
    for (int j = 0; j < k; ++j) {
      // (std::string(...).append: GCC 12 warns, a false positive, on "literal" + std::string&&)
      const std::string h = k == 1 ? std::string("H") : std::string("H").append(std::to_string(j + 1));
      ConservationEntry flow, reset;
      flow.what = "phase '" + phase.name() + "': " + h + " kept by the flow (|∇H·f| / |∇H||f|)";
      reset.what = "reset '" + phase.name() + "' -> '" + next.name() + "': " + h +
                   " kept (|ΔH| / (|H| + |∇H||x|), on the guard)";
      for (const Vector& x0 : xs) {
        Vector f, H;
        Matrix dH;
        phase.VectorField(x0, &f, nullptr);
        phase.FirstIntegrals(x0, &H, &dH, nullptr);
        const double scale = dH.row(j).norm() * f.norm();
        Record(&flow, scale > 0.0 ? std::abs(dH.row(j).dot(f)) / scale : 0.0, FormatState(phase, x0));
        Vector x = x0;
        if (!ProjectOnGuard(phase, &x)) continue;
        Vector x_next, H_next;
        phase.Reset(x, &x_next, nullptr);
        phase.FirstIntegrals(x, &H, &dH, nullptr);
        next.FirstIntegrals(x_next, &H_next, nullptr, nullptr);
        const double size = std::abs(H(j)) + dH.row(j).norm() * x.norm();
        Record(&reset, size > 0.0 ? std::abs(H_next(j) - H(j)) / size : 0.0, FormatState(phase, x));
      }
      report.entries.push_back(flow);
      report.entries.push_back(reset);
    }
  }
  return report;
}

}  // namespace hybridcont
