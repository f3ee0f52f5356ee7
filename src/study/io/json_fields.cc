#include "study/io/json_fields.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace hybridcont::study {

void Malformed(const std::string& where, const std::string& what) { throw std::invalid_argument(where + ": " + what); }

const nlohmann::json* FindField(const nlohmann::json& object, const std::string& key) {
  if (!object.is_object()) return nullptr;
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

const nlohmann::json& JsonField(const nlohmann::json& object, const std::string& key, const std::string& where) {
  const nlohmann::json* v = FindField(object, key);
  if (v == nullptr) Malformed(where + "." + key, "missing");
  return *v;
}

double JsonNumberValue(const nlohmann::json& v, const std::string& where) {
  if (v.is_number()) return v.get<double>();
  if (v.is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
  }
  Malformed(where, "expected a number, found " + v.dump());
}

int JsonInt(const nlohmann::json& object, const std::string& key, const std::string& where,
            std::optional<int> fallback) {
  const nlohmann::json* v = FindField(object, key);
  if (v == nullptr) {
    if (fallback) return *fallback;
    Malformed(where + "." + key, "missing");
  }
  if (!v->is_number_integer()) Malformed(where + "." + key, "expected an integer, found " + v->dump());
  const long long x = v->get<long long>();
  if (x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max()) {
    Malformed(where + "." + key, "out of range: " + v->dump());
  }
  return static_cast<int>(x);
}

double JsonNumber(const nlohmann::json& object, const std::string& key, const std::string& where,
                  std::optional<double> fallback) {
  const nlohmann::json* v = FindField(object, key);
  if (v == nullptr) {
    if (fallback) return *fallback;
    Malformed(where + "." + key, "missing");
  }
  return JsonNumberValue(*v, where + "." + key);
}

std::string JsonText(const nlohmann::json& object, const std::string& key, const std::string& where,
                     std::optional<std::string> fallback) {
  const nlohmann::json* v = FindField(object, key);
  if (v == nullptr) {
    if (fallback) return *fallback;
    Malformed(where + "." + key, "missing");
  }
  if (!v->is_string()) Malformed(where + "." + key, "expected a string, found " + v->dump());
  return v->get<std::string>();
}

std::vector<std::string> JsonTexts(const nlohmann::json& object, const std::string& key, const std::string& where) {
  const nlohmann::json* v = FindField(object, key);
  if (v == nullptr) return {};
  if (!v->is_array()) Malformed(where + "." + key, "expected a list of strings");
  std::vector<std::string> list;
  for (std::size_t i = 0; i < v->size(); ++i) {
    if (!(*v)[i].is_string()) Malformed(where + "." + key + "[" + std::to_string(i) + "]", "expected a string");
    list.push_back((*v)[i].get<std::string>());
  }
  return list;
}

nlohmann::json NumberJson(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return x;
}

nlohmann::json VectorJson(const Vector& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(NumberJson(v(i)));
  return a;
}

Vector VectorFrom(const nlohmann::json& list, const std::string& where) {
  if (!list.is_array()) throw std::invalid_argument(where + ": expected a list of numbers");
  Vector v(static_cast<Eigen::Index>(list.size()));
  for (std::size_t i = 0; i < list.size(); ++i) {
    v(static_cast<Eigen::Index>(i)) = JsonNumberValue(list[i], where + "[" + std::to_string(i) + "]");
  }
  return v;
}

}  // namespace hybridcont::study
