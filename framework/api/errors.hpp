// Errors that reach the user. InputError is bad input (exit status 2): it names the file, the
// line and column or the key, and what was expected. Anything else is an internal failure (1).
#pragma once
#include <stdexcept>
#include <string>

namespace gem {

class InputError : public std::runtime_error {
 public:
  // A message longer than kMaxMessage is cut in its middle (a 200 MB token must not be echoed whole).
  explicit InputError(const std::string& message) : std::runtime_error(shorten(message)) {}
  struct Whole {};  // the message is already shortened line by line
  InputError(const std::string& message, Whole) : std::runtime_error(message) {}
  // "FILE:LINE:COL: message" (line/column 0 are left out).
  InputError(const std::string& file, int line, int column, const std::string& message)
      : std::runtime_error(shorten(format(file, line, column, message))) {}

  // Several errors, one per line, each line cut to kMaxMessage (ErrorCollector::throwIfAny).
  static InputError multiline(const std::string& lines);

  static constexpr size_t kMaxMessage = 1000;
  static std::string shorten(const std::string& message);

 private:
  static std::string format(const std::string& file, int line, int column, const std::string& message);
};

}  // namespace gem
