// What a study keeps so that it can be resumed after an interruption (StudyOptions::resume; a SIGKILL
// included): every half-branch as the exploration merged it, in the engine's units, one file per branch in
// DIR/.resume/ (written whole: temp file + rename), with the study's options in DIR/.resume/study.json.
//
// A resumed study runs again from the start with the same options; each exploration takes the branches the
// store holds instead of tracing them (ExplorationOptions::recorded_branch) and traces the rest. Branches are
// stored at full precision (JSON numbers round-trip exactly), so the resumed study's decisions, special
// points and results are those of an uninterrupted one. The analysis of each point (classification, Floquet
// multipliers) is computed again, for a point whose test functions took the corrector's evaluation from the
// map at that same iterate (ContinuationPoint::evaluated_at, stored), so that its numbers are the
// uninterrupted run's to the bit; the continuation, its test functions and the location of special points
// are not. A study that completes removes the folder.
//
// Format (private to the resume; a version mismatch makes the study start afresh): .resume/study.json
// {"format": 2, "version", "options": {...}}; .resume/branch-<id>.json {"format": 2, "sha256", "branch": {...}},
// the digest of the options and the branch. Files are untrusted input: a file that does not parse as a
// branch is refused with its name and field, one whose content does not match its digest as changed.
#ifndef HYBRIDCONT_STUDY_RESUME_STORE_H_
#define HYBRIDCONT_STUDY_RESUME_STORE_H_

#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "hybridcont/continuation.h"

namespace hybridcont::study {

class ResumeStore {
 public:
  // A store in dir/.resume for a study with `options` (the StudyOptions that decide its results, as JSON).
  // With `resume`, the branches stored there by a study with the same options are loaded; a store of other
  // options throws std::invalid_argument naming the first option that differs (`what` is the caller's word
  // for the folder). Without `resume`, an old store is removed.
  ResumeStore(const std::filesystem::path& dir, const nlohmann::json& options, bool resume);

  // The branch stored under `id`, if any.
  std::optional<Branch> Lookup(int id) const;
  // Stores branch `id` (engine units); a write that fails is ignored (the study does not depend on it).
  void Save(int id, const Branch& branch);
  // The study completed: the store is removed.
  void Complete();

  int loaded() const { return static_cast<int>(loaded_.size()); }
  int used() const { return used_; }

 private:
  std::filesystem::path dir_;
  nlohmann::json options_;  // the study's options: part of every stored branch's digest
  std::map<int, Branch> loaded_;
  mutable int used_ = 0;
  mutable std::mutex mutex_;
};

// The JSON form of a branch and back (every field, full precision; NaN and infinities as strings).
nlohmann::json BranchToJson(const Branch& b);
// Throws std::invalid_argument naming `where` and the field.
Branch BranchFromJson(const nlohmann::json& j, const std::string& where);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_RESUME_STORE_H_
