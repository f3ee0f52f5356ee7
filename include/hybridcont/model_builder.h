// ModelBuilder: assembles a HybridModel (model.h) from templated phase functors over a parameter struct P.
//
// Users write the functions of each phase once, as static templates over the scalar type T; the builder
// instantiates them with double and with forward-mode jets (internal/autodiff_phase.h), so every
// derivative the shooting maps need (df, dH and its Hessian, de, dDelta) is exact:
//
//   struct BallParameters { double m = 1.0, g = 1.0; };
//   struct Fall {
//     template <class T> static StateVector<T> VectorField(const StateVector<T>& x, const BallParameters& p) {
//       StateVector<T> f(2); f << x(1), T(-p.g); return f;
//     }
//     template <class T> static T FirstIntegral(const StateVector<T>& x, const BallParameters& p) {
//       return 0.5 * p.m * x(1) * x(1) + p.m * p.g * x(0);
//     }
//     template <class T> static T Event(const StateVector<T>& x, const BallParameters&) { return x(0); }
//     template <class T> static StateVector<T> Reset(const StateVector<T>& x, const BallParameters&) {
//       StateVector<T> y(2); y << x(0), -x(1); return y;
//     }
//   };
//   struct Apex { template <class T> static T Anchor(const StateVector<T>& x, const BallParameters&) { return x(1); } };
//
//   ModelBuilder<BallParameters> b("bouncing-ball", "a ball bouncing elastically on the ground");
//   b.Parameter("m", &BallParameters::m, "mass").Parameter("g", &BallParameters::g, "gravity");
//   b.AddPhase<Fall>("flight", {"y", "dy"}, /*typical_state=*/{0.5, 0.0});
//   b.SetAnchor<Apex>();
//   HybridModel ball = b.Build();
//
// A phase functor may define `FirstIntegrals` (returning a StateVector<T> of k values) instead of
// `FirstIntegral` when the system has k > 1 hybrid first integrals (the paper's remark on N_H > 1).
//
// Templated phases have at most kMaxPhaseDim states: their StateVector<T> and jets are stack storage of that
// capacity, which keeps small models free of heap allocation. A larger phase is written as a model file or
// model text (ParseModelText + BuildExpressionModel, or LoadModelFile: generated code of any size, values,
// Jacobians and Hessians over jets of the phase's exact dimension) or as a hand-written Phase subclass added
// with AddPhase(std::unique_ptr<Phase>) (any size, its derivatives the caller's).
//
// A functor (phase or anchor) may declare its state dimension, `static constexpr int kDimension = 2;`:
// its derivatives are then compiled for that dimension only, not for every dimension up to the jets'
// capacity (several times faster to compile; the numbers are the same). AddPhase throws
// std::invalid_argument when the state names do not match it.
//
// Parameters that can be free unknowns (continuation in a model parameter, shooting_layout.h): write the
// parameter struct as a template over its scalar, the functions over any parameter type Q, and register
// each parameter by an accessor; the builder then differentiates in the parameters exactly too:
//
//   template <class T> struct BallParameters { T m = 1.0, g = 1.0; };
//   struct Fall {
//     template <class T, class Q> static StateVector<T> VectorField(const StateVector<T>& x, const Q& p) {
//       StateVector<T> f(2); f << x(1), T(-p.g); return f;
//     }
//     ...
//   };
//   ModelBuilder<BallParameters<double>> b("bouncing-ball", "...");
//   b.Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity");
//
// Q is BallParameters<double> for values and state derivatives (no cost over a plain struct) and
// BallParameters<jet> for derivatives in a parameter. A model with a plain struct, or with parameters
// registered by member pointer, runs as before; its parameters can only be set, not freed.
#ifndef HYBRIDCONT_MODEL_BUILDER_H_
#define HYBRIDCONT_MODEL_BUILDER_H_

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "hybridcont/internal/autodiff_phase.h"
#include "hybridcont/model.h"

namespace hybridcont {

// Assembles a HybridModel from templated functors over a parameter struct P.
template <class P>
class ModelBuilder {
 public:
  ModelBuilder(std::string name, std::string description)
      : name_(std::move(name)), description_(std::move(description)),
        parameters_(std::make_unique<internal::TypedParameterBlock<P>>()) {}

  // Registers a named parameter stored in member `member` of P; its default is the member's initializer.
  // range: the values it may take (default: every finite value); the default must lie inside.
  ModelBuilder& Parameter(std::string name, double P::*member, std::string description,
                          ParameterRange range = {}) {
    parameters_->Add(std::move(name), member, std::move(description), range);
    return *this;
  }
  // Registers a named parameter by a generic accessor, [](auto& p) -> auto& { return p.member; }, which
  // also reaches the member of the parameter struct over jets (see the header comment).
  template <class Accessor>
    requires std::is_invocable_v<Accessor, P&>
  ModelBuilder& Parameter(std::string name, Accessor accessor, std::string description, ParameterRange range = {}) {
    parameters_->Add(std::move(name), std::move(accessor), std::move(description), range);
    return *this;
  }

  // The model's default run and presentation (model_setup.h).
  ModelBuilder& Setup(ModelSetup setup) {
    setup_ = std::move(setup);
    return *this;
  }

  // Appends a phase whose functions are the static templates of F (see the header comment).
  // typical_state: a state where the functions are well defined (sizes the phase; samples checks).
  template <class F>
  ModelBuilder& AddPhase(std::string name, std::vector<std::string> state_names, Vector typical_state) {
    pending_.push_back({std::move(name), std::move(state_names), std::move(typical_state),
                        [](PendingPhase& pp, int next_dim, const ParameterBlock* block,
                           int slot) -> std::unique_ptr<Phase> {
                          return std::make_unique<internal::AutoDiffPhase<F, P>>(
                              pp.name, pp.state_names, next_dim, pp.typical_state, block, slot);
                        }});
    return *this;
  }
  ModelBuilder& AddPhase(std::unique_ptr<Phase> hand_written) {
    ready_.emplace(static_cast<int>(pending_.size()), std::move(hand_written));
    pending_.push_back({});
    return *this;
  }

  template <class A>
  ModelBuilder& SetAnchor() {
    anchor_factory_ = [](const ParameterBlock* block, int slot) -> std::unique_ptr<Anchor> {
      return std::make_unique<internal::AutoDiffAnchor<A, P>>(block, slot);
    };
    return *this;
  }

  // Declares a symmetry (ModelSymmetry): one sign vector per phase, in the order the phases were added.
  ModelBuilder& Symmetry(std::string name, std::vector<Vector> state_signs, bool reverses_time) {
    symmetries_.push_back({std::move(name), std::move(state_signs), reverses_time});
    return *this;
  }

  // Validates dimensions (reset maps into the next phase, first integrals in every phase) and builds.
  // Throws std::invalid_argument naming the offending phase.
  HybridModel Build() {
    const int m = static_cast<int>(pending_.size());
    if (m == 0) throw std::invalid_argument("model '" + name_ + "': no phases");
    if (!anchor_factory_) throw std::invalid_argument("model '" + name_ + "': no anchor set");
    const ParameterBlock* block = parameters_.get();
    std::vector<std::unique_ptr<Phase>> phases(m);
    std::vector<int> dims(m);
    for (int i = 0; i < m; ++i) {
      dims[i] = ready_.count(i) ? ready_.at(i)->dim() : static_cast<int>(pending_[i].state_names.size());
    }
    for (int i = 0; i < m; ++i) {
      if (ready_.count(i)) {
        phases[i] = std::move(ready_.at(i));
      } else {
        if (pending_[i].typical_state.size() != dims[i]) {
          throw std::invalid_argument("model '" + name_ + "', phase '" + pending_[i].name +
                                      "': typical_state has " + std::to_string(pending_[i].typical_state.size()) +
                                      " entries, the phase has " + std::to_string(dims[i]) + " states");
        }
        if (dims[i] < 1 || dims[i] > kMaxPhaseDim) {
          throw std::invalid_argument("model '" + name_ + "', phase '" + pending_[i].name + "': dimension " +
                                      std::to_string(dims[i]) + " outside [1, kMaxPhaseDim = " +
                                      std::to_string(kMaxPhaseDim) +
                                      "] of templated phases; a larger phase is a model file or model text "
                                      "(generated code of any size, model_file.h) or a hand-written Phase "
                                      "(AddPhase(std::unique_ptr<Phase>))");
        }
        phases[i] = pending_[i].make(pending_[i], dims[(i + 1) % m], block, i);
      }
    }
    internal::ValidatePhaseSizes(name_, phases);
    HybridModel model(name_, description_, std::move(parameters_), std::move(phases), anchor_factory_(block, m));
    for (ModelSymmetry& symmetry : symmetries_) model.AddSymmetry(std::move(symmetry));
    model.SetSetup(std::move(setup_));
    return model;
  }

 private:
  struct PendingPhase {
    std::string name;
    std::vector<std::string> state_names;
    Vector typical_state;
    std::function<std::unique_ptr<Phase>(PendingPhase&, int, const ParameterBlock*, int)> make;
  };
  std::string name_;
  std::string description_;
  std::unique_ptr<internal::TypedParameterBlock<P>> parameters_;
  std::vector<PendingPhase> pending_;
  std::map<int, std::unique_ptr<Phase>> ready_;
  std::function<std::unique_ptr<Anchor>(const ParameterBlock*, int)> anchor_factory_;
  std::vector<ModelSymmetry> symmetries_;
  ModelSetup setup_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_MODEL_BUILDER_H_
