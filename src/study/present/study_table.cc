#include "hybridcont/study_table.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace hybridcont {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Columns filled row by row: a number column is created (NaN for the rows before) when first met. A column
// given twice in one row keeps the first value: an observable among the unknowns (--monitor, --extremum) is
// both an unknown and an observable of the point, equal on the orbit.
class ColumnBuilder {
 public:
  void Text(const std::string& name, const std::string& value) {
    StudyColumn& c = At(name, true);
    if (static_cast<int>(c.texts.size()) <= rows_) c.texts.push_back(value);
  }
  void Number(const std::string& name, double value) {
    StudyColumn& c = At(name, false);
    if (static_cast<int>(c.numbers.size()) <= rows_) c.numbers.push_back(value);
  }
  // Ends a row: every column the row did not reach gets NaN (or "").
  void EndRow() {
    ++rows_;
    for (StudyColumn& c : columns_) {
      if (c.text && static_cast<int>(c.texts.size()) < rows_) c.texts.emplace_back();
      if (!c.text && static_cast<int>(c.numbers.size()) < rows_) c.numbers.push_back(kNaN);
    }
  }
  std::vector<StudyColumn> Take() { return std::move(columns_); }

 private:
  std::vector<StudyColumn> columns_;
  std::map<std::string, std::size_t> index_;
  int rows_ = 0;

  StudyColumn& At(const std::string& name, bool text) {
    const auto [it, added] = index_.emplace(name, columns_.size());
    if (added) {
      StudyColumn c;
      c.name = name;
      c.text = text;
      if (text) c.texts.assign(rows_, "");
      else c.numbers.assign(rows_, kNaN);
      columns_.push_back(std::move(c));
    }
    return columns_[it->second];
  }
};

}  // namespace

std::vector<StudyColumn> StudyPointColumns(const StudyResult& study) {
  std::size_t multipliers = 0;
  bool automaton = false;
  for (const StudyBranch& b : study.branches) {
    for (const StudyPoint& p : b.points) {
      multipliers = std::max(multipliers, p.analysis.multipliers.size());
      automaton = automaton || !std::isnan(p.analysis.automaton_replay_error);
    }
  }
  ColumnBuilder rows;
  for (const StudyBranch& b : study.branches) {
    const auto H = std::find(b.unknown_names.begin(), b.unknown_names.end(), "H");
    for (const StudyPoint& p : b.points) {
      const OrbitAnalysis& a = p.analysis;
      rows.Number("branch", b.id);
      rows.Text("family", b.family);
      rows.Number("index", p.index);
      rows.Number("H", H == b.unknown_names.end() ? kNaN : p.u(H - b.unknown_names.begin()));
      rows.Number("T", p.T);
      for (std::size_t k = 0; k < b.unknown_names.size(); ++k) {
        if (b.unknown_names[k] != "H") rows.Number(b.unknown_names[k], p.u(static_cast<Eigen::Index>(k)));
      }
      rows.Number("physical", a.classification.physical ? 1 : 0);
      rows.Text("classification", ToString(a.classification.reason));
      rows.Text("stability", a.stability);
      rows.Number("residual", a.residual);
      rows.Number("newton_iterations", p.newton_iterations);
      rows.Number("step", p.step);
      rows.Number("dT_d" + b.continued, p.period_slope);
      const auto flag = [&](bool value) { return a.floquet ? (value ? 1.0 : 0.0) : kNaN; };
      rows.Number("replay_error", a.replay_error);
      rows.Number("stable", flag(a.stable));
      rows.Number("normal", flag(a.normal));
      rows.Number("num_unit", a.floquet ? a.num_unit : kNaN);
      rows.Number("max_multiplier", a.max_multiplier);
      rows.Number("bp_test", a.bp_test);
      rows.Number("pd_test", a.pd_test);
      rows.Number("multiplier_error", a.floquet ? a.multiplier_error : kNaN);
      for (std::size_t j = 0; j < multipliers; ++j) {
        const bool known = j < a.multipliers.size();
        rows.Number("mu" + std::to_string(j + 1) + "_re", known ? a.multipliers[j].real() : kNaN);
        rows.Number("mu" + std::to_string(j + 1) + "_im", known ? a.multipliers[j].imag() : kNaN);
      }
      if (automaton) rows.Number("automaton_replay_error", a.automaton_replay_error);
      for (const NamedValue& q : p.quantities) rows.Number(q.name, q.value);
      for (const auto& [name, value] : a.observables) rows.Number(name, value);
      rows.EndRow();
    }
  }
  return rows.Take();
}

}  // namespace hybridcont
