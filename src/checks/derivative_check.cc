#include "hybridcont/derivative_check.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <random>
#include <sstream>
#include <stdexcept>

#include "hybridcont/orbit_observables.h"
#include "hybridcont/timebased_shooting.h"

#include "hybridcont/internal/options_check.h"

namespace hybridcont {

std::string DerivativeCheckOptions::Validate() const {
  const internal::OptionsCheck check = internal::OptionsCheck("DerivativeCheckOptions")
                                            .AtLeast("num_points", num_points, 1)
                                            .Require(model_step > 0.0, "model_step", model_step, "must be > 0")
                                            .Require(flow_step > 0.0, "flow_step", flow_step, "must be > 0")
                                            .Require(max_duration >= 0.0, "max_duration", max_duration, "must be >= 0");
  return check.failed() ? check.message() : integrator.Validate();
}

bool DerivativeCheckReport::passed() const {
  for (const auto& e : entries) {
    if (!e.passed()) return false;
  }
  return true;
}

std::string DerivativeCheckReport::Table() const {
  std::ostringstream os;
  os << "derivative check of model '" << model << "' (relative error vs central finite differences)\n";
  size_t width = 44;
  for (const auto& e : entries) width = std::max(width, e.what.size() + 2);
  const int w = static_cast<int>(width);
  os << std::left << std::setw(w) << "derivative" << std::right << std::setw(12) << "worst error" << std::setw(12)
     << "threshold" << "  verdict\n";
  for (const auto& e : entries) {
    os << std::left << std::setw(w) << e.what << std::right << std::scientific << std::setprecision(2)
       << std::setw(12) << e.worst_error << std::setw(12) << e.tolerance << "  " << (e.passed() ? "ok" : "FAIL");
    if (!e.note.empty()) os << " (" << e.note << ")";
    if (e.redrawn_unintegrable > 0) os << " (" << e.redrawn_unintegrable << " drawn again: not integrable there)";
    if (e.redrawn_not_differentiable > 0) {
      os << " (" << e.redrawn_not_differentiable << " drawn again: not differentiable there)";
    }
    os << "\n";
  }
  os << (passed() ? "all derivatives agree with finite differences\n" : "SOME DERIVATIVES DISAGREE\n");
  return os.str();
}

namespace {

double RelativeError(const Matrix& exact, const Matrix& fd) {
  const double scale = std::max(exact.cwiseAbs().maxCoeff(), 1e-8);
  return (exact - fd).cwiseAbs().maxCoeff() / scale;
}

// Central differences of a vector function g at x along each coordinate (steps h (1 + |x_j|)).
Matrix FiniteDifferenceJacobian(const std::function<bool(const Vector&, Vector*)>& g, const Vector& x, double h,
                                bool* ok) {
  Vector plus, minus;
  Matrix J;
  for (int j = 0; j < x.size(); ++j) {
    const double step = h * (1.0 + std::abs(x(j)));
    Vector xp = x, xm = x;
    xp(j) += step;
    xm(j) -= step;
    if (!g(xp, &plus) || !g(xm, &minus)) {
      *ok = false;
      return J;
    }
    if (j == 0) J.resize(plus.size(), x.size());
    J.col(j) = (plus - minus) / (2.0 * step);
  }
  *ok = true;
  return J;
}

class Checker {
 public:
  // Draws per point where the integration fails (or, for observables, the value is not differentiable)
  // before an entry gives up: enough that a domain covering most of the sampled box is always hit.
  static constexpr int kRedraws = 4;

  Checker(const HybridModel& model, const DerivativeCheckOptions& o) : model_(model), o_(o), rng_(o.seed) {}

  DerivativeCheckReport Run() {
    report_.model = model_.name();
    for (int p = 0; p < model_.num_phases(); ++p) CheckPhase(model_.phase(p));
    CheckAnchor();
    CheckShootingMap();
    CheckParameterColumns();
    CheckObservables();
    return report_;
  }

 private:
  double Uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }

  Vector SampleState(const Phase& phase) {
    Vector x = phase.typical_state();
    for (int i = 0; i < x.size(); ++i) x(i) += 0.1 * (1.0 + std::abs(x(i))) * Uniform(-1.0, 1.0);
    return x;
  }

  DerivativeCheckEntry& Entry(const std::string& what, double tolerance) {
    for (auto& e : report_.entries) {
      if (e.what == what) return e;
    }
    report_.entries.push_back({what, 0.0, tolerance, ""});
    return report_.entries.back();
  }

  void Record(const std::string& what, double tolerance, const Matrix& exact, const Matrix& fd, bool ok,
              const std::string& failure = "finite-difference evaluation failed") {
    DerivativeCheckEntry& e = Entry(what, tolerance);
    if (!ok) {
      e.note = failure;
      return;
    }
    e.worst_error = std::max(e.worst_error, RelativeError(exact, fd));
  }

  void CheckPhase(const Phase& phase) {
    const std::string tag = "phase '" + phase.name() + "': ";
    const int k = phase.num_first_integrals();
    PhaseFlow flow(phase, o_.integrator);
    for (int point = 0; point < o_.num_points; ++point) {
      const Vector x = SampleState(phase);
      bool ok = false;
      // vector field
      Vector f;
      Matrix df;
      phase.VectorField(x, &f, &df);
      Matrix fd = FiniteDifferenceJacobian([&](const Vector& y, Vector* out) {
        phase.VectorField(y, out, nullptr);
        return out->allFinite();
      }, x, o_.model_step, &ok);
      Record(tag + "df/dx", o_.model_tolerance, df, fd, ok);
      // event
      RowVector de;
      phase.Event(x, &de);
      fd = FiniteDifferenceJacobian([&](const Vector& y, Vector* out) {
        *out = Vector::Constant(1, phase.Event(y, nullptr));
        return out->allFinite();
      }, x, o_.model_step, &ok);
      Record(tag + "de/dx", o_.model_tolerance, de, fd, ok);
      // reset
      Vector xn;
      Matrix D;
      phase.Reset(x, &xn, &D);
      fd = FiniteDifferenceJacobian([&](const Vector& y, Vector* out) {
        phase.Reset(y, out, nullptr);
        return out->allFinite();
      }, x, o_.model_step, &ok);
      Record(tag + "dDelta/dx", o_.model_tolerance, D, fd, ok);
      // first integrals: gradient and Hessians
      Vector H;
      Matrix dH;
      std::vector<Matrix> d2H;
      phase.FirstIntegrals(x, &H, &dH, &d2H);
      fd = FiniteDifferenceJacobian([&](const Vector& y, Vector* out) {
        phase.FirstIntegrals(y, out, nullptr, nullptr);
        return out->allFinite();
      }, x, o_.model_step, &ok);
      if (k > 0) Record(tag + "dH/dx", o_.model_tolerance, dH, fd, ok);  // none without a first integral
      for (int j = 0; j < k; ++j) {
        fd = FiniteDifferenceJacobian([&](const Vector& y, Vector* out) {
          Vector h;
          Matrix g;
          phase.FirstIntegrals(y, &h, &g, nullptr);
          *out = g.row(j).transpose();
          return out->allFinite();
        }, x, o_.model_step, &ok);
        // (std::string(...).append: GCC 12 warns, a false positive, on "literal" + std::string&&)
        const std::string index = k > 1 ? std::string("[").append(std::to_string(j + 1)).append("]") : "";
        Record(tag + "d2H/dx2" + index, o_.model_tolerance, d2H[j], fd, ok);
      }
      // flow sensitivities with xi != 0 and a duration of either sign; a duration and xi for which the flow
      // leaves the model's domain (the unfolded flow of a stiffening spring blows up in finite time) are
      // drawn again: this checks derivatives, not the domain.
      double t = 0;
      Vector xi(k);
      PhaseFlowResult res;
      for (int attempt = 0; attempt < kRedraws; ++attempt) {
        if (attempt > 0) ++Entry(tag + "Phi = dphi/dx0", o_.flow_tolerance).redrawn_unintegrable;
        t = Uniform(-o_.max_duration, o_.max_duration);
        for (int j = 0; j < k; ++j) xi(j) = Uniform(-o_.max_xi, o_.max_xi);
        flow.Integrate(x, xi, t, true, &res);
        if (res.ok()) break;
      }
      if (!res.ok()) {
        Record(tag + "Phi = dphi/dx0", o_.flow_tolerance, Matrix(), Matrix(), false, res.message);
        continue;
      }
      auto integrate = [&](const Vector& x0, const Vector& xi0, Vector* out) {
        PhaseFlowResult r;
        flow.Integrate(x0, xi0, t, false, &r);
        *out = r.x;
        return r.ok();
      };
      fd = FiniteDifferenceJacobian([&](const Vector& y, Vector* out) { return integrate(y, xi, out); }, x,
                                    o_.flow_step, &ok);
      Record(tag + "Phi = dphi/dx0", o_.flow_tolerance, res.Phi, fd, ok);
      fd = FiniteDifferenceJacobian([&](const Vector& z, Vector* out) { return integrate(x, z, out); }, xi,
                                    o_.flow_step, &ok);
      if (k > 0) Record(tag + "Psi = dphi/dxi", o_.flow_tolerance, res.Psi, fd, ok);
    }
  }

  void CheckAnchor() {
    const Phase& phase = model_.phase(0);
    for (int point = 0; point < o_.num_points; ++point) {
      const Vector x = SampleState(phase);
      RowVector da;
      model_.anchor().Evaluate(x, &da);
      bool ok = false;
      const Matrix fd = FiniteDifferenceJacobian([&](const Vector& y, Vector* out) {
        *out = Vector::Constant(1, model_.anchor().Evaluate(y, nullptr));
        return out->allFinite();
      }, x, o_.model_step, &ok);
      Record("anchor: da/dx", o_.model_tolerance, da, fd, ok);
    }
  }

  // A random u of the layout: durations, states near the typical ones, ξ and H̄; free parameters at the
  // model's values.
  Vector SampleUnknowns(const ShootingLayout& layout) {
    Vector u(layout.num_unknowns());
    for (int i = 0; i < layout.num_segments(); ++i) {
      u(layout.time_index(i)) = Uniform(-o_.max_duration, o_.max_duration);
      u.segment(layout.state_offset(i), layout.dim(i)) = SampleState(model_.phase(i));
    }
    for (int j = 0; j < layout.num_first_integrals(); ++j) u(layout.xi_index(j)) = Uniform(-o_.max_xi, o_.max_xi);
    if (layout.has_level()) u(layout.H_index()) = Uniform(0.0, 2.0);
    for (int i = 0; i < layout.num_free_parameters(); ++i) {
      u(layout.parameter_index(i)) = model_.parameter_value(layout.parameter_model_index(i));
    }
    return u;
  }

  // The column of each model parameter in the time-based map with that parameter free (flow sensitivities
  // and the parameter derivatives of resets, events, anchor and first integrals together) against central
  // differences of r in the parameter.
  void CheckParameterColumns() {
    if (!model_.has_parameter_derivatives() || !model_.is_cloneable()) return;
    for (const ParameterInfo& info : model_.parameters()) {
      const std::string what = "shooting map: dr/d" + info.name;
      // The parameter free (and, with a first integral, held by a fixing row; without, it carries the family).
      const FreeParameters free = model_.num_first_integrals() > 0
                                      ? FreeParameters{{info.name}, {{info.name, info.default_value}}, {}}
                                      : FreeParameters{{info.name}, {}, {}};
      TimeBasedShooting shooting(model_, o_.integrator, free);
      const int col = shooting.layout().parameter_index(0);
      // Random points where the map cannot be integrated (a singular state reached) are drawn again: this
      // checks derivatives, not the model's domain (dr/du reports such failures).
      int checked = 0;
      std::string failure;
      for (int attempt = 0; attempt < kRedraws * o_.num_points && checked < o_.num_points; ++attempt) {
        const Vector u = SampleUnknowns(shooting.layout());
        Vector r, r_plus, r_minus;
        Matrix dr;
        const double h = o_.flow_step * std::max(1.0, std::abs(u(col)));
        Vector up = u, um = u;
        up(col) += h;
        um(col) -= h;
        const EvaluationStatus s = shooting.Evaluate(u, &r, &dr);
        const bool ok = s.ok && shooting.Evaluate(up, &r_plus, nullptr).ok && shooting.Evaluate(um, &r_minus, nullptr).ok;
        if (!ok) {
          failure = s.ok ? "finite-difference evaluation failed" : s.message;
          ++Entry(what, o_.flow_tolerance).redrawn_unintegrable;
          continue;
        }
        // Relative to the map's sensitivity to relative changes of its unknowns, not to the column alone: a
        // parameter derivative that is exactly zero (a parameter that cancels) is compared with differences
        // that are integration noise, which the column's own size (zero) cannot judge.
        double sensitivity = 0.0;
        for (int j = 0; j < dr.cols(); ++j) {
          if (j != col) sensitivity = std::max(sensitivity, dr.col(j).cwiseAbs().maxCoeff() * std::max(1.0, std::abs(u(j))));
        }
        const double p_scale = std::max(1.0, std::abs(u(col)));
        const Vector exact = dr.col(col) * p_scale, fd = (r_plus - r_minus) / (2 * h) * p_scale;
        const double scale = std::max({exact.cwiseAbs().maxCoeff(), sensitivity, 1e-8});
        DerivativeCheckEntry& e = Entry(what, o_.flow_tolerance);
        e.worst_error = std::max(e.worst_error, (exact - fd).cwiseAbs().maxCoeff() / scale);
        ++checked;
      }
      if (checked == 0) Record(what, o_.flow_tolerance, Matrix(), Matrix(), false, failure);
    }
  }

  // Each observable's gradient in u (orbit_observables.h) against central differences of its value, at
  // random u where it evaluates (an integration that fails at a drawn point is drawn again).
  void CheckObservables() {
    const ShootingLayout layout(model_);
    ObservableEvaluator evaluator(model_, layout, o_.integrator);
    for (int j = 0; j < static_cast<int>(model_.observables().size()); ++j) {
      const std::string what = "observable '" + model_.observables()[j].name + "': d/du";
      int checked = 0;
      std::string failure;
      for (int attempt = 0; attempt < kRedraws * o_.num_points && checked < o_.num_points; ++attempt) {
        const Vector u = SampleUnknowns(layout);
        double value = 0.0;
        RowVector du;
        const EvaluationStatus s = evaluator.Evaluate(j, u, &value, &du);
        if (!s.ok) {
          failure = s.message;
          ++Entry(what, o_.flow_tolerance).redrawn_unintegrable;
          continue;
        }
        const auto value_at = [&](const Vector& v, Vector* out) {
          out->resize(1);
          return evaluator.Evaluate(j, v, &(*out)(0), nullptr).ok;
        };
        bool ok = false, ok_half = false;
        const Matrix fd = FiniteDifferenceJacobian(value_at, u, o_.flow_step, &ok);
        const Matrix fd_half = ok ? FiniteDifferenceJacobian(value_at, u, 0.5 * o_.flow_step, &ok_half) : Matrix();
        if (!ok || !ok_half) {
          ++Entry(what, o_.flow_tolerance).redrawn_unintegrable;
          continue;
        }
        // Differences at two steps that disagree: a kink or jump inside the stencil (a minimum over a phase
        // changing its place, a competing guard arming where a phase begins on it), not a derivative error.
        if (RelativeError(fd, fd_half) > o_.flow_tolerance) {
          ++Entry(what, o_.flow_tolerance).redrawn_not_differentiable;
          continue;
        }
        // Compared with the Richardson extrapolation of the two, (4 fd_half − fd) / 3: the h² error of
        // central differences cancels (a mean over a phase, an integral over a short period: the curvature
        // of the value put fd itself 1e-5 off at one drawn point of the swing-leg biped).
        Record(what, o_.flow_tolerance, du, (4 * fd_half - fd) / 3, true);
        ++checked;
      }
      if (checked == 0) Record(what, o_.flow_tolerance, Matrix(), Matrix(), false, failure);
    }
  }

  // dr/du at random u; a u where the map cannot be integrated is drawn again (as for the parameter columns),
  // and the entry fails for it only when no drawn u could be.
  void CheckShootingMap() {
    TimeBasedShooting shooting(model_, o_.integrator);
    const ShootingLayout& layout = shooting.layout();
    const std::string what = "shooting map: dr/du";
    int checked = 0;
    std::string failure;
    for (int attempt = 0; attempt < kRedraws * o_.num_points && checked < o_.num_points; ++attempt) {
      const Vector u = SampleUnknowns(layout);
      Vector r;
      Matrix dr;
      const EvaluationStatus s = shooting.Evaluate(u, &r, &dr);
      if (!s.ok) {
        failure = s.message;
        ++Entry(what, o_.flow_tolerance).redrawn_unintegrable;
        continue;
      }
      ++checked;
      bool ok = false;
      const Matrix fd = FiniteDifferenceJacobian([&](const Vector& v, Vector* out) {
        return shooting.Evaluate(v, out, nullptr).ok;
      }, u, o_.flow_step, &ok);
      Record(what, o_.flow_tolerance, dr, fd, ok);
      CheckSymmetries(&shooting, u, r, dr);
    }
    if (checked == 0) Record(what, o_.flow_tolerance, Matrix(), Matrix(), false, failure);
  }

  // A declared symmetry S maps r to ±r componentwise (r(S u) = T r(u), T a sign matrix) and dr to
  // dr(S u) S = T dr(u): compared as |r(S u)| against |r(u)| and |dr(S u) S| against |dr(u)|, relative
  // to the largest entry. Exact in exact arithmetic; a wrong sign in a declaration gives O(1) errors.
  void CheckSymmetries(TimeBasedShooting* shooting, const Vector& u, const Vector& r, const Matrix& dr) {
    for (const Symmetry& g : shooting->symmetries()) {
      const std::string what = "symmetry '" + g.name + "': |r(Su)|, |dr(Su) S| vs |r(u)|, |dr(u)|";
      Vector r_image;
      Matrix dr_image;
      const EvaluationStatus s = shooting->Evaluate(g.Apply(u), &r_image, &dr_image);
      if (!s.ok) {
        Record(what, o_.flow_tolerance, Matrix(), Matrix(), false, s.message);
        continue;
      }
      Matrix exact(r.size(), dr.cols() + 1), image(r.size(), dr.cols() + 1);
      exact << dr.cwiseAbs(), r.cwiseAbs();
      image << (dr_image * g.signs.asDiagonal()).cwiseAbs(), r_image.cwiseAbs();
      Record(what, o_.flow_tolerance, exact, image, true);
    }
  }

  const HybridModel& model_;
  const DerivativeCheckOptions& o_;
  std::mt19937_64 rng_;
  DerivativeCheckReport report_;
};

}  // namespace

DerivativeCheckReport CheckDerivatives(const HybridModel& model, const DerivativeCheckOptions& options) {
  if (const std::string why = options.Validate(); !why.empty()) throw std::invalid_argument(why);
  return Checker(model, options).Run();
}

}  // namespace hybridcont
