// The one validation helper behind every options struct's `Validate()` (conventions §2): a chain of
// checks that keeps the first failure, phrased as "<Struct>::<field> = <value> must <constraint>".
//
//   std::string IntegratorOptions::Validate() const {
//     return internal::OptionsCheck("IntegratorOptions")
//         .Positive("rtol", rtol).Positive("atol", atol).AtLeast("max_steps", max_steps, 1)
//         .message();
//   }
//
// Contract: checks after the first failure are not evaluated for messages (they may assume the earlier
// ones held); message() is empty when every check passed. Used by the library's sources; not used
// directly by library users.
#ifndef HYBRIDCONT_INTERNAL_OPTIONS_CHECK_H_
#define HYBRIDCONT_INTERNAL_OPTIONS_CHECK_H_

#include <cmath>
#include <sstream>
#include <string>
#include <utility>

namespace hybridcont::internal {

class OptionsCheck {
 public:
  explicit OptionsCheck(std::string struct_name) : struct_name_(std::move(struct_name)) {}

  // value finite and > 0.
  OptionsCheck& Positive(const char* field, double value) {
    return Require(value > 0.0 && std::isfinite(value), field, value, "must be finite and > 0");
  }
  // value finite and >= 0.
  OptionsCheck& NonNegative(const char* field, double value) {
    return Require(value >= 0.0 && std::isfinite(value), field, value, "must be finite and >= 0");
  }
  // value finite and in the open interval (lower, upper).
  OptionsCheck& Between(const char* field, double value, double lower, double upper) {
    if (failed()) return *this;
    std::ostringstream constraint;
    constraint << "must lie in (" << lower << ", " << upper << ")";
    return Require(value > lower && value < upper && std::isfinite(value), field, value, constraint.str());
  }
  // An integer at least `minimum`.
  OptionsCheck& AtLeast(const char* field, long long value, long long minimum) {
    return Require(value >= minimum, field, value, "must be >= " + std::to_string(minimum));
  }
  // A general condition: `constraint` completes "<Struct>::<field> = <value> ...".
  template <class V>
  OptionsCheck& Require(bool holds, const char* field, const V& value, const std::string& constraint) {
    if (failed() || holds) return *this;
    std::ostringstream out;
    out << struct_name_ << "::" << field << " = " << value << " " << constraint;
    message_ = out.str();
    return *this;
  }
  // A condition whose message is written whole (prefixed by "<Struct>::").
  OptionsCheck& Require(bool holds, const std::string& message) {
    if (!failed() && !holds) message_ = struct_name_ + "::" + message;
    return *this;
  }
  // The Validate() message of a nested options struct, prefixed by "<Struct>::<field>: ".
  OptionsCheck& Nested(const char* field, const std::string& nested_message) {
    if (!failed() && !nested_message.empty()) message_ = struct_name_ + "::" + field + ": " + nested_message;
    return *this;
  }

  bool failed() const { return !message_.empty(); }
  const std::string& message() const { return message_; }

 private:
  std::string struct_name_;
  std::string message_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_INTERNAL_OPTIONS_CHECK_H_
