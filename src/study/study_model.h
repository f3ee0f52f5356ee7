// The study's model at the values its options set (StudyOptions::parameters): one rule for a built-in model,
// a model file, model text and a caller's model.
#ifndef HYBRIDCONT_STUDY_STUDY_MODEL_H_
#define HYBRIDCONT_STUDY_STUDY_MODEL_H_

#include <vector>

#include "hybridcont/study.h"

namespace hybridcont {

// Sets each named value on the model. Each name once; a name the model lacks or a value outside the
// parameter's range throws StudyOptionError("parameters", i, ...) (a ModelInputError of the model passes).
void SetStudyParameters(const std::vector<NamedValue>& parameters, HybridModel* model);

// MakeStudyModel (study.h), and where the model is: a model file read once, *source's digest that of the bytes
// the model was made of (a file edited while the model compiles cannot be vouched for).
HybridModel MakeStudyModel(const std::string& name, const std::vector<NamedValue>& parameters,
                           const std::string& models_directory, std::ostream* log, bool compile,
                           StudyModelSource* source);

}  // namespace hybridcont

#endif  // HYBRIDCONT_STUDY_STUDY_MODEL_H_
