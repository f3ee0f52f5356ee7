#include "study/stages/period_doubled_families.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "hybridcont/family_ranges.h"
#include "hybridcont/floquet.h"
#include "hybridcont/period_doubling.h"
#include "hybridcont/timebased_shooting.h"
#include "study/stages/families.h"
#include "study/engine/model_exploration.h"
#include "study/engine/point_analysis.h"
#include "study/engine/scenario.h"
#include "study/stages/special_points.h"

namespace hybridcont::study {
namespace {

// The run's continuation options on the doubled layout: a bound or target on an unknown applies to each
// of its copies, a sum bound to the sum over all copies (twice the parent's on repeated orbits).
ExplorationOptions DoubledOptions(const ExplorationOptions& run, const ShootingLayout& parent) {
  ExplorationOptions o = run;
  ContinuationOptions& c = o.continuation;
  c.bounds.clear();
  for (const ComponentBound& b : run.continuation.bounds) {
    for (const std::string& name : RepeatedNames(parent, b.component, 2)) c.bounds.push_back({name, b.lower, b.upper});
  }
  c.targets.clear();
  for (const ComponentTarget& t : run.continuation.targets) {
    for (const std::string& name : RepeatedNames(parent, t.component, 2)) c.targets.push_back({name, t.value});
  }
  c.sum_bounds.clear();
  for (const SumBound& b : run.continuation.sum_bounds) {
    SumBound doubled{{}, 2 * b.lower, 2 * b.upper};
    for (const std::string& component : b.components) {
      for (const std::string& name : RepeatedNames(parent, component, 2)) doubled.components.push_back(name);
    }
    c.sum_bounds.push_back(doubled);
  }
  o.start_conditions.clear();
  return o;
}

std::string Multipliers(const FloquetResult& f) {
  std::string text;
  for (const std::complex<double>& mu : f.nontrivial) {
    text += fmt::format("{}{:.10g}{}", text.empty() ? "" : ", ", mu.real(),
                        mu.imag() == 0 ? "" : fmt::format("{:+.3g}i", mu.imag()));
  }
  return text;
}

}  // namespace

std::string ExplorePeriodDoubledFamilies(const HybridModel& model, const HybridModel& doubled, const RunSetup& setup,
                                         const BifurcationDiagram& diagram, std::vector<StudySpecialPoint>* special_points,
                                         ResultsWriter& writer) {
  // A model without first integral is followed in its parameter: both maps have it free (setup.free).
  const ShootingLayout parent(model, setup.free), layout(doubled, setup.free);
  const ExplorationOptions options = DoubledOptions(setup.exploration, parent);
  const Scenario scenario = DefaultScenario(doubled);
  TimeBasedShooting parent_map(model, setup.integrator, setup.free), floquet_map(doubled, setup.integrator, setup.free);
  HybridModel at_point = doubled.Clone();  // the doubled model at a point's free-parameter values
  const ReplayOptions replay = ReplayOptionsFor(setup.integrator);
  std::string report = "Period-doubled families (the phase sequence traversed twice, model " + doubled.name() + "):\n";
  int next_branch = static_cast<int>(diagram.branches.size());
  int families = 0;
  const FamilyNamer name_of = PeriodDoubledNamer(setup.scenario.describe, parent, layout);
  std::string family_lines;  // where each family's orbits are physical and stable (families.h)
  for (const SpecialPoint& pd : diagram.special_points) {
    const bool located_pd = pd.type == SpecialPointType::kPeriodDoubling && pd.status == LocationStatus::kLocated;
    if (!located_pd || pd.duplicate_of >= 0 || pd.u.size() == 0) continue;
    const Vector& u_pd = pd.u;
    const int pd_id = pd.id;
    const int offset = next_branch;
    std::set<int> begun;  // the family's branch ids with a point so far
    ModelExploration exploration(doubled, scenario, setup.integrator, options, Formulation::kTimeBased, setup.free);
    exploration.set_branch_store(writer.resume_store(), offset);
    BifurcationDiagram d = exploration.RunPeriodDoubled(parent, u_pd, [&](const ProgressInfo& info, const Vector& u) {
      const int id = info.branch_id + offset;
      if (begun.insert(id).second) writer.SetBranchModel(id, doubled, "period-doubled");
      PointRecord record = RecordOf(info, u);
      SetFreeParameters(layout, u, &at_point);
      const auto known = exploration.KnownBranchPointAnalysis(u);
      AnalyzePoint(at_point, setup.integrator, floquet_map, replay, &record, known ? &*known : nullptr);
      writer.AddPoint(id, record);
    });
    MarkExtrema(setup.extrema, &d);  // the observables' turning points are EX points here too
    const FloquetResult at_pd = ComputeFloquet(parent_map, u_pd);
    report += fmt::format("  from PD #{} at {} = {:.12f} (parent period {:.12f}, multipliers {}):\n", pd_id,
                          parent.continued_name(), u_pd(parent.continued_index()), parent.Period(u_pd),
                          at_pd.ok() ? Multipliers(at_pd) : "-");
    if (d.status == ExplorationStatus::kStartFailed) {
      report += "    not started: " + d.message + "\n";
      continue;
    }
    ++families;
    RenumberDiagram(offset, static_cast<int>(special_points->size()), &d);
    for (SpecialPoint& sp : d.special_points) sp.message += " [period-doubled family of PD #" + std::to_string(pd_id) + "]";
    for (StudySpecialPoint& p : RecordSpecialPoints(d, layout)) {
      p.period_doubled_from = pd_id;
      special_points->push_back(std::move(p));
    }
    for (const Branch& b : d.branches) {
      if (!begun.count(b.id)) writer.SetBranchModel(b.id, doubled, "period-doubled");  // a branch without points
      writer.EndBranch(b);
      // Its family and ranges (families.h), from the typed analysis of its points, and where its stability changes.
      family_lines += AssignBranchFamily(b, layout, name_of, writer);
      writer.SetPeriodDoubledFrom(b.id, pd_id);
      const std::vector<StabilityChange> changes = StabilityChanges(*writer.FindBranch(b.id));
      const Vector& start = b.points.empty() ? u_pd : b.points.front().u;
      const FloquetResult f = b.points.empty() ? FloquetResult{} : ComputeFloquet(floquet_map, start);
      std::string flips;
      for (const StabilityChange& c : changes) {
        flips += fmt::format("{}{} = {:.10f} ({}{})", flips.empty() ? "" : ", ", layout.continued_name(), c.value,
                             c.stable ? "stable" : "unstable",
                             c.special_point >= 0 ? ", " + c.how : ", between two points, not located");
      }
      report += fmt::format("    branch {}: {} points, {}; start T = {:.12f} (2x parent {:.12f}), multipliers {}; "
                            "stability changes: {}\n",
                            b.id, b.points.size(), ToString(b.termination),
                            b.points.empty() ? std::nan("") : layout.Period(start), 2 * parent.Period(u_pd),
                            f.ok() ? Multipliers(f) : "-", flips.empty() ? "none" : flips);
    }
    for (const SpecialPoint& sp : d.special_points) report += "    " + sp.BriefReport(layout.unknown_names()) + "\n";
    next_branch += static_cast<int>(d.branches.size());
  }
  if (families == 0 && report.find("from PD") == std::string::npos) report += "  none (no located PD point)\n";
  if (!family_lines.empty()) {
    report += "Physical period-doubled families (where their orbits are physical and where stable, in " +
              layout.continued_name() + "):\n" + family_lines;
  }
  return report;
}

}  // namespace hybridcont::study
