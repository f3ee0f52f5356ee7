#include "hybridcont/observable_test_functions.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace hybridcont {

ObservableTestFunctions::ObservableTestFunctions(const HybridModel& model, const IntegratorOptions& integrator,
                                                 FreeParameters free,
                                                 std::vector<std::pair<std::string, double>> monitors)
    : model_(&model),
      integrator_(integrator),
      free_(std::move(free)),
      monitors_(std::move(monitors)),
      layout_(model, free_),
      point_model_(layout_.num_free_parameters() > 0 ? std::make_unique<HybridModel>(model.Clone()) : nullptr),
      evaluator_(std::make_unique<ObservableEvaluator>(point_model_ ? *point_model_ : model, layout_, integrator)) {
  for (const auto& [name, value] : monitors_) {
    const int j = model.FindObservable(name);
    if (j < 0) throw std::invalid_argument("monitored observable '" + name + "': model '" + model.name() + "' has none such");
    functions_.push_back({j, value, false, layout_.UnknownIndex(name)});
  }
  for (int j = 0; j < static_cast<int>(model.observables().size()); ++j) {
    if (model.observables()[j].constraint) functions_.push_back({j, 0.0, true, -1});
  }
}

std::vector<SpecialPointType> ObservableTestFunctions::types() const {
  std::vector<SpecialPointType> types;
  for (const Function& f : functions_) {
    types.push_back(f.constraint ? SpecialPointType::kConstraintBoundary : SpecialPointType::kObservableValue);
  }
  return types;
}

void ObservableTestFunctions::SetParameters(const Vector& u) {
  for (int i = 0; i < layout_.num_free_parameters(); ++i) {
    point_model_->SetParameterValue(layout_.parameter_model_index(i), u(layout_.parameter_index(i)));
  }
}

void ObservableTestFunctions::Evaluate(const Vector& u, bool branch_point, Vector* values) {
  (void)branch_point;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  *values = Vector::Constant(size(), nan);
  try {
    if (point_model_) SetParameters(u);
  } catch (const std::invalid_argument&) {
    return;  // a parameter outside its range: no orbit of the model
  }
  // A constraint means nothing on an orbit that runs a phase backward or not at all: no sign there (and no
  // integrations spent on the non-physical branches of a diagram).
  bool forward = true;
  for (int s = 0; s < layout_.num_segments(); ++s) forward = forward && u(layout_.time_index(s)) > 0;
  for (int i = 0; i < size(); ++i) {
    const Function& f = functions_[i];
    if (f.constraint && !forward) continue;
    double value = 0.0;
    if (f.unknown >= 0) {
      value = u(f.unknown);
    } else if (!evaluator_->Evaluate(f.observable, u, &value, nullptr).ok) {
      continue;
    }
    // A minimum's sign at an end value means nothing (a clearance is 0 there); a final value always has one.
    const bool minimum = model_->observables()[f.observable].kind == ObservableKind::kMinimum;
    if (f.constraint && minimum && !evaluator_->last_extremum_interior()) continue;
    (*values)(i) = value - f.value;
  }
}

bool ObservableTestFunctions::Keep(int function, const Vector& u, std::string* note) {
  (void)u;
  const Function& f = functions_.at(function);
  *note = "'" + model_->observables()[f.observable].name + "' = " + std::to_string(f.value);
  return true;
}

std::unique_ptr<TestFunctions> ObservableTestFunctions::Clone() const {
  return std::make_unique<ObservableTestFunctions>(*model_, integrator_, free_, monitors_);
}

std::unique_ptr<TestFunctions> ObservableTestFunctions::Refined(double factor) const {
  IntegratorOptions refined = integrator_;
  refined.rtol *= factor;
  refined.atol *= factor;
  return std::make_unique<ObservableTestFunctions>(*model_, refined, free_, monitors_);
}

}  // namespace hybridcont
