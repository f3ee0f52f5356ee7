// RunStudy (study.h): the pipeline of a study. Order of work, so that bad input writes nothing: validate every
// option, build the model, validate the exploration options against the problem, check the start, prepare the
// output folder; only then compute. Points are classified (physical or why not) and handed to the record
// (results_writer.h) as they are accepted (with threads > 1: branch by branch as the exploration merges
// them, in the order of one thread).
//
// Steps in files of their own: run_setup.h (options -> validated set-up), point_analysis.h (each accepted
// point), summary_json.h (options and special points in the document), period_doubled_families.h,
// word_families.h, parameter_curves.h, families.h (every branch's family and ranges).
#include <fmt/format.h>
#include <openssl/evp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "study/stages/family_guide.h"
#include "study/stages/families.h"
#include "hybridcont/automaton_words.h"
#include "hybridcont/conservation_check.h"
#include "hybridcont/exploration.h"
#include "hybridcont/floquet.h"
#include "hybridcont/model_file.h"
#include "hybridcont/period_doubling.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/study.h"
#include "hybridcont/timebased_shooting.h"
#include "hybridcont/version.h"
#include "modelfile/model_cache.h"
#include "study/engine/model_exploration.h"
#include "study/engine/orbit_start.h"
#include "study/stages/parameter_curves.h"
#include "study/engine/parameter_starts.h"
#include "study/engine/start_carry.h"
#include "study/stages/period_doubled_families.h"
#include "study/engine/point_analysis.h"
#include "study/stages/restart.h"
#include "study/stages/special_points.h"
#include "study/study_model.h"
#include "study/io/results_writer.h"
#include "study/engine/run_setup.h"
#include "study/engine/scenario.h"
#include "study/io/study_document.h"
#include "study/io/summary_json.h"
#include "study/stages/word_families.h"

namespace hybridcont::study {
namespace {

// A report of several indented lines as one: lines joined by "; ", their indentation dropped.
std::string OneLine(const std::string& report) {
  std::string out;
  std::size_t begin = 0;
  while (begin < report.size()) {
    std::size_t end = report.find('\n', begin);
    if (end == std::string::npos) end = report.size();
    std::string line = report.substr(begin, end - begin);
    line.erase(0, line.find_first_not_of(' '));
    if (!line.empty()) out += (out.empty() ? "" : "; ") + line;
    begin = end + 1;
  }
  return out;
}

// The physicality of the accepted points, per branch id and in the order of the points (false where a point
// could not be converted to the time-based layout).
struct PointLog {
  std::map<int, std::vector<bool>> physical;
};

// The exploration's point callback: converts each accepted point to the time-based layout (which every
// output uses, whatever the formulation), analyses it (orbit_analysis.h) and hands it to the record.
// dT/dc from a tangent τ in the layout's unknowns (c: the continued coordinate): Σ τ_{t_i} / τ_c; NaN
// without a tangent, ±infinity at a turning point in c.
double PeriodSlope(const ShootingLayout& layout, const Vector& tangent) {
  if (tangent.size() != layout.num_unknowns()) return std::nan("");
  double dT = 0;
  for (int i = 0; i < layout.num_segments(); ++i) dT += tangent(layout.time_index(i));
  const double dc = tangent(layout.continued_index());
  return dc == 0 ? std::copysign(HUGE_VAL, dT) : dT / dc;
}

class PointStream {
 public:
  PointStream(const HybridModel& model, const RunSetup& setup, ModelExploration& exploration, ResultsWriter& writer)
      : model_(model), setup_(setup), exploration_(exploration), writer_(writer),
        floquet_map_(model, setup.integrator, setup.free), replay_options_(ReplayOptionsFor(setup.integrator)),
        point_model_(setup.free.empty() ? nullptr : std::make_unique<HybridModel>(model.Clone())) {}

  void Add(const ProgressInfo& info, const Vector& u_problem) {
    Vector u;
    if (!exploration_.ToTimeBased(u_problem, &u).ok) {
      log_.physical[info.branch_id].push_back(false);  // keep per-point alignment

      return;
    }
    PointRecord record = RecordOf(info, u);
    record.period_slope = PeriodSlope(floquet_map_.layout(), info.tangent);
    if (point_model_) SetFreeParameters(floquet_map_.layout(), u, point_model_.get());
    const auto known = exploration_.KnownBranchPointAnalysis(u);
    AnalyzePoint(point_model_ ? *point_model_ : model_, setup_.integrator, floquet_map_, replay_options_, &record,
                 known ? &*known : nullptr);
    writer_.AddPoint(info.branch_id, record);
    log_.physical[info.branch_id].push_back(record.classification.physical);
  }

  const PointLog& log() const { return log_; }
  // One map for residuals and Floquet data, separate from the engine's (whose cache stays intact).
  TimeBasedShooting& floquet_map() { return floquet_map_; }

 private:
  const HybridModel& model_;
  const RunSetup& setup_;
  ModelExploration& exploration_;
  ResultsWriter& writer_;
  TimeBasedShooting floquet_map_;
  const ReplayOptions replay_options_;
  std::unique_ptr<HybridModel> point_model_;  // with free parameters: the model at the point's values
  PointLog log_;
};

// Interval widths of a state-based special point in the time-based layout: the widths of the unknowns both
// layouts have (x̄_1, ξ, H̄: the same names), NaN for the others; empty when the width is unknown.
void ConvertWidth(const std::vector<std::string>& state_names, const std::vector<std::string>& time_names,
                  Vector* width) {
  if (width->size() != static_cast<Eigen::Index>(state_names.size())) return width->resize(0);
  Vector w = Vector::Constant(static_cast<Eigen::Index>(time_names.size()), std::nan(""));
  for (size_t i = 0; i < state_names.size(); ++i) {
    const auto it = std::find(time_names.begin(), time_names.end(), state_names[i]);
    if (it != time_names.end()) w(it - time_names.begin()) = (*width)(static_cast<Eigen::Index>(i));
  }
  *width = w;
}

// A state-based diagram in the time-based layout, which everything downstream reads: points (without
// tangents) and special points, NaN where a point cannot be converted.
void ConvertToTimeBased(ModelExploration& exploration, const ShootingLayout& layout, BifurcationDiagram* diagram) {
  const auto convert = [&](Vector* u) {
    Vector u_time;
    if (u->size() && exploration.ToTimeBased(*u, &u_time).ok) *u = u_time;
    else *u = Vector::Constant(layout.num_unknowns(), std::nan(""));
  };
  const std::vector<std::string> state_names = diagram->unknown_names, time_names = layout.unknown_names();
  for (Branch& b : diagram->branches) {
    for (ContinuationPoint& p : b.points) convert(&p.u), p.tangent.resize(0);
    for (SpecialPoint& sp : b.special_points) convert(&sp.u), ConvertWidth(state_names, time_names, &sp.interval_width);
  }
  for (SpecialPoint& sp : diagram->special_points) {
    convert(&sp.u), ConvertWidth(state_names, time_names, &sp.interval_width);
  }
  diagram->unknown_names = layout.unknown_names();
}

// The key-frame orbits: per family, as the model names its physical orbits, the physical point closest to
// the scenario's key-frame target (two halves of one family from a start would otherwise fill the frames
// with one gait twice); orbits no family rule names, per branch. In the order of their branches, the first
// scenario.max_keyframe_orbits of them, each traced and written.
void WriteKeyframeOrbits(const BifurcationDiagram& diagram, const PointLog& log, const HybridModel& model,
                         const RunSetup& setup, const ShootingLayout& layout, ResultsWriter& writer) {
  const Scenario& sc = setup.scenario;
  struct Candidate {
    int branch = -1, point = -1;
    double distance = 1e300;
    std::string family;
  };
  std::vector<Candidate> candidates;  // one per named family, one per branch of unnamed orbits
  for (const Branch& b : diagram.branches) {
    const auto flags = log.physical.find(b.id);
    if (flags == log.physical.end()) continue;
    for (int i = 0; i < static_cast<int>(b.points.size()) && i < static_cast<int>(flags->second.size()); ++i) {
      if (!flags->second[i]) continue;
      const Vector& u = b.points[i].u;
      const double value = sc.keyframes.component == "T" ? layout.Period(u) : u(layout.continued_index());
      const double distance = std::abs(value - sc.keyframes.value);
      const std::string family = sc.describe(u);
      const bool named = family != kUnnamedFamily;
      auto it = std::find_if(candidates.begin(), candidates.end(), [&](const Candidate& c) {
        return c.family == family && (named || c.branch == b.id);
      });
      if (it == candidates.end()) it = candidates.insert(candidates.end(), Candidate{b.id, i, distance, family});
      if (distance < it->distance) *it = Candidate{b.id, i, distance, family};
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.branch < b.branch; });
  std::vector<Vector> drawn;
  TimeBasedShooting floquet_map(model, setup.integrator, setup.free);  // the orbits' monodromy matrices
  for (const Candidate& c : candidates) {
    if (static_cast<int>(drawn.size()) >= sc.max_keyframe_orbits) break;
    const auto branch = std::find_if(diagram.branches.begin(), diagram.branches.end(),
                                     [&](const Branch& b) { return b.id == c.branch; });
    const Vector& u = branch->points[c.point].u;
    if (std::any_of(drawn.begin(), drawn.end(),
                    [&](const Vector& v) { return (v - u).lpNorm<Eigen::Infinity>() <= 1e-9 * (1 + u.norm()); })) {
      continue;  // the same orbit, the start of two half-branches
    }
    drawn.push_back(u);
    HybridModel at_point = model.Clone();
    SetFreeParameters(layout, u, &at_point);
    const OrbitTrace trace(at_point, OrbitPart(layout, u), setup.integrator);
    const FloquetResult floquet = ComputeFloquet(floquet_map, u);
    writer.AddOrbit(trace, c.branch, c.point, layout.has_level() ? u(layout.H_index()) : std::nan(""),
                    layout.Period(u), c.family, floquet.ok() ? floquet.monodromy : Matrix());
  }
}

// Per branch with physical orbits: its family, where its orbits are physical and where stable, in the
// continued coordinate, each end from the special point located there (families.h).
std::string RangesReport(const BifurcationDiagram& diagram, const Scenario& sc, const ShootingLayout& layout,
                         ResultsWriter& writer) {
  std::string report = fmt::format("Physical families (where their orbits are physical and where stable, in {}):\n",
                                   layout.continued_name());
  std::string families;
  for (const Branch& b : diagram.branches) families += AssignBranchFamily(b, layout, sc.describe, writer);
  return report + (families.empty() ? "  none\n" : families);
}

// The Floquet crossings among the diagram's special points (located by the exploration as test functions,
// floquet_test_functions.h), one line each, BP before PD. A monitored value is located on any orbit: one on an
// orbit that is no motion of the system (`physical` false) says so.
std::string FloquetReport(const BifurcationDiagram& diagram, const ShootingLayout& layout,
                          const std::function<bool(const Vector& u)>& physical) {
  std::string report =
      "Floquet and observable special points (multiplier crossings on physical orbits; grazing events; constraint "
      "boundaries; monitored values):\n";
  int count = 0;
  for (const SpecialPointType type : {SpecialPointType::kFloquetBranchPoint, SpecialPointType::kPeriodDoubling,
                                      SpecialPointType::kGrazing, SpecialPointType::kNeimarkSacker,
                                      SpecialPointType::kKreinCollision, SpecialPointType::kConstraintBoundary,
                                      SpecialPointType::kZeroDuration, SpecialPointType::kObservableValue}) {
    const std::string code = Code(type);  // special_point.h: the one definition of the codes
    for (const SpecialPoint& sp : diagram.special_points) {
      if (sp.type != type || sp.u.size() == 0) continue;
      // Over the components the point's layout has (a state-based point converted to the time-based layout
      // has no widths for the durations and the later segments' states: NaN there).
      double precision = 0;
      bool widths = false;
      for (Eigen::Index i = 0; i < sp.interval_width.size(); ++i) {
        if (std::isfinite(sp.interval_width(i))) precision += sp.interval_width(i) * sp.interval_width(i), widths = true;
      }
      precision = widths ? std::sqrt(precision) : sp.precision();
      const bool non_physical = type == SpecialPointType::kObservableValue && !physical(sp.u);
      report += fmt::format("  {} on branch {} after point {}: {} = {:.12f}, T = {:.12f} ({}, precision {:.1e}){}{}\n",
                            code, sp.branch_id, sp.index, layout.continued_name(), sp.u(layout.continued_index()),
                            layout.Period(sp.u), ToString(sp.status), precision,
                            sp.message.empty() ? "" : " " + sp.message,
                            non_physical ? " (on a non-physical orbit)" : "");
      ++count;
    }
  }
  if (count == 0) report += "  none\n";
  return report;
}

// The diagram's report, the Floquet points' and the wall time and work of the whole computation
// (exploration, classification and replays, Floquet multipliers, key-frame orbits, and the branch and orbit
// files written on the way), before the summary, report and figures; the Floquet test functions' work on a
// line of its own (ModelExploration::test_function_work: not the continuation's).
std::string RunReport(const BifurcationDiagram& diagram, const std::string& floquet_report,
                      std::chrono::steady_clock::time_point start_time, const ModelExploration& exploration,
                      const TimeBasedShooting& floquet_map) {
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  const TestFunctionWork tests = exploration.test_function_work();
  return diagram.FullReport() + floquet_report +
         fmt::format("\nwall time {:.3f} s, {} right-hand-side evaluations in {} map evaluations; Floquet multipliers "
                     "of the accepted points: {} right-hand-side evaluations in {} map evaluations\n"
                     "Floquet test functions (BP and PD): {} right-hand-side evaluations in {} map evaluations, {} of "
                     "them for curve points between branch points and the location of their zeros; {} accepted "
                     "points valued from the corrector's last evaluation\n",
                     seconds, exploration.counters().rhs_evaluations, exploration.num_evaluations(),
                     floquet_map.counters().rhs_evaluations, floquet_map.num_evaluations(),
                     tests.counters.rhs_evaluations, tests.evaluations, tests.curve_evaluations, tests.reused_points);
}

// ---- 2. compute, streaming every accepted point; 3. summary, key-frame orbits, report, figures

// The study's own families as the exploration traced them (time-based layout), and what the later stages
// start from.
struct ExploredFamilies {
  BifurcationDiagram diagram;
  // A restart's special point, for the stages that start from special points (period-doubled families,
  // curves); empty otherwise.
  BifurcationDiagram restart_points;
  std::string starts_report;  // where the exploration began, in words
  std::optional<StudyParameterStarts> parameter_starts;  // a study in a free parameter
};

using PointSink = std::function<void(const ProgressInfo& info, const Vector& u_problem)>;
using StageSay = std::function<void(const std::string& stage, const std::string& text)>;

// The exploration of the study's own families: from a restart's point, from the model's start, or (a free
// parameter) from the starts found in it; each accepted point goes to `on_point`, every branch to the writer.
ExploredFamilies ExploreFamilies(const HybridModel& model, const RunSetup& setup, const RestartPlan* restart,
                                 Formulation formulation, ModelExploration& exploration, ResultsWriter& writer,
                                 const PointSink& on_point, const StageSay& say) {
  const ShootingLayout& layout = exploration.shooting().layout();
  ExploredFamilies out;
  BifurcationDiagram& diagram = out.diagram;
  int skipped = 0;  // starts on branches traced from earlier starts
  using Kind = RestartSpec::Kind;
  if (restart != nullptr) {
    writer.Annotate("restarted_from", restart->where);
    out.starts_report = "Restarted from " + restart->description + " (" + ToString(restart->kind) + ")\n";
    say("start", out.starts_report);
    diagram.unknown_names = layout.unknown_names();
    switch (restart->kind) {
      case Kind::kContinue:
        diagram = exploration.RunFromPoint(restart->u, restart->tangent, on_point);
        break;
      case Kind::kSwitch:
        diagram = exploration.RunFromStarts({restart->u}, on_point, &skipped);
        break;
      case Kind::kFree: {
        Vector start(restart->u.size() + layout.num_free_parameters());
        start.head(restart->u.size()) = restart->u;
        for (int i = 0; i < layout.num_free_parameters(); ++i) {
          start(restart->u.size() + i) = model.parameter_value(layout.parameter_model_index(i));
        }
        diagram = exploration.RunFromStarts({start}, on_point, &skipped);
        break;
      }
      case Kind::kPeriodDoubled:
      case Kind::kCurve:
      case Kind::kAuto:
        out.restart_points.unknown_names = layout.unknown_names();
        out.restart_points.special_points = {restart->point};
        break;
    }
  } else if (setup.free.empty()) {
    out.starts_report = exploration.start_report();
    if (!out.starts_report.empty()) {  // how far Newton moved a guess: said now, and in the answer
      say("start", out.starts_report);
      writer.AppendStartNote(out.starts_report);
    }
    diagram = exploration.Run(on_point);
  } else if (model.num_first_integrals() == 0) {  // the family in the parameter from the model's start
    const OrbitStarts starts = FindOrbitStarts(model, setup, layout);
    say("start", starts.report);
    diagram = exploration.RunFromStarts(starts.points, on_point, &skipped);
    if (starts.points.empty()) diagram.message = "no start point: " + OneLine(starts.report);  // why, in the answer
    out.starts_report = starts.report + fmt::format("  {} of them on branches traced from earlier starts\n", skipped);
  } else {
    const ParameterStarts starts = FindParameterStarts(model, setup, exploration.shooting());
    diagram = exploration.RunFromStarts(starts.points, on_point, &skipped);
    if (starts.points.empty()) diagram.message = "no start point: " + OneLine(starts.report);
    out.starts_report = starts.report + fmt::format("  {} of them on branches traced from earlier starts\n", skipped);
    say("start", out.starts_report);
    out.parameter_starts = StudyParameterStarts{starts.crossings, static_cast<int>(starts.points.size()), skipped,
                                                starts.ordinary_branches};
    writer.SetParameterStarts(*out.parameter_starts);
  }
  if (formulation == Formulation::kStateBased) ConvertToTimeBased(exploration, layout, &diagram);
  MarkExtrema(setup.extrema, &diagram);
  for (const Branch& b : diagram.branches) writer.EndBranch(b);
  exploration.ForgetBranchPointAnalyses();  // every point of the exploration has been analysed
  writer.SetExplorationStatus(diagram.status, diagram.message);
  return out;
}

// The stages after the exploration, each until a stop request: the period-doubled families, the families of
// other words, the two-parameter curves. Their special points join `special_points`, their curves the result;
// returns their report sections.
// `doubled`: RepeatedModel(model, 2) where period-doubled families are explored (it must outlive the writer's
// use of their branches), else null.
std::string RunLaterStages(const StudyOptions& options, const HybridModel& model, const HybridModel* doubled,
                           const RunSetup& setup, const RestartPlan* restart, const ExploredFamilies& explored,
                           ResultsWriter& writer,
                           const StudyHooks& hooks, const StageSay& say, std::vector<StudySpecialPoint>* special_points,
                           StudyResult* result) {
  const bool from_pd = restart != nullptr && restart->kind == RestartSpec::Kind::kPeriodDoubled;
  const bool from_curve = restart != nullptr && restart->kind == RestartSpec::Kind::kCurve;
  const auto stopped = [&] { return writer.failed() || (hooks.stop_requested && hooks.stop_requested()); };
  std::string report;
  if (doubled != nullptr && !stopped()) {
    say("period-doubled families", "");
    report += ExplorePeriodDoubledFamilies(model, *doubled, setup, from_pd ? explored.restart_points : explored.diagram,
                                           special_points, writer);
  }
  if (options.follow_word_changes && !stopped()) {
    say("words", "");
    WordRecord words;
    report += ExploreWordChanges(model, setup, explored.diagram, special_points, &words, writer, hooks);
  }
  if (!setup.curve_parameter.empty() && !stopped()) {
    say("curves", "");
    std::vector<StudyCurve> curves;
    std::string curves_report;
    try {
      curves = TraceParameterCurves(model, setup, from_curve ? explored.restart_points : explored.diagram, writer.dir(),
                                    &curves_report);
    } catch (const CurveFileError& e) {  // a curve file that could not be written (a full disk)
      writer.RecordWriteError(e.what());
    }
    if (from_curve && curves.empty()) {
      curves_report += fmt::format("  from {}: not traced (curves start at physical orbits; this one is not)\n",
                                   restart->where.value("label", std::string()));
    }
    writer.SetCurves(setup.curve_parameter, curves);
    report += curves_report;
  }
  // A stop (or a failed write) during these stages: what they did is kept, the study is not complete.
  if (stopped() && result->status == ExplorationStatus::kCompleted) {
    result->status = ExplorationStatus::kCancelled;
    result->message = "stopped after the exploration, before the study's end";
    writer.SetExplorationStatus(result->status, result->message);
  }
  return report;
}

void Compute(const StudyOptions& options, const StudyHooks& hooks, const HybridModel& model, const RunSetup& setup,
             const RestartPlan* restart, ModelExploration& exploration, ResultsWriter& writer, StudyResult* result) {
  const ShootingLayout& layout = exploration.shooting().layout();
  PointStream stream(model, setup, exploration, writer);
  const auto start_time = std::chrono::steady_clock::now();
  // A write that fails (a full disk) stops the run at once: the branches end at their last point, nothing
  // more is computed, and the run says which file could not be written.
  exploration.set_cancel([&writer, &hooks] { return writer.failed() || (hooks.stop_requested && hooks.stop_requested()); });
  const StageSay say = [&](const std::string& stage, const std::string& text) {
    if (hooks.on_progress) hooks.on_progress({stage, writer.next_branch_id(), writer.num_points(), text});
  };
  const ExploredFamilies explored =
      ExploreFamilies(model, setup, restart, options.formulation, exploration, writer,
                      [&](const ProgressInfo& info, const Vector& u_problem) { stream.Add(info, u_problem); }, say);
  const BifurcationDiagram& diagram = explored.diagram;
  result->status = diagram.status;
  result->message = diagram.message;
  result->diagram = std::make_shared<const BifurcationDiagram>(diagram);
  if (writer.failed()) return;  // the failed write is the result's write_error
  std::vector<StudySpecialPoint> special_points = RecordSpecialPoints(diagram, layout, &model, setup.integrator);
  const std::unique_ptr<HybridModel> at_point = setup.free.empty() ? nullptr : std::make_unique<HybridModel>(model.Clone());
  const std::string floquet_report = FloquetReport(diagram, layout, [&](const Vector& u) {
    if (at_point) SetFreeParameters(layout, u, at_point.get());
    return IsPhysical(at_point ? *at_point : model, OrbitPart(layout, u), setup.integrator);
  });
  const bool period_doubling = options.period_doubling || (restart && restart->kind == RestartSpec::Kind::kPeriodDoubled);
  const std::unique_ptr<HybridModel> doubled =
      period_doubling ? std::make_unique<HybridModel>(RepeatedModel(model, 2)) : nullptr;
  const std::string stages = RunLaterStages(options, model, doubled.get(), setup, restart, explored, writer, hooks, say,
                                            &special_points, result);
  writer.SetSpecialPoints(std::move(special_points));
  say("key frames", "");
  WriteKeyframeOrbits(diagram, stream.log(), model, setup, layout, writer);
  const std::string ranges = RangesReport(diagram, setup.scenario, layout, writer);
  const std::string report = RunReport(diagram, explored.starts_report + floquet_report + ranges + stages, start_time,
                                       exploration, stream.floquet_map());
  writer.SetReport(report);
  const TestFunctionWork tests = exploration.test_function_work();
  result->work.rhs_evaluations = exploration.counters().rhs_evaluations;
  result->work.map_evaluations = exploration.num_evaluations();
  result->work.analysis_rhs_evaluations = stream.floquet_map().counters().rhs_evaluations;
  result->work.analysis_map_evaluations = stream.floquet_map().num_evaluations();
  result->work.test_rhs_evaluations = tests.counters.rhs_evaluations;
  result->work.test_map_evaluations = tests.evaluations;
  result->work.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
}

// The exploration of the model; a problem the exploration refuses names --until/--bound when they were given.
std::unique_ptr<ModelExploration> MakeExploration(const StudyOptions& options, const HybridModel& model,
                                                  const RunSetup& setup) {
  try {
    return std::make_unique<ModelExploration>(model, setup.scenario, setup.integrator, setup.exploration,
                                              options.formulation, setup.free, setup.monitors);
  } catch (const std::invalid_argument& e) {
    if (options.until.empty() && options.bounds.empty()) throw;
    throw StudyOptionError(options.until.empty() ? "bounds" : "until", -1, e.what());
  }
}

// The model must keep its first integrals (conservation_check.h): checked at the typical states and at the
// start orbit's states before anything runs; a violation is a modelling error (bad input).
void CheckConservationAtStart(const HybridModel& model, const std::string& argument, const ShootingLayout& layout,
                              const Vector& start) {
  std::vector<std::vector<Vector>> states(model.num_phases());
  for (int i = 0; i < model.num_phases(); ++i) states[i].push_back(model.phase(i).typical_state());
  if (start.size() == layout.num_unknowns()) {
    for (int s = 0; s < layout.num_segments(); ++s) {
      states[s % model.num_phases()].push_back(start.segment(layout.state_offset(s), layout.dim(s)));
    }
  }
  const ConservationReport report = CheckConservation(model, states);
  if (!report.passed()) {
    throw std::invalid_argument("model '" + model.name() + "' does not conserve its energy: " +
                                report.FirstFailure() + " (`hybridcont check " + argument +
                                "` shows every phase and reset)");
  }
}


// A value of an option in the resume key (exact: JSON numbers round-trip).
nlohmann::json OptionValueJson(const StudyOptionValue& value) {
  const auto bound = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return std::visit(
      [&](const auto& v) -> nlohmann::json {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::monostate>) {
          return nullptr;
        } else if constexpr (std::is_same_v<T, std::vector<NamedValue>>) {
          nlohmann::json a = nlohmann::json::array();
          for (const NamedValue& x : v) a.push_back({x.name, x.value});
          return a;
        } else if constexpr (std::is_same_v<T, std::vector<NamedInterval>>) {
          nlohmann::json a = nlohmann::json::array();
          for (const NamedInterval& x : v) a.push_back({x.name, bound(x.lower), bound(x.upper)});
          return a;
        } else {
          return v;
        }
      },
      value);
}

// The resume key: every option whose role is to decide the results (study_options.h), and the model's identity
// (its name, the digest of its text, its parameter values). How and where the study runs (threads, the folder,
// overwrite, resume) is not part of it.
nlohmann::json ResultOptionsJson(const StudyOptions& o, const HybridModel& model, const StudyModelSource& source) {
  nlohmann::json j = nlohmann::json::object();
  for (const StudyOptionSpec& spec : StudyOptionSpecs()) {
    if (spec.role == OptionRole::kResult) j[spec.field] = OptionValueJson(spec.get(o));
  }
  nlohmann::json parameters = nlohmann::json::object();
  for (const ParameterInfo& info : model.parameters()) parameters[info.name] = model.parameter(info.name);
  j["model.name"] = model.name();
  j["model.text_sha256"] = source.sha256;
  j["model.parameters"] = parameters;
  // A study in memory is identified by its document's digest (two in-memory studies are never taken for one).
  if (o.restart && o.restart->study) j["restart.study"] = internal::Sha256Hex(o.restart->study->summary_json);
  return j;
}

// A stream whose every line goes to the hooks' on_note (a model file's compile notes as they are said).
class NoteBuffer : public std::stringbuf {
 public:
  explicit NoteBuffer(const StudyHooks& hooks) : hooks_(hooks) {}
  // A flush without a newline (a note said in parts, "compiling ..." then "done") waits for its line's end.
  int sync() override {
    pending_ += str();
    str("");
    std::size_t end;
    while ((end = pending_.find('\n')) != std::string::npos) {
      std::string line = pending_.substr(0, end);
      if (line.rfind("note: ", 0) == 0) line.erase(0, 6);
      if (hooks_.on_note) hooks_.on_note(line);
      pending_.erase(0, end + 1);
    }
    return 0;
  }

 private:
  const StudyHooks& hooks_;
  std::string pending_;  // the start of a line not yet ended
};

// A study checked against its model, ready to run: nothing computed or written yet.
struct PreparedStudy {
  std::unique_ptr<HybridModel> model;
  RunSetup setup;
  std::unique_ptr<ModelExploration> exploration;
  std::unique_ptr<FamilyGuide> guide;  // options.families_of: prunes the exploration's half-branches
  StudyModelSource source;             // which model it is (recorded in the result)
  std::string start_note;              // how the start was found, where the model's own did not do (StudyResult)
};

// `given`: the caller's model (copied; options.model and models_directory are then not read).
// The study's model: the caller's (copied), made of options.model_text, or options.model (a built-in model or
// a model file) at options.parameters; *source says which (study.h, StudyModelSource).
std::unique_ptr<HybridModel> BuildModel(const StudyOptions& options, const HybridModel* given, std::ostream& log,
                                        StudyModelSource* source) {
  if (options.model.empty() && options.model_text.empty() && given == nullptr) {
    throw StudyOptionError("model", -1, "'': name a built-in model or a model file");
  }
  std::unique_ptr<HybridModel> model;
  if (given == nullptr && options.model_text.empty()) {
    return std::make_unique<HybridModel>(MakeStudyModel(options.model, options.parameters, options.models_directory,
                                                        &log, /*compile=*/true, source));
  }
  if (given != nullptr) {
    model = std::make_unique<HybridModel>(given->Clone());
  } else {
    ModelFileOptions file_options;
    file_options.log = &log;
    model = std::make_unique<HybridModel>(LoadModelText(
        options.model_text, "<" + (options.model.empty() ? "model text" : options.model) + ">", file_options));
  }
  *source = options.model_text.empty()
                ? StudyModelSource{StudyModelSource::Kind::kCaller, model->name(), "", "", ""}
                : StudyModelSource{StudyModelSource::Kind::kText, model->name(), "",
                                   internal::Sha256Hex(options.model_text), options.model_text};
  // A caller's model made from a built-in model or a model file (options.model names it: Python's
  // hc.model("slip")) is recorded as that source when it is that model, so that its folder rebuilds it.
  if (given != nullptr && options.model_text.empty() && !options.model.empty()) {
    StudyModelSource made;
    try {
      const HybridModel from = MakeStudyModel(options.model, {}, options.models_directory, nullptr,
                                              /*compile=*/false, &made);
      if (from.name() == model->name() && from.num_phases() == model->num_phases()) *source = made;
    } catch (const std::invalid_argument&) {
      // Not a name or file the library can make: the caller's own model.
    }
  }
  SetStudyParameters(options.parameters, model.get());
  return model;
}

// Whether two folder names name the same folder (neither need exist).
bool SameFolder(const std::string& a, const std::string& b) {
  std::error_code ec_a, ec_b;
  const std::filesystem::path x = std::filesystem::weakly_canonical(a, ec_a), y = std::filesystem::weakly_canonical(b, ec_b);
  return !ec_a && !ec_b && x == y;
}

// A study never writes over a study it reads: the folder restarted from, the one whose families guide it.
void CheckFoldersRead(const StudyOptions& options) {
  if (options.out_dir.empty()) return;
  const auto refuse = [&](const std::string& field) {
    throw StudyOptionError("out_dir", -1, "'" + options.out_dir + "': is the study read by " + MentionOption(field) +
                           ", which this one would replace; name another folder for its results");
  };
  if (options.restart && !options.restart->study && SameFolder(options.restart->from, options.out_dir)) {
    refuse("restart.from");
  }
  if (!options.families_of.empty() && SameFolder(options.families_of, options.out_dir)) refuse("families_of");
}

// Options that contradict each other, whatever the model.
void CheckOptionPairs(const StudyOptions& options) {
  CheckFoldersRead(options);
  if (options.resume && options.out_dir.empty()) {
    throw StudyOptionError("resume", -1, ": needs the results folder to resume in (" + MentionOption("out_dir") + ")");
  }
  if (!options.free.empty() && options.formulation == Formulation::kStateBased) {
    throw StudyOptionError("formulation", -1, "state: " + MentionOption("free") + " '" + options.free +
                           "' needs the time-based formulation (the state-based map has no free parameters)");
  }
  if (!options.monitors.empty() && options.formulation == Formulation::kStateBased) {
    throw StudyOptionError("monitors", -1, "needs the time-based formulation");
  }
  if (!options.free.empty() && options.period_doubling) {
    throw StudyOptionError("period_doubling", -1, ": not with " + MentionOption("free") + " '" + options.free + "'");
  }
  if (options.restart && !options.restart->study) {
    // The parts of a restart go together (--from FOLDER --at LABEL [--as KIND]).
    const RestartSpec& r = *options.restart;
    if (r.from.empty() && r.label.empty()) {
      throw StudyOptionError("restart.kind", -1, "'" + ToString(r.kind) + "': needs " + MentionOption("restart.from") +
                             " FOLDER " + MentionOption("restart.label") + " LABEL");
    }
    if (r.from.empty()) {
      throw StudyOptionError("restart.label", -1, "'" + r.label + "': needs " + MentionOption("restart.from") +
                             " FOLDER (a saved study)");
    }
    if (r.label.empty()) {
      throw StudyOptionError("restart.from", -1, "'" + r.from + "': needs " + MentionOption("restart.label") +
                             " LABEL (e.g. PD4, B5)");
    }
  }
  if (!options.families.empty() && options.families_of.empty()) {
    throw StudyOptionError("families", 0, "'" + options.families[0] + "': needs the saved study whose families are "
                           "continued (" + MentionOption("families_of") + ")");
  }
}

// An automaton's starts in other words take transitions the file's word may not: their words are checked too,
// at their typical states and their starts; and every transition that none of these words takes, which only a
// change of the phase sequence would reach, on a word through it at the typical states.
void CheckAutomatonWords(const HybridModel& model, const std::string& argument) {
  if (model.automaton() == nullptr) return;
  std::vector<Word> checked = {model.word()};
  for (const StartSpec& start : model.setup().word_starts) {
    const HybridModel word_model = WordModelAt(model, start.word);
    CheckConservationAtStart(word_model, argument, ShootingLayout(word_model), StartPoint(word_model, start));
    checked.push_back(start.word);
  }
  const HybridAutomaton& automaton = *model.automaton();
  for (const Word& word : WordsThroughEveryTransition(automaton, checked)) {
    const HybridModel word_model = WordModelAt(model, word);
    try {
      CheckConservationAtStart(word_model, argument, ShootingLayout(word_model), Vector());
    } catch (const std::invalid_argument& e) {
      // Named by the transitions that brought the word in: those no start's word takes.
      std::string transitions;
      for (const int k : TransitionsOf(word)) {
        const bool taken = std::any_of(checked.begin(), checked.end(), [k](const Word& w) {
          return std::find(w.begin(), w.end(), k) != w.end();
        });
        if (!taken) transitions += (transitions.empty() ? "'" : ", '") + automaton.transitions()[k].name + "'";
      }
      throw std::invalid_argument("transition " + transitions + ", which a change of the phase sequence may take " +
                                  "(checked on the word " + automaton.WordName(word) + "): " + e.what());
    }
  }
}

// options.families_of: the saved study's families guide the exploration (family_guide.h).
void AttachGuide(const StudyOptions& options, PreparedStudy* p) {
  const auto refuse = [&](const std::string& why) {
    throw StudyOptionError("families_of", -1, "'" + options.families_of + "': " + why);
  };
  if (options.restart) refuse("not with a restart (a restart traces from its point; families_of from the model's start)");
  if (!options.free.empty()) refuse("not with " + MentionOption("free") + " '" + options.free + "'");
  if (options.formulation != Formulation::kTimeBased) refuse("needs the time-based formulation");
  p->guide = std::make_unique<FamilyGuide>(FamilyGuide::Load(options.families_of, *p->model,
                                                             p->exploration->shooting().layout(), options.families,
                                                             OptionsJson(options, p->setup)));
  p->exploration->set_ray_filter([guide = p->guide.get(), exploration = p->exploration.get()](const Vector& u,
                                                                                             const Vector& v) {
    return guide->Prune(u, v, exploration->unknown_scales());
  });
}

// At parameters the user set (options.parameters) the start is carried there from the model's own values
// (start_carry.h): Newton from the file's guess at other values may fail, or converge to another family's
// orbit. True when that settled the start: carried, or (the carry failing) Newton's own start at the values set
// kept with a note, or the study's status set to a failed start (a numerical outcome at valid parameters,
// never bad input). False where the start fails at the model's own values too: the ordinary check then speaks.
bool CarryToSetValues(const StudyOptions& options, const StudyHooks& hooks, bool converged, const std::string& why,
                      PreparedStudy* p) {
  const HybridModel& model = *p->model;
  HybridModel own = model.Clone();
  for (const NamedValue& v : p->setup.own_parameters) own.SetParameter(v.name, v.value);
  StudyOptions own_options = options;
  own_options.parameters.clear();
  const RunSetup own_setup = MakeRunSetup(own_options, own);
  const std::unique_ptr<ModelExploration> at_own = MakeExploration(own_options, own, own_setup);
  std::string own_why;
  if (!at_own->PrepareStart(&own_why) || !IsPhysical(own, at_own->prepared_start(), p->setup.integrator)) return false;
  const CarriedStart carried = CarryStart(model, p->setup.own_parameters, at_own->prepared_start(),
                                          p->setup.integrator, {p->setup.free, LevelBound(p->setup, ShootingLayout(model, p->setup.free).continued_name())});
  const auto note = [&](const std::string& text) {
    p->start_note = text;
    if (hooks.on_note) hooks.on_note(text);
  };
  if (carried.ok) {  // said as the start's report while the study runs, and in its answer
    p->exploration->SetStart(carried.u, carried.report + "\n");
    p->start_note = carried.report;
    return true;
  }
  if (converged && IsPhysical(model, p->exploration->prepared_start(), p->setup.integrator)) {
    note(carried.why + "; the study starts from the orbit Newton finds from the model's start at the values set, "
         "which need not be of the same family");
    return true;
  }
  std::string first = converged ? std::string("the start converges to an orbit that is not physical")
                                : why.substr(0, why.find('\n'));
  while (!first.empty() && (first.back() == ':' || first.back() == ' ')) first.pop_back();
  p->exploration->SetStartFailure(first + "; " + carried.why);
  if (hooks.on_note) hooks.on_note(first + "; " + carried.why);
  return true;
}

// The ordinary run's start, checked (a guess corrected) before anything is written: a start that is not an
// orbit is an error of the model's input, said per part of the cycle that does not close (or, where a start
// may fail, a note and the study's status). At parameters the user set, a guess or a simulated start is
// carried there (CarryToSetValues).
void CheckStart(const StudyOptions& options, const StudyHooks& hooks, PreparedStudy* p) {
  const HybridModel& model = *p->model;
  if (!p->setup.free.empty() || model.num_first_integrals() == 0 || options.restart) return;
  std::string why;
  const bool converged = p->exploration->PrepareStart(&why);
  const StartSpec::Kind kind = model.setup().start.kind;
  const bool carried_kind = kind == StartSpec::Kind::kGuess || kind == StartSpec::Kind::kSimulation;
  if (!p->setup.own_parameters.empty() && carried_kind && CarryToSetValues(options, hooks, converged, why, p)) return;
  if (converged) return;
  SourceLocation where = model.setup().start.where;
  if (where.field.empty()) where.field = "start";
  if (options.start_must_converge) throw ModelInputError(where, why);
  if (hooks.on_note) {
    const std::string message = ModelInputError(where, why).what();
    hooks.on_note(message.substr(0, message.find('\n')) + " (the study goes on without it)");
  }
}

PreparedStudy Prepare(const StudyOptions& options, const StudyHooks& hooks, const HybridModel* given = nullptr) {
  PreparedStudy p;
  {
    NoteBuffer notes(hooks);
    std::ostream log(&notes);
    p.model = BuildModel(options, given, log, &p.source);
    log.flush();
  }
  const HybridModel& model = *p.model;
  CheckOptionPairs(options);
  p.setup = MakeRunSetup(options, model);
  // What the study will not do that the options ask for implicitly: said before it runs.
  if (options.follow_word_changes) {
    if (const std::string why = WordsNotFollowed(model, p.setup); !why.empty() && options.free.empty()) {
      p.setup.notes.push_back("the automaton's other words are not followed: " + why);
    }
  }
  // The model's own values of the parameters set (start_carry.h): the caller's model's, or those its file or
  // built-in declares.
  for (const NamedValue& set : options.parameters) {
    double own = 0;
    if (given != nullptr) {
      own = given->parameter(set.name);
    } else {
      for (const ParameterInfo& info : model.parameters()) {
        if (info.name == set.name) own = info.default_value;
      }
    }
    p.setup.own_parameters.push_back({set.name, own});
  }
  // The period-doubled families' model is drawn too: its presentation is checked before anything runs.
  if (options.period_doubling) OrbitPresentation(RepeatedModel(model, 2), p.setup.free);
  p.exploration = MakeExploration(options, model, p.setup);
  CheckConservationAtStart(model, options.model, p.exploration->shooting().layout(), p.setup.scenario.start);
  CheckAutomatonWords(model, options.model);
  if (!options.families_of.empty()) AttachGuide(options, &p);
  CheckStart(options, hooks, &p);
  return p;
}

}  // namespace

// The study of options.model, or of *given_model when not null (RunStudy).
StudyResult Run(const StudyOptions& options, const StudyHooks& hooks, const HybridModel* given_model);

}  // namespace hybridcont::study

namespace hybridcont {

std::string Version() { return HYBRIDCONT_VERSION; }

std::string BranchFileName(int id) { return "branch-" + std::to_string(id) + ".csv"; }

const StudySpecialPoint* StudyResult::FindSpecialPoint(const std::string& label) const {
  for (const StudySpecialPoint& p : special_points) {
    if (p.Label() == label) return &p;
  }
  return nullptr;
}

const StudyBranch& StudyResult::branch(int id) const {
  if (id < 0 || id >= static_cast<int>(branches.size())) {
    throw std::out_of_range("StudyResult::branch(" + std::to_string(id) + "): the study has " +
                            std::to_string(branches.size()) + " branches");
  }
  return branches[id];
}

std::vector<std::string> CheckStudyOptions(const StudyOptions& options,
                                           const std::function<std::string(const std::string&)>& words) {
  const study::PreparedStudy p = study::Prepare(options, {});
  std::vector<std::string> notes;
  for (const std::string& note : p.setup.notes) notes.push_back(SayOptions(note, words));
  return notes;
}

StudyResult RunStudy(const StudyOptions& options, const StudyHooks& hooks) {
  return study::Run(options, hooks, nullptr);
}

StudyResult RunStudy(const HybridModel& model, const StudyOptions& options, const StudyHooks& hooks) {
  return study::Run(options, hooks, &model);
}

}  // namespace hybridcont

namespace hybridcont::study {

StudyResult Run(const StudyOptions& given, const StudyHooks& hooks, const HybridModel* given_model) {
  StudyOptions options = given;
  // A restart in a free parameter from an orbit holds its H unless told otherwise.
  if (options.restart && !options.free.empty() && !options.fix &&
      (options.restart->kind == RestartSpec::Kind::kAuto || options.restart->kind == RestartSpec::Kind::kFree)) {
    const double level = RestartLevel(*options.restart);
    if (std::isfinite(level)) options.fix = NamedValue{"H", level};
  }
  PreparedStudy p = Prepare(options, hooks, given_model);
  const HybridModel& model = *p.model;
  std::optional<RestartPlan> restart;
  if (options.restart) restart = PlanRestart(*options.restart, options, model);
  for (const std::string& note : p.setup.notes) {
    if (hooks.on_note) hooks.on_note(SayOptions(note, hooks.option_words));
  }
  const nlohmann::json options_json = OptionsJson(options, p.setup);
  const std::filesystem::path dir = options.out_dir;
  if (!dir.empty()) ResultsWriter::PrepareDirectory(dir, model.name(), options.overwrite);
  // An interrupted study's branches (resume_store.h): checked before anything is written.
  std::unique_ptr<ResumeStore> store;
  if (!dir.empty()) {
    try {
      store = std::make_unique<ResumeStore>(dir, ResultOptionsJson(options, model, p.source), options.resume);
    } catch (const std::invalid_argument& e) {
      throw StudyOptionError("resume", -1, e.what());
    }
    p.exploration->set_branch_store(store.get());
  }
  ResultsWriter writer(dir, model, options_json, p.source, p.setup.free, &hooks);
  writer.SetStartNote(p.start_note);
  writer.set_resume_store(store.get());
  // Every exploration of the study (the period-doubled and word families', the starts' of a free parameter)
  // stops at a stop request or a failed write.
  const auto cancel = [&writer, &hooks] { return writer.failed() || (hooks.stop_requested && hooks.stop_requested()); };
  p.setup.exploration.continuation.cancel = cancel;
  p.setup.seed_exploration.continuation.cancel = cancel;
  StudyResult result;
  try {
    Compute(options, hooks, model, p.setup, restart ? &*restart : nullptr, *p.exploration, writer, &result);
  } catch (const std::exception& e) {
    // The folder must not look complete: the summary says "failed" (or, if it cannot be written, the last
    // one written says "running").
    writer.Fail(e.what());
    throw;
  }
  if (p.guide) {
    std::vector<Vector> switch_points;
    for (const SpecialPoint& sp : result.diagram->special_points) switch_points.push_back(sp.u);
    const nlohmann::json guided = p.guide->Json(switch_points);
    writer.Annotate("guided", guided);
    if (hooks.on_note) {
      hooks.on_note(fmt::format("families of {}: {} half-branches not traced (their counterparts there led to no "
                                "family{}; {} of its {} half-branches did)",
                                options.families_of, guided["pruned_half_branches"].get<int>(),
                                options.families.empty() ? "" : " continued", guided["rays_to_families"].get<int>(),
                                guided["rays"].get<int>()));
    }
  }
  // A stopped study ends its folder as "cancelled": whole, but not the whole study (--resume completes it).
  if (!writer.Finish(result.status == ExplorationStatus::kCancelled)) writer.Fail(writer.write_error());  // a full disk: the folder is marked incomplete
  const bool complete = writer.write_error().empty() && result.status != ExplorationStatus::kCancelled;
  if (store) {
    result.work.resumed_branches = store->used();
    if (complete) store->Complete();  // nothing left to resume
  }
  // The record the stages filled is the result; the folder holds its serialization.
  StudyResult typed = writer.Record();
  typed.status = result.status;
  typed.message = result.message;
  typed.work = result.work;
  typed.diagram = std::move(result.diagram);
  typed.write_error = writer.write_error();
  return typed;
}

}  // namespace hybridcont::study
