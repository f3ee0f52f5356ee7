// The typed study (study.h) read from its saved document: the summary.json of a results folder
// (docs/results-format.md) and the analysed points of every branch. RunStudy and LoadStudy both build their
// result here, so a study read back from its folder is the study that wrote it.
//
// The document is untrusted input when it comes from a folder: every field read is checked for its type, and
// a field that is missing or of the wrong type throws std::invalid_argument naming the JSON path
// ("branches[3].termination: expected a string").
#ifndef HYBRIDCONT_STUDY_STUDY_DOCUMENT_H_
#define HYBRIDCONT_STUDY_STUDY_DOCUMENT_H_

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hybridcont/study.h"

namespace hybridcont::study {

// A branch's entry in summary.json (its points not included); `unknowns` is the layout of the summary's
// "unknowns" unless the entry names its own (a period-doubled family's).
StudyBranch BranchFromSummary(const nlohmann::json& entry, const std::vector<std::string>& unknowns,
                              const std::string& where = "branches[]");
StudySpecialPoint SpecialPointFromSummary(const nlohmann::json& entry, const std::string& where = "special_points[]");
// The branch with id `id` that a study's record does not list (an interrupted study's branch that had no point
// yet): "unlisted", in the study's own model and layout.
StudyBranch UnlistedBranch(int id, const StudyResult& study, const std::string& continued);
// The whole study; points[id] are branch id's analysed points.
StudyResult ResultFromSummary(const nlohmann::json& summary, std::map<int, std::vector<StudyPoint>> points);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_STUDY_DOCUMENT_H_
