#pragma once
// The one error type for a user mistake in a scene file. Its what() is a complete,
// compiler-style message that editors and terminals can jump to:
//   "<file>:<line>:<column>: error: <what was wrong>; <what to do / allowed values>"
// Lines and columns are 1-based. A problem with the file as a whole (missing,
// unreadable) has line 0 and column 0 and prints as "<file>: error: ...".
#include <stdexcept>
#include <string>
#include <utility>

namespace grainflow {

class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, int line, int column, std::string message)
      : std::runtime_error(format(file, line, column, message)),
        file_(std::move(file)),
        line_(line),
        column_(column),
        message_(std::move(message)) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  // The message without the "<file>:<line>:<column>: error: " prefix.
  const std::string& message() const { return message_; }

 private:
  static std::string format(const std::string& file, int line, int column,
                            const std::string& message) {
    if (line <= 0) return file + ": error: " + message;
    return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + message;
  }

  std::string file_;
  int line_;
  int column_;
  std::string message_;
};

}  // namespace grainflow
