// `hybridcont run MODEL ...`: the complete bifurcation diagram of a built-in model, as data and figures.
//
// Order of work, so that bad input writes nothing: parse and validate every option, build the model,
// validate the exploration options against the problem, prepare the output folder; only then compute.
// Points are classified (physical or why not) and streamed to branch-<id>.csv as they are accepted (with
// --threads > 1: branch by branch as the exploration merges them, in the order of --threads 1).
//
// The command's steps live in files of their own: run_setup.h (options -> validated set-up),
// orbit_analysis.h (each accepted point), summary_json.h (the
// options and special points in summary.json), figure_script.h (the figures).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>

#include "commands.h"
#include "family_report.h"
#include "figure_script.h"
#include "hybridcont/automaton_words.h"
#include "hybridcont/conservation_check.h"
#include "hybridcont/exploration.h"
#include "hybridcont/period_doubling.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/timebased_shooting.h"
#include "model_exploration.h"
#include "model_options.h"
#include "orbit_analysis.h"
#include "parameter_curves.h"
#include "orbit_start.h"
#include "parameter_starts.h"
#include "period_doubled_families.h"
#include "word_families.h"
#include "results_writer.h"
#include "run_setup.h"
#include "scenario.h"
#include "summary_json.h"

namespace hybridcont::app {

namespace fs = std::filesystem;

CLI::Option* NonEmpty(CLI::Option* option) {
  return option->check(CLI::Validator(
      [](const std::string& text) { return text.empty() ? std::string("an empty value is not allowed") : std::string(); },
      "", "non-empty"));
}

void AddRunOptions(CLI::App* run, RunArguments* args) {
  NonEmpty(run->add_option("model", args->model, "built-in model name (see `hybridcont list`) or model file (.toml)")
               ->required());
  NonEmpty(run->add_option("--set", args->assignments, "override a model parameter, NAME=VALUE (repeatable)"));
  NonEmpty(run->add_option("--until", args->until,
                           "end every branch exactly where an unknown or an observable of the model reaches a value, "
                           "NAME=VALUE, e.g. H=2 or speed=1 (repeatable)"));
  NonEmpty(run->add_option("--monitor", args->monitors,
                           "locate the points where an observable of the model reaches a value, NAME=VALUE, e.g. "
                           "speed=0.5 (repeatable; special points UZ)"));
  NonEmpty(run->add_option("--bound", args->bounds,
                           "replace the model's bound on an unknown, NAME=LOWER:UPPER (e.g. H=0:2.7; 'period' is the "
                           "sum of the durations; an empty end is unbounded) (repeatable)"));
  NonEmpty(run->add_option("--out", args->out_dir, "results folder (default results/MODEL)"));
  NonEmpty(run->add_option("--rtol", args->rtol, "integrator relative tolerance (default 1e-10)"));
  NonEmpty(run->add_option("--atol", args->atol, "integrator absolute tolerance (default 1e-10)"));
  NonEmpty(run->add_option("--max-branches", args->max_branches, "maximum number of half-branches traced"));
  NonEmpty(run->add_option("--threads", args->threads,
                           "threads tracing half-branches concurrently (default: the machine's cores; 1 = one after "
                           "the other); the results do not depend on it"));
  NonEmpty(run->add_option("--formulation", args->formulation,
                           "time (default: time-based multiple shooting) or state (event-driven Poincare map)"));
  NonEmpty(run->add_option("--free", args->free,
                           "continue the families in a model parameter instead of H, e.g. k (needs --fix)"));
  NonEmpty(run->add_option("--fix", args->fix,
                           "the unknown held fixed while --free varies, NAME=VALUE: H=1.5, a state x2_dx=0.8, a "
                           "duration t2=0 (where that phase vanishes) or an observable speed=1; starts are the physical families' crossings "
                           "of that value in the ordinary run"));
  NonEmpty(run->add_option("--curves", args->curves,
                           "after the run, continue every turning and SB point of the physical families in (H, "
                           "PARAMETER), e.g. w2 (bounds: --bound PARAMETER=LO:HI)"));
  run->add_flag("--no-symmetry", args->no_symmetry,
               "trace every half-branch, also those that are images of traced ones under the model's symmetries");
  run->add_flag("--overwrite", args->overwrite,
                "replace the results of another model in --out (without it such a folder is refused)");
  run->add_flag("--period-doubling", args->period_doubling,
                "explore the period-doubled family of every located PD point (the phase sequence traversed twice)");
  run->add_flag("--one-word", args->one_word,
                "a model given as an automaton: follow the start's phase sequence only, not the words its families "
                "lead into where a phase vanishes or a competing guard is touched");
  run->add_flag("--quiet", args->quiet, "no progress lines");
  run->add_flag("--no-plots", args->no_plots, "do not draw figures");
}

namespace {

// The physicality of the accepted points, per branch id and in the order of the points (false where a point
// could not be converted to the time-based layout).
struct PointLog {
  std::map<int, std::vector<bool>> physical;
};

// The exploration's point callback: converts each accepted point to the time-based layout (which every
// output uses, whatever the formulation), analyses it (orbit_analysis.h), streams it to its branch file
// and prints a progress line.
class PointStream {
 public:
  PointStream(const RunArguments& args, const HybridModel& model, const RunSetup& setup, ModelExploration& exploration,
              ResultsWriter& writer, std::ostream& out)
      : args_(args), model_(model), setup_(setup), exploration_(exploration), writer_(writer), out_(out),
        floquet_map_(model, setup.integrator, setup.free), replay_options_(ReplayOptionsFor(setup.integrator)),
        point_model_(setup.free.empty() ? nullptr : std::make_unique<HybridModel>(model.Clone())) {}

  void Add(const ProgressInfo& info, const Vector& u_problem) {
    Vector u;
    if (!exploration_.ToTimeBased(u_problem, &u).ok) {
      log_.physical[info.branch_id].push_back(false);  // keep per-point alignment

      return;
    }
    PointRecord record = RecordOf(info, u);
    if (point_model_) SetFreeParameters(floquet_map_.layout(), u, point_model_.get());
    AnalyzePoint(point_model_ ? *point_model_ : model_, setup_.integrator, floquet_map_, replay_options_, &record);
    writer_.AddPoint(info.branch_id, record);
    log_.physical[info.branch_id].push_back(record.classification.physical);

    if (!args_.quiet) PrintProgress(info, record);
  }

  const PointLog& log() const { return log_; }
  // One map for residuals and Floquet data, separate from the engine's (whose cache stays intact).
  TimeBasedShooting& floquet_map() { return floquet_map_; }

 private:
  void PrintProgress(const ProgressInfo& info, const PointRecord& record) {
    const ShootingLayout& layout = exploration_.shooting().layout();
    if (info.branch_id != current_branch_) {
      out_ << fmt::format("branch {}\n", info.branch_id);
      current_branch_ = info.branch_id;
    }
    const int x = layout.continued_index();
    out_ << fmt::format("  b{:<3} #{:<4} {} = {:<12.8f} T = {:<12.8f} step {:<9.3g} newton {}  {}\n", info.branch_id,
                        info.point_index, layout.unknown_names()[x], record.u(x), layout.Period(record.u), info.step,
                        info.newton_iterations, ToString(record.classification.reason));
  }

  const RunArguments& args_;
  const HybridModel& model_;
  const RunSetup& setup_;
  ModelExploration& exploration_;
  ResultsWriter& writer_;
  std::ostream& out_;
  TimeBasedShooting floquet_map_;
  const ReplayOptions replay_options_;
  std::unique_ptr<HybridModel> point_model_;  // with free parameters: the model at the point's values
  PointLog log_;
  int current_branch_ = -1;
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
    writer.AddOrbit(trace, c.branch, c.point, layout.has_level() ? u(layout.H_index()) : std::nan(""),
                    layout.Period(u), c.family);
  }
}

// Per branch with physical orbits: its family, where its orbits are physical and where stable, in the
// continued coordinate, each end from the special point located there (family_report.h).
std::string RangesReport(const BifurcationDiagram& diagram, const Scenario& sc, const ShootingLayout& layout,
                         ResultsWriter& writer) {
  std::string report = fmt::format("Physical families (where their orbits are physical and where stable, in {}):\n",
                                   layout.continued_name());
  std::string families;
  for (const Branch& b : diagram.branches) families += BranchRangesReport(b, layout, sc.describe, writer);
  return report + (families.empty() ? "  none\n" : families);
}

// The Floquet crossings among the diagram's special points (located by the exploration as test functions,
// floquet_test_functions.h), one line each, BP before PD.
std::string FloquetReport(const BifurcationDiagram& diagram, const ShootingLayout& layout) {
  std::string report =
      "Floquet and observable special points (multiplier crossings on physical orbits; grazing events; constraint "
      "boundaries; monitored values):\n";
  int count = 0;
  for (const SpecialPointType type : {SpecialPointType::kFloquetBranchPoint, SpecialPointType::kPeriodDoubling,
                                      SpecialPointType::kGrazing, SpecialPointType::kNeimarkSacker,
                                      SpecialPointType::kKreinCollision, SpecialPointType::kConstraintBoundary,
                                      SpecialPointType::kObservableValue}) {
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
      report += fmt::format("  {} on branch {} after point {}: {} = {:.12f}, T = {:.12f} ({}, precision {:.1e}){}\n", code,
                            sp.branch_id, sp.index, layout.continued_name(), sp.u(layout.continued_index()),
                            layout.Period(sp.u), ToString(sp.status), precision,
                            sp.message.empty() ? "" : " " + sp.message);
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
                     "them for curve points between branch points and the location of their zeros\n",
                     seconds, exploration.counters().rhs_evaluations, exploration.num_evaluations(),
                     floquet_map.counters().rhs_evaluations, floquet_map.num_evaluations(),
                     tests.counters.rhs_evaluations, tests.evaluations, tests.curve_evaluations);
}

// Completes summary.json and draws the figures; the exit code of the run.
int FinishAndDraw(const RunArguments& args, const BifurcationDiagram& diagram, ResultsWriter& writer,
                  std::ostream& out, std::ostream& err) {
  const fs::path& dir = writer.dir();
  if (!writer.Finish()) {
    // A full disk (or a folder removed under us): what could be written stays, marked as not complete.
    const std::string why = writer.write_error();
    writer.Fail(why);
    err << "error: " << why << "; the results in " << dir.string()
        << "/ are incomplete (summary.json, if present, says status 'running' or 'failed')\n";
    return 1;
  }
  out << fmt::format("results written to {}/ (summary.json, branch-*.csv, orbit-*.csv)\n", dir.string());
  if (diagram.status == ExplorationStatus::kStartFailed) {
    err << "error: no family was traced: " << diagram.message << "\n";
    return 1;  // nothing to draw
  }
  if (!args.no_plots && DrawFigures(dir, err, false) == 0) out << fmt::format("figures written to {}/\n", dir.string());
  return 0;
}

// ---- 2. compute, streaming every accepted point; 3. summary, key-frame orbits, report, figures
int ComputeAndWrite(const RunArguments& args, const HybridModel& model, Formulation formulation,
                    const RunSetup& setup, ModelExploration& exploration, ResultsWriter& writer, std::ostream& out,
                    std::ostream& err) {
  const ShootingLayout& layout = exploration.shooting().layout();
  PointStream stream(args, model, setup, exploration, writer, out);
  const auto start_time = std::chrono::steady_clock::now();
  const auto on_point = [&](const ProgressInfo& info, const Vector& u_problem) { stream.Add(info, u_problem); };
  std::string starts_report;
  BifurcationDiagram diagram;
  // A write that fails (a full disk) stops the run at once: the branches end at their last point, nothing
  // more is computed, and the run says which file could not be written.
  exploration.set_cancel([&writer] { return writer.failed(); });
  if (setup.free.empty()) {
    starts_report = exploration.start_report();
    if (!args.quiet) out << starts_report;  // how far Newton moved a guess
    diagram = exploration.Run(on_point);
  } else if (model.num_first_integrals() == 0) {  // the family in the parameter from the model's start
    const OrbitStarts starts = FindOrbitStarts(model, setup, layout);
    int skipped = 0;
    if (!args.quiet) out << starts.report;
    diagram = exploration.RunFromStarts(starts.points, on_point, &skipped);
    starts_report = starts.report + fmt::format("  {} of them on branches traced from earlier starts\n", skipped);
  } else {
    const ParameterStarts starts = FindParameterStarts(model, setup, exploration.shooting());
    int skipped = 0;
    diagram = exploration.RunFromStarts(starts.points, on_point, &skipped);
    starts_report = starts.report + fmt::format("  {} of them on branches traced from earlier starts\n", skipped);
    if (!args.quiet) out << starts_report;
    writer.Annotate("starts", {{"crossings", starts.crossings},
                               {"distinct", starts.points.size()},
                               {"on_traced_branches", skipped},
                               {"ordinary_half_branches", starts.ordinary_branches}});
  }
  if (formulation == Formulation::kStateBased) ConvertToTimeBased(exploration, layout, &diagram);
  for (const Branch& b : diagram.branches) writer.EndBranch(b);
  if (writer.failed()) return FinishAndDraw(args, diagram, writer, out, err);  // reports the failed write
  nlohmann::json special_points = SpecialPointsJson(diagram, layout, &model, setup.integrator);
  const std::string floquet_report = FloquetReport(diagram, layout);
  std::string period_doubled;
  const std::unique_ptr<HybridModel> doubled =
      args.period_doubling ? std::make_unique<HybridModel>(RepeatedModel(model, 2)) : nullptr;
  if (doubled) {
    period_doubled = ExplorePeriodDoubledFamilies(model, *doubled, setup, diagram, &special_points, writer, out, args.quiet);
  }
  const std::string words = args.one_word ? "" : ExploreWordChanges(model, setup, diagram, &special_points, writer, out, args.quiet);
  std::string curves_report;
  if (!setup.curve_parameter.empty()) {
    writer.Annotate("curves", TraceParameterCurves(model, setup, diagram, writer.dir(), &curves_report));
  }
  writer.SetSpecialPoints(special_points);
  WriteKeyframeOrbits(diagram, stream.log(), model, setup, layout, writer);
  const std::string ranges = RangesReport(diagram, setup.scenario, layout, writer);
  const std::string report =
      RunReport(diagram, starts_report + floquet_report + ranges + period_doubled + words + curves_report, start_time,
                exploration, stream.floquet_map());
  writer.SetReport(report);
  out << report;
  return FinishAndDraw(args, diagram, writer, out, err);
}

Formulation ParseFormulation(const std::string& text) {
  Formulation formulation;
  if (!FromString(text, &formulation)) {
    throw std::invalid_argument("--formulation '" + text + "': expected 'time' or 'state'");
  }
  return formulation;
}

// The exploration of the model; a problem the exploration refuses names --until/--bound when they were given.
std::unique_ptr<ModelExploration> MakeExploration(const RunArguments& args, const HybridModel& model,
                                                  const RunSetup& setup, Formulation formulation) {
  try {
    return std::make_unique<ModelExploration>(model, setup.scenario, setup.integrator, setup.exploration, formulation,
                                              setup.free, setup.monitors);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(args.until.empty() && args.bounds.empty() ? "" : "--until/--bound: ") +
                                e.what());
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

}  // namespace

int RunCommand(const RunArguments& args, std::ostream& out, std::ostream& err) {
  // ---- 1. validate all input before anything is written
  HybridModel model = MakeModelWithOverrides(args.model, args.assignments, &err);
  const Formulation formulation = ParseFormulation(args.formulation);
  if (!args.free.empty() && formulation == Formulation::kStateBased) {
    throw std::invalid_argument("--formulation state: --free '" + args.free +
                                "' needs the time-based formulation (the state-based map has no free parameters)");
  }
  if (!args.monitors.empty() && formulation == Formulation::kStateBased) {
    throw std::invalid_argument("--monitor: needs the time-based formulation");
  }
  if (!args.free.empty() && args.period_doubling) {
    throw std::invalid_argument("--period-doubling: not with --free '" + args.free + "'");
  }
  const RunSetup setup = MakeRunSetup(args, model);
  for (const std::string& note : setup.notes) err << "note: " << note << "\n";
  const nlohmann::json options_json = OptionsJson(args, setup);
  const std::unique_ptr<ModelExploration> exploration = MakeExploration(args, model, setup, formulation);
  CheckConservationAtStart(model, args.model, exploration->shooting().layout(), setup.scenario.start);
  // An automaton's starts in other words take transitions the file's word may not: their words are checked
  // too, at their typical states and their starts; and every transition that none of these words takes, which
  // only a change of the phase sequence would reach, on a word through it at the typical states.
  if (model.automaton() != nullptr) {
    std::vector<Word> checked = {model.word()};
    for (const StartSpec& start : model.setup().word_starts) {
      const HybridModel word_model = WordModelAt(model, start.word);
      CheckConservationAtStart(word_model, args.model, ShootingLayout(word_model), StartPoint(word_model, start));
      checked.push_back(start.word);
    }
    const HybridAutomaton& automaton = *model.automaton();
    for (const Word& word : WordsThroughEveryTransition(automaton, checked)) {
      const HybridModel word_model = WordModelAt(model, word);
      try {
        CheckConservationAtStart(word_model, args.model, ShootingLayout(word_model), Vector());
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
  // The ordinary run's start, checked (a guess corrected) before anything is written: a start that is not an
  // orbit is an error of the model's input, said per part of the cycle that does not close.
  if (setup.free.empty() && model.num_first_integrals() > 0) {
    std::string why;
    if (!exploration->PrepareStart(&why)) {
      SourceLocation where = model.setup().start.where;
      if (where.field.empty()) where.field = "start";
      throw ModelInputError(where, why);
    }
  }
  const fs::path dir = args.out_dir.empty() ? fs::path("results") / model.name() : fs::path(args.out_dir);
  ResultsWriter::PrepareDirectory(dir, model.name(), args.overwrite);

  ResultsWriter writer(dir, model, options_json, setup.free);
  try {
    return ComputeAndWrite(args, model, formulation, setup, *exploration, writer, out, err);
  } catch (const std::exception& e) {
    // The folder must not look complete: the summary says "failed" (or, if it cannot be written, the last
    // one written says "running").
    writer.Fail(e.what());
    throw;
  }
}

int PlotCommand(const std::string& dir, std::ostream& out, std::ostream& err) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw std::invalid_argument("plot '" + dir + "': no such folder");
  if (!fs::is_directory(dir, ec)) throw std::invalid_argument("plot '" + dir + "': not a folder");
  if (!fs::exists(fs::path(dir) / "summary.json", ec)) {
    throw std::invalid_argument("plot '" + dir + "': no summary.json (run `hybridcont run MODEL --out " + dir + "` first)");
  }
  const int rc = DrawFigures(dir, err, true);
  if (rc == 0) out << "figures written to " << dir << "/\n";
  return rc == 0 ? 0 : rc == 2 ? 2 : 1;  // 2: the script found the results malformed (bad input)
}

}  // namespace hybridcont::app
