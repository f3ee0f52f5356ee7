// Checked reads of a JSON document that is untrusted input (a results folder's summary.json, a resume
// store's branch): a missing field, or one of another type or out of range, throws std::invalid_argument
// naming its path, "branches[3].termination: expected a string, found 3". Numbers may be written as null
// or as the strings "nan", "inf" and "-inf" (JSON has no NaN): they read as those values.
#ifndef HYBRIDCONT_STUDY_JSON_FIELDS_H_
#define HYBRIDCONT_STUDY_JSON_FIELDS_H_

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hybridcont/types.h"

namespace hybridcont::study {

[[noreturn]] void Malformed(const std::string& where, const std::string& what);
// The field, or null (also when `object` is no object).
const nlohmann::json* FindField(const nlohmann::json& object, const std::string& key);
// The field, which must be there.
const nlohmann::json& JsonField(const nlohmann::json& object, const std::string& key, const std::string& where);
// A value that must be a number (or null, "nan", "inf", "-inf").
double JsonNumberValue(const nlohmann::json& value, const std::string& where);
// Fields of a type; a missing one is `fallback` where one is given.
int JsonInt(const nlohmann::json& object, const std::string& key, const std::string& where,
            std::optional<int> fallback = {});
double JsonNumber(const nlohmann::json& object, const std::string& key, const std::string& where,
                  std::optional<double> fallback = {});
std::string JsonText(const nlohmann::json& object, const std::string& key, const std::string& where,
                     std::optional<std::string> fallback = {});
// A list of strings; a missing one is empty.
std::vector<std::string> JsonTexts(const nlohmann::json& object, const std::string& key, const std::string& where);

// Writing side of the same convention: a number (NaN and infinities as "nan", "inf", "-inf") and a vector of them.
nlohmann::json NumberJson(double x);
nlohmann::json VectorJson(const Vector& v);
// A list of numbers as a vector.
Vector VectorFrom(const nlohmann::json& list, const std::string& where);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_JSON_FIELDS_H_
