// The k-fold repeated model and its orbits (period_doubling.h).
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/period_doubling.h"
#include "model/phase_view.h"

namespace hybridcont {
namespace {

// The parent's parameters, read through; the parent's phases read them from the parent's block. A copy
// (Clone) owns a copy of the parent, whose parameters it then sets: a copied repeated model is a model of
// its own, with its parameters free to change (a free parameter of the doubled map).
class ParameterView : public ParameterBlock, public internal::ParentModelAccess {
 public:
  ParameterView(const HybridModel& parent) : parent_(&parent) {}  // NOLINT(google-explicit-constructor)
  explicit ParameterView(std::shared_ptr<HybridModel> owned) : parent_(owned.get()), owned_(std::move(owned)) {}
  const std::vector<ParameterInfo>& infos() const override { return parent_->parameters(); }
  double Get(int index) const override { return parent_->parameter_value(index); }
  void Set(int index, double value) override {
    if (!owned_) {
      throw std::invalid_argument("parameter '" + parent_->parameters()[index].name + "' of a repeated model is its "
                                  "parent '" + parent_->name() + "''s: set it on the parent model");
    }
    owned_->SetParameterValue(index, value);
  }
  std::unique_ptr<ParameterBlock> Clone() const override {
    if (!parent_->is_cloneable()) return nullptr;
    return std::make_unique<ParameterView>(std::make_shared<HybridModel>(parent_->Clone()));
  }
  const HybridModel& parent() const override { return *parent_; }

 private:
  const HybridModel* parent_;
  std::shared_ptr<HybridModel> owned_;  // a copy's own parent
};

void RequireFold(int k) {
  if (k < 1) throw std::invalid_argument("RepeatedModel: k = " + std::to_string(k) + ", must be >= 1");
}

// The names of the copies of a parent unknown in the k-fold layout: "t<i>" and "x<i>_<state>" of parent
// segment i are those of segments i, i + (m+1), ...; ξ, H̄ and anything else are their own names.
std::vector<std::string> CopyNames(const std::string& name, int segments, int k) {
  const bool time = name.size() > 1 && name[0] == 't';
  const bool state = name.size() > 1 && name[0] == 'x' && name.find('_') != std::string::npos;
  if (!time && !state) return {name};
  const std::string digits = time ? name.substr(1) : name.substr(1, name.find('_') - 1);
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) return {name};
  const int i = std::stoi(digits);
  const std::string tail = time ? "" : name.substr(name.find('_'));
  std::vector<std::string> names;
  for (int c = 0; c < k; ++c) names.push_back(std::string(1, name[0]) + std::to_string(i + c * segments) + tail);
  return names;
}

// The parent's set-up in the k-fold layout (period_doubling.h): bounds, scales and start values on each
// copy of their unknown, a bound on the period times k, drawings of a segment on each copy of it.
ModelSetup RepeatedSetup(const ModelSetup& parent, int segments, int k) {
  ModelSetup setup = parent;
  setup.run.bounds.clear();
  for (const BoundSpec& b : parent.run.bounds) {
    if (b.component == "period") {
      const auto times_k = [k](const SetupValue& v) {
        return SetupValue(std::to_string(k) + "*(" + v.expression + ")", v.where);
      };
      setup.run.bounds.push_back({b.component, times_k(b.lower), times_k(b.upper)});
      continue;
    }
    for (const std::string& name : CopyNames(b.component, segments, k)) setup.run.bounds.push_back({name, b.lower, b.upper});
  }
  setup.run.scales.clear();
  for (const auto& [component, value] : parent.run.scales) {
    for (const std::string& name : CopyNames(component, segments, k)) setup.run.scales.push_back({name, value});
  }
  setup.start.values.clear();
  for (const auto& [component, value] : parent.start.values) {
    for (const std::string& name : CopyNames(component, segments, k)) setup.start.values.push_back({name, value});
  }
  for (DrawingSpec::PhaseDrawing& drawing : setup.drawing.phases) {
    std::vector<int> copies;
    for (const int s : drawing.segments) {
      for (int c = 0; c < k; ++c) copies.push_back(s + c * segments);
    }
    drawing.segments = std::move(copies);
  }
  if (!setup.title.empty()) setup.title += ", " + std::to_string(k) + "-fold";
  return setup;
}

}  // namespace

HybridModel RepeatedModel(const HybridModel& model, int k) {
  RequireFold(k);
  const int m = model.num_phases();
  std::vector<std::unique_ptr<Phase>> phases;
  std::vector<int> parent_phase;  // per phase of the k-fold model: the parent phase it repeats
  for (int c = 0; c < k; ++c) {
    for (int i = 0; i < m; ++i) {
      phases.push_back(std::make_unique<internal::PhaseView>(model.phase(i), i));
      parent_phase.push_back(i);
    }
    if (c + 1 < k) {
      phases.push_back(std::make_unique<internal::SectionPhaseView>(model.phase(0), model.anchor()));
      parent_phase.push_back(0);
    }
  }
  HybridModel repeated(model.name() + "-x" + std::to_string(k),
                       model.description() + ", " + std::to_string(k) + "-fold repeated",
                       std::make_unique<ParameterView>(model), std::move(phases),
                       std::make_unique<internal::AnchorView>(model.anchor()));
  for (const ModelSymmetry& symmetry : model.symmetries()) {
    ModelSymmetry copy{symmetry.name, {}, symmetry.reverses_time};
    for (const int i : parent_phase) copy.state_signs.push_back(symmetry.state_signs[i]);
    repeated.AddSymmetry(std::move(copy));
  }
  repeated.SetSetup(RepeatedSetup(model.setup(), m + 1, k));
  return repeated;
}

Vector RepeatedOrbit(const ShootingLayout& layout, const Vector& u, int k) {
  RequireFold(k);
  if (u.size() != layout.num_unknowns()) {
    throw std::invalid_argument("RepeatedOrbit: u has size " + std::to_string(u.size()) + ", the layout " +
                                std::to_string(layout.num_unknowns()));
  }
  const int cycle = layout.xi_index(0);  // the segment blocks come first
  const int tail = layout.num_unknowns() - cycle;
  Vector u_k(k * cycle + tail);
  for (int c = 0; c < k; ++c) u_k.segment(c * cycle, cycle) = u.head(cycle);
  u_k.tail(tail) = u.tail(tail);
  return u_k;
}

std::vector<std::string> RepeatedNames(const ShootingLayout& layout, const std::string& name, int k) {
  RequireFold(k);
  const std::vector<std::string>& names = layout.unknown_names();
  if (std::find(names.begin(), names.begin() + layout.xi_index(0), name) == names.begin() + layout.xi_index(0)) {
    return {name};
  }
  return CopyNames(name, layout.num_segments(), k);
}

bool IsRepeatedOrbit(const ShootingLayout& layout, const Vector& u_k, int k, double tolerance) {
  const int cycle = layout.xi_index(0);
  const int tail = layout.num_unknowns() - cycle;
  if (k < 1 || u_k.size() != k * cycle + tail) return false;
  const double scale = tolerance * (1.0 + u_k.lpNorm<Eigen::Infinity>());
  for (int c = 1; c < k; ++c) {
    if ((u_k.segment(c * cycle, cycle) - u_k.head(cycle)).lpNorm<Eigen::Infinity>() > scale) return false;
  }
  return true;
}

}  // namespace hybridcont
