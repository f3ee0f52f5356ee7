// The JSON that a study writes into summary.json beyond the writer's own: the effective options
// and the special points of the continuation (SB, TP, start, and the Floquet crossings BP and PD located
// as test functions, floquet_test_functions.h), with one set of fields for every special point:
//   {"id", "label", "type", "branch", "index", "H", "T", "status", "precision", "precision_arclength",
//    "precision_H", "residual", "component", "duplicate_of", "message", "u"}
#ifndef HYBRIDCONT_STUDY_SUMMARY_JSON_H_
#define HYBRIDCONT_STUDY_SUMMARY_JSON_H_

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "hybridcont/study.h"
#include "hybridcont/exploration.h"
#include "hybridcont/shooting_layout.h"
#include "study/engine/run_setup.h"

namespace hybridcont::study {

// The effective configuration of a run: formulation, integrator, continuation, bounds, targets,
// exploration limits, start conditions and the scenario's unknown scales.
nlohmann::json OptionsJson(const StudyOptions& options, const RunSetup& setup);

// The study's special points (special_points.h, RecordSpecialPoints), summary.json's "special_points": one set
// of fields for every point, plus each free parameter and observable unknown by name, "observables" where they
// were evaluated, "word" (another word's point) and "period_doubled_from" (a period-doubled family's).
nlohmann::json SpecialPointsJson(const std::vector<StudySpecialPoint>& points);

// The study's families (FoldFamilies), summary.json's "families": derived from the branches, written for
// readers of the folder that do not fold ranges themselves (LoadStudy folds them again):
//   [{"name", "continued", "branches": [ids], "physical": [{"from", "to", "from_end", "to_end"}], "stable": [...],
//     "special_points": [labels]}]
nlohmann::json FamiliesJson(const std::vector<StudyFamily>& families);

// An automaton's words and the changes of word considered, summary.json's "words" ([{"word": modes, "name",
// "branches"}]) and "word_changes" ([{"from_word", "from_branch", "at", "H", and as the change has them: "H_bracket"
// and "detail" (an end), "rule", "to_word", "residual" (a candidate), "accepted", "reason", "state_difference",
// "period_difference", "to_branches"}]).
nlohmann::json WordsJson(const std::vector<StudyWord>& words);
nlohmann::json WordChangesJson(const std::vector<StudyWordChange>& changes);
// A free-parameter study's starts, summary.json's "starts": {"crossings", "distinct", "on_traced_branches",
// "ordinary_half_branches"}.
nlohmann::json ParameterStartsJson(const StudyParameterStarts& starts);

// A branch's entry in summary.json ("branches"; BranchFromSummary reads it back): {"id", "file", "parent",
// "direction", "depth", "points" (`rows`: the rows of its file), "termination", "message", "newton_iterations",
// "rejected_steps", "word"} and as the branch has them: "model", "quantities" and "observables" (its
// model's, the names of their columns), "origin" and "unknowns" (a branch of another
// model or layout than the study's), "image_of"/"reflected_from" with "symmetry", "family" with
// "physical_ranges" and "stable_ranges", "period_doubled_from" with "stability_changes", "started_in_word",
// "handed_over_from".
nlohmann::json BranchJson(const StudyBranch& b, int rows, const StudyResult& study);
// The study's two-parameter curves, summary.json's "curves" (parameter_curves.h).
nlohmann::json CurvesJson(const std::string& parameter, const std::vector<StudyCurve>& curves);
// "regions": [{"family", "kind" ("physical" | "stable"), "branch", "polygon": [[p, a], ...]}] (regions.h).
nlohmann::json RegionsJson(const std::vector<StudyRegion>& regions);
// The value of the model parameter `name` in result.parameters; NaN where it has none.
double ParameterValue(const StudyResult& result, const std::string& name);
// The file of the k-th key frame of a results folder: "orbit-<k>.csv".
std::string OrbitFileName(int k);
// The first `listed` key frames, summary.json's "orbits": [{"file", "branch", "index", "H", "T", "label",
// "monodromy" (rows; where computed)}] (their samples are in the files).
nlohmann::json OrbitsJson(const std::vector<StudyOrbit>& orbits, int listed);

// summary.json: the typed study `record` (its branches given apart, by id, with the rows of their files; the
// first `listed_orbits` key frames) serialized into `document`, which holds the fields that are no part of
// the typed study (format, description, phases, special-point codes, presentation, options, status, how a
// restart or a guided study began). The one writer of the document; ResultFromSummary its reader.
nlohmann::json SummaryJson(const StudyResult& record, const std::map<int, StudyBranch>& branches,
                           const std::map<int, int>& rows, int listed_orbits, nlohmann::json document);

// The study's model_source (study.h, StudyModelSource): {"kind", "name", "path", "sha256", "text"}, the
// fields its kind has.
nlohmann::json ModelSourceJson(const StudyModelSource& source);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_SUMMARY_JSON_H_
