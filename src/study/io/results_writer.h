// Writes a run's results as they are computed:
//   DIR/summary.json       model, parameters, effective options, branches, special points, orbits, and the
//                          model's presentation (title, quantities, families, figures, drawing)
//   DIR/branch-<id>.csv    one row per point: H, T, xi, t1..t<m+1>, x<i>_<state>..., physical, ..., then
//                          the model's declared quantities (setup().quantities), one column each
//   DIR/orbit-<k>.csv      sampled trajectories of selected physical orbits (key frames): t, segment,
//                          phase (its name), the states of every phase, then draw.<point>.x, draw.<point>.y
//                          for every point of the model's drawing (empty where the sample's phase does not
//                          place it; OrbitPresentation::DrawOrbit)
// The figure script reads these by name; the presentation block is
//   "presentation": {"title", "quantities": [names], "families": [names],
//                    "figures": [{"file", "title", "x", "y": [...], "zoom"}],
//                    "drawing": {"ground", "mass_radius", "phases": {"<phase>": {"lines": [[point, ...]],
//                                                                               "masses": [point, ...]}}}}
// and each orbit's "label" is its family name.
// Every CSV row is flushed when written and summary.json is rewritten atomically (temp + rename) after
// each branch, so an interrupted run leaves consistent files with everything computed so far.
//
// Completeness: summary.json carries "status": "running" from the first write on, "complete" (or, for a study
// stopped on request, "cancelled") only from Finish(), "failed" (with "status_message") from Fail(). A write that fails (a full disk) is never
// renamed over the last good summary.json and stops all further writing; the folder then keeps the last
// summary that could be written, which says "running" (or there is none): it never claims to be complete.
//
// Another run's results in the folder: PrepareDirectory refuses a folder whose summary.json belongs to
// another model (or cannot be read) unless `overwrite`; the constructor then removes every file an earlier
// run wrote there (summary.json first, so that the folder claims nothing while it is cleaned).
#ifndef HYBRIDCONT_STUDY_RESULTS_WRITER_H_
#define HYBRIDCONT_STUDY_RESULTS_WRITER_H_

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hybridcont/classification.h"
#include "hybridcont/orbit_analysis.h"
#include "hybridcont/continuation.h"
#include "hybridcont/orbit_trace.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/study.h"
#include "study/stages/families.h"
#include "study/io/resume_store.h"

namespace hybridcont::study {

// The version of the results folder's format (summary.json's "format"; docs/results-format.md): 2 adds
// "format", "exploration", "special_point_codes", "restarted_from" and every branch of another layout's
// "unknowns" to version 1 (no "format" key), whose folders LoadStudy reads as well.
inline constexpr int kResultsFormat = 2;

// What is known about one branch point beyond u.
struct PointRecord {
  int index = 0;
  Vector u;
  Classification classification;
  // The Floquet stability class of a physical orbit ("asymptotically stable", "unstable (saddle)", ...;
  // StabilityClass::ToString); empty where there are no multipliers.
  std::string stability;
  double residual = 0.0;
  int newton_iterations = 0;
  double step = 0.0;
  // The point is a branch's start at a singular point (ProgressInfo::at_singular_point): its multipliers
  // are classified as at a located branch point (FloquetOptions::at_branch_point).
  bool at_branch_point = false;
  // Extra named columns appended after the fixed ones (e.g. Floquet data); same names for every row.
  std::vector<std::pair<std::string, double>> extra;
  // The model's observables and constraints at the point (observable.h), written after the quantities; NaN
  // where one is undefined (a mean over zero durations, a failed integration) and, unless it is an unknown of
  // the run, at a non-physical point.
  std::vector<std::pair<std::string, double>> observables;
  // The typed analysis the fields above are taken from (orbit_analysis.h).
  OrbitAnalysis analysis;
  // dT/dc along the branch, c the coordinate it is continued in (H̄ or a parameter): from the branch's
  // tangent τ at the point, Σ τ_{t_i} / τ_c (the period's slope; infinite at a turning point in c). Written as
  // the column dT_d<c>. NaN where the tangent is unknown.
  double period_slope = std::numeric_limits<double>::quiet_NaN();
};

// The record of an accepted point u before its analysis: index, Newton iterations and step from `info`.
inline PointRecord RecordOf(const ProgressInfo& info, const Vector& u) {
  PointRecord record;
  record.index = info.point_index;
  record.u = u;
  record.newton_iterations = info.newton_iterations;
  record.step = info.step;
  record.at_branch_point = info.at_singular_point;
  return record;
}

// The record of a study as it grows: the typed study (study.h) that every stage fills — branches with their
// analysed points, special points, key frames, words, curves, the report — and, with a folder, its files
// written as described above. summary.json is one serialization of that record (SummaryJson, summary_json.h),
// LoadStudy its reader back (study_document.h); beside it the document holds only what is no part of the
// typed study (the effective options, the model's presentation, how a restart or a guided study began). Each
// point and each finished branch is handed to the caller's hooks.
class ResultsWriter {
 public:
  // Creates dir if needed and checks that a file can be written in it. Throws std::invalid_argument
  // ("--out 'DIR': ...") otherwise, and when dir holds results of a model other than `model` (or a
  // summary.json that cannot be read) and `overwrite` is false; an empty `model` skips that check. Call
  // before any computation so that bad input writes nothing.
  static void PrepareDirectory(const std::filesystem::path& dir, const std::string& model = "",
                               bool overwrite = false);

  // Throws ModelInputError for a model whose presentation does not evaluate (OrbitPresentation).
  // With free parameters, points are in their layout: the CSV files have a column per parameter after T,
  // and the model's figures that plot H on the horizontal axis plot the first parameter instead.
  // An empty `dir` writes nothing (the record in memory only). `hooks` may be null; it must outlive the writer.
  ResultsWriter(std::filesystem::path dir, const HybridModel& model, nlohmann::json options,
                const StudyModelSource& source, const FreeParameters& free = {}, const StudyHooks* hooks = nullptr);
  // Sets a field of summary.json that is no part of the typed study ("restarted_from", "guided") and rewrites it.
  void Annotate(const std::string& key, nlohmann::json value);

  // Branch `branch_id` is one of another model (a period-doubled family's, RepeatedModel(model, 2)): its
  // CSV columns follow that model's layout and presentation. Call before its first point; `model` must
  // outlive the branch's last AddPoint (the presentation kept for it is not used after).
  // `origin` names the family's kind (StudyBranch::origin): "period-doubled", a word's name.
  void SetBranchModel(int branch_id, const HybridModel& model, const std::string& origin = "");
  void AddPoint(int branch_id, const PointRecord& point);
  // Records the finished branch (its metadata; its points came by AddPoint) and rewrites summary.json.
  void EndBranch(const Branch& branch);
  // The family and ranges of branch `branch_id` (families.h), after EndBranch.
  void SetBranchFamily(int branch_id, const BranchFamily& family);
  // What the later stages learn of a finished branch (StudyBranch): the PD point a period-doubled family is
  // born at; a family of another word traced from that word's own start; the word change it begins at.
  void SetPeriodDoubledFrom(int branch_id, int special_point);
  void SetStartedInWord(int branch_id);
  void SetHandedOverFrom(int branch_id, int word_change);

  // The study's typed parts that its stages give whole, each rewriting summary.json.
  void SetExplorationStatus(ExplorationStatus status, const std::string& message);
  void SetParameterStarts(const StudyParameterStarts& starts);
  void SetWords(const std::vector<StudyWord>& words, const std::vector<StudyWordChange>& changes);
  void SetCurves(const std::string& parameter, const std::vector<StudyCurve>& curves);
  void SetSpecialPoints(std::vector<StudySpecialPoint> special_points);
  // Writes orbit-<k>.csv and records the key frame (with its monodromy matrix Φ_T, when not empty); returns
  // the file name.
  std::string AddOrbit(const OrbitTrace& trace, int branch_id, int index, double H, double T,
                       const std::string& label, const Matrix& monodromy = Matrix());
  void SetReport(const std::string& report);
  void SetStartNote(const std::string& note) { record_.start_note = note; }
  // More of it (how far Newton moved a start that was a guess): each line not said yet, in order.
  void AppendStartNote(const std::string& text) {
    std::size_t start = 0;
    while (start < text.size()) {
      const std::size_t end = std::min(text.find('\n', start), text.size());
      const std::string line = text.substr(start, end - start);
      if (!line.empty() && record_.start_note.find(line) == std::string::npos) {
        record_.start_note += (record_.start_note.empty() ? "" : "\n") + line;
      }
      start = end + 1;
    }
  }
  // Rewrites summary.json atomically; false (and write_error() set) when it could not be written.
  bool WriteSummary();
  // The final summary: "status": "complete", or "cancelled" for a study stopped on request. False when it
  // could not be written.
  bool Finish(bool cancelled = false);
  // Records why the run did not complete ("status": "failed") and tries to write the summary.
  void Fail(const std::string& message);

  // A file written outside the writer (a curve's) could not be written: recorded as the writer's own failures
  // are; nothing more is written.
  void RecordWriteError(const std::string& message) {
    if (write_error_.empty()) write_error_ = message;
    failed_ = true;
  }
  // Empty while every file has been written in full; else what failed (file and system message). After a
  // failure nothing more is written.
  const std::string& write_error() const { return write_error_; }
  // Whether a write has failed: safe to ask from any thread (a run's cancel hook, continuation.h).
  bool failed() const { return failed_.load(); }

  const std::filesystem::path& dir() const { return dir_; }
  bool writes_files() const { return !dir_.empty(); }
  // Where the explorations of the study keep their branches for a resume (resume_store.h); null without a
  // folder.
  ResumeStore* resume_store() const { return resume_store_; }
  void set_resume_store(ResumeStore* store) { resume_store_ = store; }

  // The study so far, typed: branches id == index (an id not listed yet is there, "unlisted"), special points,
  // families (FoldFamilies), key frames, words, curves, report, and summary_json, the document as it stands.
  StudyResult Record() const;
  // The summary document as it stands (summary.json).
  nlohmann::json Document() const;
  // The record of branch `branch_id` so far (with its points); null for a branch not listed yet.
  const StudyBranch* FindBranch(int branch_id) const {
    const auto b = branches_.find(branch_id);
    return b == branches_.end() ? nullptr : &b->second;
  }
  // The analysed points of branch `branch_id` so far; null for a branch without points.
  const std::vector<StudyPoint>* PointsOf(int branch_id) const;
  // The points added so far, over every branch.
  int num_points() const;
  // One more than the largest branch id listed so far (0 for none).
  int next_branch_id() const;

 private:
  std::filesystem::path dir_;
  const HybridModel& model_;
  FreeParameters free_;
  ShootingLayout layout_;
  OrbitPresentation presentation_;
  // The typed study (branches, families and summary_json aside: branches_, Record()).
  StudyResult record_;
  std::map<int, StudyBranch> branches_;  // listed from their first point (or their end) on
  // The fields of summary.json that are no part of the typed study.
  nlohmann::json document_;
  struct BranchModel {
    ShootingLayout layout;
    OrbitPresentation presentation;
    std::vector<std::string> word;  // its modes (HybridModel::WordModeNames)
    std::string model_name;
    std::string origin;
  };
  std::map<int, BranchModel> branch_models_;  // branches of another model (SetBranchModel)
  int listed_orbits_ = 0;                      // the first key frames, whose files were written
  std::map<int, StudyBranch> live_;            // the branches being traced, as the point hook sees them
  const StudyHooks* hooks_ = nullptr;
  ResumeStore* resume_store_ = nullptr;
  std::map<int, std::ofstream> branch_files_;
  std::map<int, int> rows_;                      // rows of each branch file written in full
  std::map<int, std::uintmax_t> branch_bytes_;  // bytes of each branch file written in full (whole rows)
  std::string write_error_;
  std::atomic<bool> failed_{false};

  // Records the first failed write of `file` (errno's message) and returns false.
  bool WriteFailed(const std::filesystem::path& file);
  // The point's CSV row (and, first, the file's header); `point` is its typed record.
  void WritePoint(int branch_id, const PointRecord& p, const StudyPoint& point, const ShootingLayout& layout);
  // The branch's record, listed (and summary.json rewritten) when it is first met: at its first point, or at
  // its end for a branch without points.
  StudyBranch& Listed(int branch_id);
  // The branch with the given id as the hooks see it: without its points.
  StudyBranch Unpointed(int branch_id) const;
  // The record of a finished branch that a later stage annotates (an invariant: EndBranch came first).
  StudyBranch& Ended(int branch_id);
};

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_RESULTS_WRITER_H_
