#include "hybridcont/event_flow.h"
#include "hybridcont/orbit_observables.h"

#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <limits>
#include <string>

#include "hybridcont/invariant.h"

namespace hybridcont {

namespace {

// The phase with the quadrature state q' = g(x) appended: x_aug = [x; q]. Its first integrals, event and
// reset are the phase's, blind to q, so that the unfolded field is [f + ξ∇H; g] and the flow's
// sensitivities carry dq/d(x0, ξ, p).
class QuadraturePhase : public Phase {
 public:
  QuadraturePhase(const Phase& base, const SmoothFunction& g, const HybridModel& model)
      : Phase(base.name(), Names(base), base.next_dim(), base.num_first_integrals(), Typical(base)),
        base_(&base),
        g_(&g),
        model_(&model) {}

  void VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const override {
    const int n = base_->dim();
    thread_local Vector fb;
    thread_local Matrix dfb;
    base_->VectorField(x.head(n), &fb, df ? &dfb : nullptr);
    Assemble(x, fb, df ? &dfb : nullptr, f, df);
  }
  void FirstIntegrals(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH, std::vector<Matrix>* d2H) const override {
    const int n = base_->dim();
    Matrix dHb;
    std::vector<Matrix> d2Hb;
    base_->FirstIntegrals(x.head(n), H, dH ? &dHb : nullptr, d2H ? &d2Hb : nullptr);
    if (dH) {
      dH->setZero(dHb.rows(), n + 1);
      dH->leftCols(n) = dHb;
    }
    if (d2H) {
      d2H->resize(d2Hb.size());
      for (std::size_t j = 0; j < d2Hb.size(); ++j) {
        (*d2H)[j].setZero(n + 1, n + 1);
        (*d2H)[j].topLeftCorner(n, n) = d2Hb[j];
      }
    }
  }
  double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const override {
    const int n = base_->dim();
    RowVector deb;
    const double e = base_->Event(x.head(n), de ? &deb : nullptr);
    if (de) {
      de->setZero(n + 1);
      de->head(n) = deb;
    }
    return e;
  }
  void Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const override {
    const int n = base_->dim();
    Matrix Db;
    base_->Reset(x.head(n), x_next, D ? &Db : nullptr);
    if (D) {
      D->setZero(Db.rows(), n + 1);
      D->leftCols(n) = Db;
    }
  }
  bool has_parameter_derivatives() const override { return base_->has_parameter_derivatives(); }
  void ParameterDerivatives(const Eigen::Ref<const Vector>& x, int parameter, Vector* field, Vector* integrals,
                            double* event, Vector* reset) const override {
    const int n = base_->dim();
    Vector fb;
    base_->ParameterDerivatives(x.head(n), parameter, field ? &fb : nullptr, integrals, event, reset);
    if (field) {
      field->resize(n + 1);
      field->head(n) = fb;
      (*field)(n) = ParameterDerivativeOfG(x.head(n), parameter);
    }
  }
  void UnfoldedFieldParameterDerivative(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                        int parameter, Vector* dfdp, bool include_mixed_term) const override {
    const int n = base_->dim();
    thread_local Vector fb;
    base_->UnfoldedFieldParameterDerivative(x.head(n), xi, parameter, &fb, include_mixed_term);
    dfdp->resize(n + 1);
    dfdp->head(n) = fb;
    (*dfdp)(n) = ParameterDerivativeOfG(x.head(n), parameter);
  }

 protected:
  void ComputeUnfoldedVectorField(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                  Vector* f_tilde, Matrix* A, Matrix* B, bool include_hessian_term) const override {
    const int n = base_->dim();
    thread_local Vector fb;
    thread_local Matrix Ab, Bb;
    base_->UnfoldedVectorField(x.head(n), xi, &fb, A ? &Ab : nullptr, B ? &Bb : nullptr, include_hessian_term);
    Assemble(x, fb, A ? &Ab : nullptr, f_tilde, A);
    if (B) {
      B->setZero(n + 1, Bb.cols());
      B->topRows(n) = Bb;
    }
  }

 private:
  static std::vector<std::string> Names(const Phase& base) {
    std::vector<std::string> names = base.state_names();
    names.push_back("quadrature");
    return names;
  }
  static Vector Typical(const Phase& base) {
    Vector x = Vector::Zero(base.dim() + 1);
    x.head(base.dim()) = base.typical_state();
    return x;
  }
  Vector Parameters() const {
    Vector p(model_->parameters().size());
    for (int i = 0; i < p.size(); ++i) p(i) = model_->parameter_value(i);
    return p;
  }
  double ParameterDerivativeOfG(const Eigen::Ref<const Vector>& x, int parameter) const {
    RowVector dp;
    g_->Evaluate(x, Parameters(), nullptr, &dp);
    return dp(parameter);
  }
  // [fb; g(x)] and, with dfb, [[dfb, 0]; [∇g, 0]].
  void Assemble(const Eigen::Ref<const Vector>& x, const Vector& fb, const Matrix* dfb, Vector* f, Matrix* df) const {
    const int n = base_->dim();
    thread_local RowVector dg;
    const double g = g_->Evaluate(x.head(n), Parameters(), dfb ? &dg : nullptr, nullptr);
    f->resize(n + 1);
    f->head(n) = fb;
    (*f)(n) = g;
    if (dfb && df) {
      df->setZero(n + 1, n + 1);
      df->topLeftCorner(n, n) = *dfb;
      df->row(n).head(n) = dg;
    }
  }

  const Phase* base_;
  const SmoothFunction* g_;
  const HybridModel* model_;
};

}  // namespace

struct ObservableEvaluator::Quadrature {
  std::unique_ptr<QuadraturePhase> phase;
  std::unique_ptr<PhaseFlow> flow;
};

ObservableEvaluator::ObservableEvaluator(const HybridModel& model, const ShootingLayout& layout,
                                         IntegratorOptions options)
    : model_(&model), layout_(layout), options_(options) {
  for (int i = 0; i < layout.num_free_parameters(); ++i) free_parameters_.push_back(layout.parameter_model_index(i));
  for (int i = 0; i < model.num_phases(); ++i) {
    flows_.emplace_back(model.phase(i), options);
    flows_.back().set_free_parameters(free_parameters_);
  }
}

ObservableEvaluator::~ObservableEvaluator() = default;
ObservableEvaluator::ObservableEvaluator(ObservableEvaluator&&) noexcept = default;
ObservableEvaluator& ObservableEvaluator::operator=(ObservableEvaluator&&) noexcept = default;

Vector ObservableEvaluator::Parameters() const {
  Vector p(model_->parameters().size());
  for (int i = 0; i < p.size(); ++i) p(i) = model_->parameter_value(i);
  return p;
}

void ObservableEvaluator::AddParameterGradient(const RowVector& dp, RowVector* du) const {
  for (int j = 0; j < layout_.num_free_parameters(); ++j) {
    (*du)(layout_.parameter_index(j)) += dp(layout_.parameter_model_index(j));
  }
}

EvaluationStatus ObservableEvaluator::Evaluate(int observable, const Vector& u, double* value, RowVector* du) {
  HYBRIDCONT_DEMAND(observable >= 0 && observable < static_cast<int>(model_->observables().size()));
  HYBRIDCONT_DEMAND(u.size() >= layout_.num_orbit_unknowns() + layout_.num_free_parameters());
  const Observable& o = model_->observables()[observable];
  if (du) du->setZero(u.size());
  EvaluationStatus status;
  if (o.kind == ObservableKind::kValue) {
    const int nv = layout_.num_orbit_unknowns();
    RowVector dv, dp;
    *value = o.value->Evaluate(u.head(nv), Parameters(), du ? &dv : nullptr, du ? &dp : nullptr);
    if (du) {
      du->head(nv) = dv;
      AddParameterGradient(dp, du);
    }
  } else if (o.kind == ObservableKind::kIntegral || o.kind == ObservableKind::kMean) {
    status = Integral(o, observable, u, value, du);
  } else if (o.kind == ObservableKind::kFinal) {
    status = Final(o, u, value, du);
  } else {
    status = Extremum(o, u, value, du);
  }
  if (status.ok && !std::isfinite(*value)) {
    status = EvaluationStatus::Failure("observable '" + o.name + "' is not finite");
  }
  if (!status.ok) status.message = "observable '" + o.name + "': " + status.message;
  return status;
}

Vector ObservableEvaluator::EvaluateAll(const Vector& u) {
  const int s = static_cast<int>(model_->observables().size());
  Vector values(s);
  for (int j = 0; j < s; ++j) {
    double v = 0.0;
    values(j) = Evaluate(j, u, &v, nullptr).ok ? v : std::numeric_limits<double>::quiet_NaN();
  }
  return values;
}

EvaluationStatus ObservableEvaluator::Integral(const Observable& o, int observable, const Vector& u, double* value,
                                               RowVector* du) {
  const int m = model_->num_phases();
  const int k = layout_.num_first_integrals();
  const auto xi = u.segment(layout_.xi_index(), k);
  const Vector p = Parameters();
  double integral = 0.0, duration = 0.0;
  RowVector d_duration;
  if (du) d_duration.setZero(u.size());
  PhaseFlowResult res;
  for (int s = 0; s < layout_.num_segments(); ++s) {
    const int i = s % m;
    const SmoothFunction* g = o.phases[i].get();
    if (g == nullptr) continue;
    auto& q = quadratures_[{observable, i}];
    if (!q) {
      q = std::make_unique<Quadrature>();
      q->phase = std::make_unique<QuadraturePhase>(model_->phase(i), *g, *model_);
      q->flow = std::make_unique<PhaseFlow>(*q->phase, options_);
      q->flow->set_free_parameters(free_parameters_);
    }
    const int n = layout_.dim(s);
    const double t = u(layout_.time_index(s));
    Vector z0 = Vector::Zero(n + 1);
    z0.head(n) = u.segment(layout_.state_offset(s), n);
    q->flow->Integrate(z0, xi, t, du != nullptr, &res);
    counters_ += res.counters;
    if (!res.ok()) return EvaluationStatus::Failure(res.message);
    integral += res.x(n);
    duration += t;
    if (du) {
      du->segment(layout_.state_offset(s), n) += res.Phi.row(n).head(n);
      (*du)(layout_.time_index(s)) += g->Evaluate(res.x.head(n), p, nullptr, nullptr);
      if (k > 0) du->segment(layout_.xi_index(), k) += res.Psi.row(n).head(k);
      for (int j = 0; j < layout_.num_free_parameters(); ++j) {
        (*du)(layout_.parameter_index(j)) += res.Psi(n, k + j);
      }
      d_duration(layout_.time_index(s)) = 1.0;
    }
  }
  if (o.kind == ObservableKind::kIntegral) {
    *value = integral;
    return {};
  }
  if (duration == 0.0) return EvaluationStatus::Failure("a mean over phases whose durations sum to 0");
  *value = integral / duration;
  if (du) *du = (*du - *value * d_duration) / duration;
  return {};
}

EvaluationStatus ObservableEvaluator::ValueAt(const SmoothFunction& g, int segment, double t, bool is_end,
                                              const Vector& u, double* value, RowVector* du) {
  const int k = layout_.num_first_integrals();
  const auto xi = u.segment(layout_.xi_index(), k);
  const int i = segment % model_->num_phases();
  const int n = layout_.dim(segment);
  PhaseFlowResult res;
  flows_[i].Integrate(u.segment(layout_.state_offset(segment), n), xi, t, du != nullptr, &res);
  counters_ += res.counters;
  if (!res.ok()) return EvaluationStatus::Failure(res.message);
  RowVector dg, dp;
  *value = g.Evaluate(res.x, Parameters(), du ? &dg : nullptr, du ? &dp : nullptr);
  if (du == nullptr) return {};
  du->segment(layout_.state_offset(segment), n) += dg * res.Phi;
  if (k > 0) du->segment(layout_.xi_index(), k) += dg * res.Psi.leftCols(k);
  for (int j = 0; j < layout_.num_free_parameters(); ++j) (*du)(layout_.parameter_index(j)) += dg.dot(res.Psi.col(k + j));
  AddParameterGradient(dp, du);
  if (is_end && t != 0.0) {  // x(t_s) moves with t_s
    Vector f;
    model_->phase(i).UnfoldedVectorField(res.x, xi, &f, nullptr, nullptr);
    (*du)(layout_.time_index(segment)) += dg.dot(f);
  }
  return {};
}

EvaluationStatus ObservableEvaluator::Final(const Observable& o, const Vector& u, double* value, RowVector* du) {
  int i = 0;
  while (o.phases[i] == nullptr) ++i;
  // Segment i ends with phase i's event (segment m, phase 1 again, ends at the section).
  last_interior_ = false;
  return ValueAt(*o.phases[i], i, u(layout_.time_index(i)), true, u, value, du);
}

EvaluationStatus ObservableEvaluator::EvaluateExtremum(const Observable& o, const Vector& u, double* value,
                                                       RowVector* du) {
  HYBRIDCONT_DEMAND(o.kind == ObservableKind::kMinimum || o.kind == ObservableKind::kMaximum);
  HYBRIDCONT_DEMAND(static_cast<int>(o.phases.size()) == model_->num_phases());
  HYBRIDCONT_DEMAND(u.size() >= layout_.num_orbit_unknowns() + layout_.num_free_parameters());
  if (du) du->setZero(u.size());
  EvaluationStatus status = Extremum(o, u, value, du);
  if (status.ok && !std::isfinite(*value)) status = EvaluationStatus::Failure("not finite");
  if (!status.ok) status.message = "'" + o.name + "': " + status.message;
  return status;
}

namespace {

// e_i(x) of one phase as a smooth function of (x, p).
class PhaseEventFunction : public SmoothFunction {
 public:
  PhaseEventFunction(const HybridModel& model, int phase) : model_(&model), phase_(phase) {}
  double Evaluate(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& p, RowVector* dx,
                  RowVector* dp) const override {
    const Phase& phase = model_->phase(phase_);
    if (dp != nullptr) {
      HYBRIDCONT_DEMAND(phase.has_parameter_derivatives());
      dp->setZero(p.size());
      for (int j = 0; j < p.size(); ++j) phase.ParameterDerivatives(x, j, nullptr, nullptr, &(*dp)(j), nullptr);
    }
    return phase.Event(x, dx);
  }

 private:
  const HybridModel* model_;
  int phase_;
};

}  // namespace

Observable OwnEventObservable(const HybridModel& model, int phase) {
  HYBRIDCONT_DEMAND(phase >= 0 && phase < model.num_phases());
  Observable o;
  o.name = model.phase(phase).name() + "_event";
  o.description = "the event of phase '" + model.phase(phase).name() + "' stays >= 0 until the phase's end";
  o.kind = ObservableKind::kMinimum;
  o.phases.resize(model.num_phases());
  o.phases[phase] = std::make_shared<PhaseEventFunction>(model, phase);
  o.constraint = true;
  o.guard = true;
  return o;
}

namespace {

// A state of a segment's trajectory at time t from the segment's start (t of the duration's sign).
struct ExtremumSample {
  double t;
  Vector x;
};

// h = sign·g along one shooting segment and its derivative along the sequence of the segment's samples,
// dh = sign·ġ·dir (ġ = ∇g·f~; dir: the sign of the segment's duration), with the segment's flow to refine
// between samples. Integrations add their work to `counters` and leave their result in `res`; f and dg are
// scratch.
struct SegmentProfile {
  const SmoothFunction& g;
  const Phase& phase;
  PhaseFlow& flow;
  Eigen::Ref<const Vector> xi;
  const Vector& p;
  double sign;
  double dir;
  PhaseFlowResult& res;
  FlowCounters& counters;
  Vector& f;
  RowVector& dg;

  // h at x, and dh there in *slope.
  double HAndSlope(const Eigen::Ref<const Vector>& x, double* slope) const {
    const double gx = g.Evaluate(x, p, &dg, nullptr);
    phase.UnfoldedVectorField(x, xi, &f, nullptr, nullptr);
    *slope = sign * dir * dg.dot(f);
    return sign * gx;
  }

  // The zero of dh between samples a and a+1, where it changes sign (dh[a] < 0 < dh[a+1]: a local minimum
  // of h; the other way round, a local maximum), located by TOMS 748 on the flow from sample a: its time in
  // *t_star, and h there (+inf where the integration fails).
  double RefineExtremum(const std::vector<ExtremumSample>& samples, const std::vector<double>& dh, int a,
                        double* t_star) const {
    const ExtremumSample& start = samples[a];
    double slope = 0.0;
    Vector x;
    const auto slope_at = [&](double t) {
      flow.Integrate(start.x, xi, t - start.t, false, &res);
      counters += res.counters;
      if (!res.ok()) return std::numeric_limits<double>::quiet_NaN();
      HAndSlope(res.x, &slope);
      return slope;
    };
    std::uintmax_t max_iter = 100;
    const auto tol = [](double lo, double hi) {
      return std::abs(hi - lo) <= 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(lo), std::abs(hi));
    };
    double lo = samples[a].t, hi = samples[a + 1].t;
    double flo = dh[a], fhi = dh[a + 1];
    if (lo > hi) {
      std::swap(lo, hi);
      std::swap(flo, fhi);
    }
    const auto bracket = boost::math::tools::toms748_solve(slope_at, lo, hi, flo, fhi, tol, max_iter);
    *t_star = 0.5 * (bracket.first + bracket.second);
    flow.Integrate(start.x, xi, *t_star - start.t, false, &res);
    counters += res.counters;
    double unused;
    return res.ok() ? HAndSlope(res.x, &unused) : std::numeric_limits<double>::infinity();
  }
};

// A competing guard counts from where it is reached from above (observable.h): per sample j of a segment,
// whether it has been positive by then, the segment beginning armed as armed_at_start says. A bump above 0
// between samples j-1 and j (a foot that barely clears the ground), located on the flow, arms it too.
std::vector<char> GuardArmedSamples(const SegmentProfile& profile, const std::vector<ExtremumSample>& samples,
                                    const std::vector<double>& h, const std::vector<double>& dh, bool armed_at_start) {
  const int ns = static_cast<int>(samples.size());
  std::vector<char> armed(ns, 1);
  bool on = armed_at_start;
  for (int j = 0; j < ns; ++j) {
    const bool below_before = j == 1 ? h[0] <= kGuardStartTolerance : h[j - 1] <= 0.0;
    if (!on && j > 0 && below_before && h[j] <= 0.0 && dh[j - 1] > 0.0 && dh[j] < 0.0) {
      double t_top = 0.0;
      const double top = profile.RefineExtremum(samples, dh, j - 1, &t_top);
      on = std::isfinite(top) && top > 0.0;
    }
    armed[j] = on = on || (j > 0 && h[j] > 0.0);
  }
  return armed;
}

}  // namespace

// Guards: whether segment s begins armed (observable.h). A segment that begins after a transition that
// changes the motion begins armed only above the guard; one that begins at the section or after a cut
// continues its predecessor's motion, and so its arming: armed if the predecessor began armed or was
// above the guard after its start (a chain of cuts without any transition is one motion).
bool ObservableEvaluator::GuardArmedAtStart(const Observable& o, const Vector& u, const Vector& p, double sign, int s) {
  const int m = model_->num_phases();
  const int k = layout_.num_first_integrals();
  const auto xi = u.segment(layout_.xi_index(), k);
  const int num_segments = layout_.num_segments();
  const auto start_value = [&](int s) {
    const SmoothFunction* g = o.phases[s % m].get();
    return g == nullptr ? 0.0 : sign * g->Evaluate(u.segment(layout_.state_offset(s), layout_.dim(s)), p, nullptr, nullptr);
  };
  const auto continuous = [&](int s) {
    return s == 0 || (model_->automaton() != nullptr &&
                      model_->automaton()->transitions()[model_->word()[(s - 1) % m]].cut);
  };
  const auto positive_after_start = [&](int s) {
    const SmoothFunction* g = o.phases[s % m].get();
    if (g == nullptr) return false;
    bool positive = false;
    PhaseFlowResult r;
    flows_[s % m].Integrate(u.segment(layout_.state_offset(s), layout_.dim(s)), xi, u(layout_.time_index(s)), false,
                            &r, [&](double t, const Eigen::Ref<const Vector>& x) {
                              if (t != 0.0 && sign * g->Evaluate(x, p, nullptr, nullptr) > 0.0) positive = true;
                            });
    counters_ += r.counters;
    return positive;
  };
  for (int depth = 0; depth < num_segments; ++depth) {
    if (start_value(s) > kGuardStartTolerance) return true;
    if (!continuous(s)) return false;
    s = s == 0 ? num_segments - 1 : s - 1;
    if (o.phases[s % m] == nullptr) return false;
    if (positive_after_start(s)) return true;
  }
  return false;
}

EvaluationStatus ObservableEvaluator::Extremum(const Observable& o, const Vector& u, double* value, RowVector* du) {
  const int m = model_->num_phases();
  const int k = layout_.num_first_integrals();
  const auto xi = u.segment(layout_.xi_index(), k);
  const Vector p = Parameters();
  const double sign = o.kind == ObservableKind::kMaximum ? -1.0 : 1.0;  // extremum of sign·g is a minimum
  // The best candidate so far: value of sign·g, segment, time (signed), interior or an end.
  double best = std::numeric_limits<double>::infinity();
  int best_segment = -1;
  double best_t = 0.0;
  bool best_interior = false;
  double best_end = std::numeric_limits<double>::infinity();  // constraints: the smaller end value
  int end_segment = -1;
  double end_t = 0.0;
  double unarmed = std::numeric_limits<double>::infinity();  // guards: -max g where never reached from above
  int unarmed_segment = -1;
  double unarmed_t = 0.0;
  PhaseFlowResult res;
  std::vector<ExtremumSample> samples;
  Vector f;
  RowVector dg;
  const int num_segments = layout_.num_segments();
  for (int s = 0; s < num_segments; ++s) {
    const int i = s % m;
    const SmoothFunction* g = o.phases[i].get();
    if (g == nullptr) continue;
    const Phase& phase = model_->phase(i);
    PhaseFlow& flow = flows_[i];
    const double t_s = u(layout_.time_index(s));
    const double dir = t_s < 0 ? -1.0 : 1.0;
    samples.clear();
    const Vector x0 = u.segment(layout_.state_offset(s), layout_.dim(s));
    flow.Integrate(x0, xi, t_s, false, &res, [&](double t, const Eigen::Ref<const Vector>& x) {
      samples.push_back({t, x});
    });
    counters_ += res.counters;
    if (!res.ok()) return EvaluationStatus::Failure(res.message);
    if (samples.empty()) samples.push_back({0.0, x0});  // a zero duration: the start alone
    // h = sign·g along the samples and its derivative along the sequence, dh = sign·ġ·dir.
    const SegmentProfile profile{*g, phase, flow, xi, p, sign, dir, res, counters_, f, dg};
    const int ns = static_cast<int>(samples.size());
    std::vector<double> h(ns), dh(ns);
    for (int j = 0; j < ns; ++j) h[j] = profile.HAndSlope(samples[j].x, &dh[j]);
    // A competing guard counts from where it is reached from above (GuardArmedSamples). Other observables
    // count everywhere.
    std::vector<char> armed(ns, 1);
    if (o.guard) {
      armed = GuardArmedSamples(profile, samples, h, dh, GuardArmedAtStart(o, u, p, sign, s));
      // A zero-duration segment has its start alone.
      for (int j = ns > 1 ? 1 : 0; j < ns; ++j) {
        if (!armed[j] && -h[j] < unarmed) unarmed = -h[j], unarmed_segment = s, unarmed_t = samples[j].t;
      }
    }
    // Interior local minima of h.
    for (int a = 0; a + 1 < ns; ++a) {
      if (!(dh[a] < 0.0 && dh[a + 1] > 0.0) || !armed[a]) continue;
      double t_star = 0.0;
      const double v = profile.RefineExtremum(samples, dh, a, &t_star);
      if (v < best) best = v, best_segment = s, best_t = t_star, best_interior = true;
    }
    // The ends.
    for (const int j : {0, ns - 1}) {
      if (o.guard && ((j == 0 && ns > 1) || !armed[j])) continue;  // a guard may be 0 where its phase begins
      if (h[j] < best_end) best_end = h[j], end_segment = s, end_t = samples[j].t;
    }
  }
  // A guard never reached from above: -max g over its phases (>= 0; 0 where it comes up to 0 from below).
  if (o.guard && best_segment < 0 && end_segment < 0) {
    HYBRIDCONT_DEMAND(sign == 1.0);  // a guard is a minimum (hybrid_automaton.cc)
    HYBRIDCONT_DEMAND(unarmed_segment >= 0);
    last_interior_ = false;
    last_segment_ = unarmed_segment;
    last_time_ = unarmed_t;
    const bool at_end = unarmed_t == u(layout_.time_index(unarmed_segment));
    const EvaluationStatus status =
        ValueAt(*o.phases[unarmed_segment % m], unarmed_segment, unarmed_t, at_end, u, value, du);
    *value = -*value;
    if (du != nullptr) *du = -*du;
    return status;
  }
  // Minimum and maximum: the smallest of all; a constraint: the smallest interior minimum, else the ends.
  const bool use_end = o.constraint ? !best_interior : best_end < best;
  const int segment = use_end ? end_segment : best_segment;
  const double t_star = use_end ? end_t : best_t;
  HYBRIDCONT_DEMAND(segment >= 0);
  *value = sign * (use_end ? best_end : best);
  last_interior_ = !use_end;
  last_segment_ = segment;
  last_time_ = t_star;
  if (du == nullptr) return {};
  // Gradient: ∇g(x(t*)) dx(t*)/d(x̄_s, ξ, p) + ∂g/∂p (envelope theorem), and ġ(t_s) when t* is the segment's
  // end.
  const bool at_end = use_end && t_star == u(layout_.time_index(segment));
  double unused;
  return ValueAt(*o.phases[segment % m], segment, t_star, at_end, u, &unused, du);
}

}  // namespace hybridcont
